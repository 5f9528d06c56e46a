#include "reconstruct/exr_header_check.h"

#include <algorithm>
#include <fstream>
#include <vector>

#include "reconstruct/exr_io.h"

namespace gdpt {

namespace {

constexpr uint32_t kExrMagic = 20000630;
constexpr int32_t kTiledFlag = 0x200, kMultipartFlag = 0x1000;

// What the check needs of one part's header.
struct PartHeader {
  bool has_window = false;
  int32_t xmin = 0, ymin = 0, xmax = -1, ymax = -1;
  int compression = 0;
  bool tiled = false;
  uint32_t tile_x = 1, tile_y = 1;
  int64_t chunk_count = -1;  // the multipart files' chunkCount, -1 when absent
};

// Scanlines per chunk of each OpenEXR compression (NONE, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A,
// DWAA, DWAB); an unknown one counts as the largest, which needs the fewest chunks.
int64_t lines_per_chunk(int compression) {
  constexpr int kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
  return compression >= 0 && compression < 10 ? kLines[compression] : 256;
}

class HeaderReader {
 public:
  HeaderReader(const std::string& path, std::ifstream& in, int64_t size)
      : path_(path), in_(in), size_(size) {}

  int64_t position() const { return pos_; }
  int64_t left() const { return size_ - pos_; }

  [[noreturn]] void fail(const std::string& why) const {
    throw ExrError("'" + path_ + "' is truncated or corrupt: " + why);
  }
  void read(void* dst, int64_t n) {
    if (n > left() || !in_.read(static_cast<char*>(dst), n)) fail("its header ends early");
    pos_ += n;
  }
  void skip(int64_t n) {
    in_.seekg(n, std::ios::cur);
    pos_ += n;
  }
  template <typename T>
  T value() {
    T v{};
    read(&v, sizeof(T));
    return v;
  }
  // A NUL-terminated name of at most 255 characters.
  std::string name() {
    std::string s;
    for (;;) {
      const char c = value<char>();
      if (c == '\0') return s;
      if (s.size() == 255) fail("a header name is longer than 255 characters");
      s.push_back(c);
    }
  }

 private:
  const std::string& path_;
  std::ifstream& in_;
  int64_t size_;
  int64_t pos_ = 0;
};

// One header's attributes up to its terminating NUL; false when the header is empty (the end of
// a multipart file's header list).
bool read_part(HeaderReader& r, PartHeader& part) {
  for (bool first = true;; first = false) {
    const std::string name = r.name();
    if (name.empty()) return !first;
    const std::string type = r.name();
    const int32_t size = r.value<int32_t>();
    if (size < 0 || size > r.left())
      r.fail("its attribute '" + name + "' claims " + std::to_string(size) + " bytes, " +
             std::to_string(r.left()) + " are left in the file");
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      part.has_window = true;
      part.xmin = r.value<int32_t>();
      part.ymin = r.value<int32_t>();
      part.xmax = r.value<int32_t>();
      part.ymax = r.value<int32_t>();
    } else if (name == "compression" && size == 1) {
      part.compression = r.value<uint8_t>();
    } else if (name == "tiles" && type == "tiledesc" && size == 9) {
      part.tile_x = std::max<uint32_t>(1, r.value<uint32_t>());
      part.tile_y = std::max<uint32_t>(1, r.value<uint32_t>());
      r.skip(1);
    } else if (name == "chunkCount" && size == 4) {
      part.chunk_count = r.value<int32_t>();
    } else if (name == "type" && size <= 64) {
      std::string t(size_t(size), '\0');
      r.read(t.data(), size);
      part.tiled = t.find("tile") != std::string::npos;
    } else {
      r.skip(size);
    }
  }
}

// Chunks the part's data window needs at its first level (mipmaps only add more).
int64_t part_chunks(HeaderReader& r, const PartHeader& p) {
  if (!p.has_window) r.fail("a header has no dataWindow");
  const int64_t w = int64_t(p.xmax) - p.xmin + 1, h = int64_t(p.ymax) - p.ymin + 1;
  const std::string size = std::to_string(w) + "x" + std::to_string(h);
  if (w <= 0 || h <= 0) r.fail("its data window " + size + " is empty");
  if (w * h > kMaxExrPixels)
    r.fail("its data window " + size + " has more than " + std::to_string(kMaxExrPixels) +
           " pixels");
  if (p.chunk_count >= 0) return p.chunk_count;
  if (p.tiled) return ((w + p.tile_x - 1) / p.tile_x) * ((h + p.tile_y - 1) / p.tile_y);
  const int64_t lines = lines_per_chunk(p.compression);
  return (h + lines - 1) / lines;
}

}  // namespace

void check_exr_header(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return;  // the reader reports the missing file
  const int64_t size = in.tellg();
  in.seekg(0);
  HeaderReader r(path, in, size);
  if (size < 8) return;
  const uint32_t magic = r.value<uint32_t>();
  if (magic != kExrMagic) return;
  const int32_t version = r.value<int32_t>();
  std::vector<PartHeader> parts;
  for (;;) {
    PartHeader part;
    part.tiled = (version & kTiledFlag) != 0;
    if (!read_part(r, part)) break;
    parts.push_back(part);
    if (!(version & kMultipartFlag)) break;
  }
  int64_t chunks = 0;
  for (const PartHeader& p : parts) chunks += part_chunks(r, p);
  const int64_t needed = r.position() + 16 * chunks;
  if (needed > size)
    r.fail("its data windows need " + std::to_string(chunks) + " chunks, at least " +
           std::to_string(needed) + " bytes, and the file has " + std::to_string(size));
}

}  // namespace gdpt

// Bounds what an OpenEXR file's headers claim by the file's size, before OpenEXR reads them.
// OpenEXR allocates an attribute's claimed size before reading its bytes: a truncated or corrupt
// 300-byte file whose string attribute claims 1.7 GB takes that much memory (and tens of seconds)
// before failing with "Unexpected end of file". The check walks the headers' attribute list
// (names, types and sizes only) and rejects, with a one-line reason:
//  - an attribute whose size is negative or larger than the bytes left in the file;
//  - a data window that is empty, inverted or larger than kMaxExrPixels;
//  - a file too short for the chunks its data windows need (every chunk has an 8-byte entry in
//    the offset table and at least an 8-byte chunk header).
// Files that are not OpenEXR (no magic number) pass unchecked: the reader reports what they are.
#pragma once

#include <cstdint>
#include <string>

namespace gdpt {

// Largest data window accepted, per part: 2^30 pixels (32768 x 32768).
inline constexpr int64_t kMaxExrPixels = int64_t(1) << 30;

// Throws ExrError (exr_io.h) when the headers of the file at `path` claim more than it holds.
void check_exr_header(const std::string& path);

}  // namespace gdpt

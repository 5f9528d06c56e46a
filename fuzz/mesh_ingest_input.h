// The byte layout the mesh-ingestion fuzzer reads (fuzz_mesh_ingest.cpp) and the seed writer
// writes (fuzz_seeds.cpp): a mode byte, a normals-per-loop byte, then each array of that mode as
// a little-endian uint16 count followed by that many 4-byte values (float or int32). A count
// past the end of the data takes what is there, so every byte string is an input.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace gdpt::fuzz {

enum class MeshMode : uint8_t { Triangles = 0, Loops = 1, Polys = 2 };

// Arrays in stream order. Triangles: positions, indices, corner_normals, corner_uvs,
// material_slot. Loops and Polys: positions, loop_vertex, normals, loop_uvs, loop_tangents,
// loop_colors, then corner_loops, material_slot (Loops) or loop_start, loop_total,
// poly_material (Polys). Float arrays hold float bits, int arrays int32.
struct MeshInput {
  MeshMode mode = MeshMode::Triangles;
  bool normals_per_loop = false;
  std::vector<std::vector<uint32_t>> arrays;
};

inline size_t mesh_array_count(MeshMode mode) {
  return mode == MeshMode::Triangles ? 5 : mode == MeshMode::Loops ? 8 : 9;
}

inline MeshInput decode_mesh_input(const uint8_t* data, size_t size) {
  MeshInput in;
  size_t at = 0;
  auto byte = [&]() -> uint8_t { return at < size ? data[at++] : 0; };
  in.mode = MeshMode(byte() % 3);
  in.normals_per_loop = byte() & 1;
  in.arrays.resize(mesh_array_count(in.mode));
  for (auto& a : in.arrays) {
    size_t count = byte();
    count |= size_t(byte()) << 8;
    count = std::min(count, (size - std::min(at, size)) / 4);
    a.resize(count);
    if (count) std::memcpy(a.data(), data + at, count * 4);
    at += count * 4;
  }
  return in;
}

inline void append_array(std::vector<uint8_t>& out, const void* values, size_t count) {
  out.push_back(uint8_t(count & 0xff));
  out.push_back(uint8_t(count >> 8));
  const auto* p = static_cast<const uint8_t*>(values);
  out.insert(out.end(), p, p + count * 4);
}

}  // namespace gdpt::fuzz

// Writes the fuzzers' seed corpora from real data at fuzz time (scripts/fuzz.sh), so no binary
// file lives in git: `fuzz_seeds exr DIR` writes EXRs with the project's own writer as Blender
// and gdpt-reconstruct name their passes; `fuzz_seeds mesh DIR` writes meshes in the
// mesh-ingestion fuzzer's layout (fuzz/mesh_ingest_input.h) as the add-on hands them over.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "fuzz/mesh_ingest_input.h"
#include "reconstruct/exr_io.h"

namespace {

std::vector<float> ramp(int w, int h, float scale) {
  std::vector<float> v(size_t(w) * h * 3);
  for (size_t i = 0; i < v.size(); ++i) v[i] = scale * float(i % 7) / 7.0f;
  return v;
}

void write_exrs(const std::string& dir) {
  using Passes = std::map<std::string, std::vector<float>>;
  for (const auto& [w, h] : {std::pair{4, 3}, std::pair{1, 1}, std::pair{9, 2}}) {
    const std::string size = std::to_string(w) + "x" + std::to_string(h);
    const Passes all = {{"Primal", ramp(w, h, 1.0f)},      {"Gradient X", ramp(w, h, 0.1f)},
                        {"Gradient Y", ramp(w, h, -0.1f)}, {"Variance", ramp(w, h, 0.01f)},
                        {"Emission", ramp(w, h, 2.0f)},    {"Normal", ramp(w, h, 1.0f)}};
    gdpt::write_multilayer_exr(dir + "/blender_" + size + ".exr", w, h, "ViewLayer", all,
                               {"Normal"});
    gdpt::write_multilayer_exr(dir + "/unprefixed_" + size + ".exr", w, h, "",
                               {{"Primal", all.at("Primal")},
                                {"Gradient X", all.at("Gradient X")},
                                {"Gradient Y", all.at("Gradient Y")}});
    gdpt::write_rgba_exr(dir + "/rgba_" + size + ".exr", w, h, ramp(w, h, 1.0f));
  }
}

// A unit cube: 8 vertices, 6 quads (24 loops), as Blender's arrays.
struct Cube {
  std::vector<float> positions;
  std::vector<int32_t> loop_vertex, loop_start, loop_total, material;
  std::vector<float> normals, uvs, tangents, colors;
  Cube() {
    for (int v = 0; v < 8; ++v)
      for (int k = 0; k < 3; ++k) positions.push_back(float((v >> k) & 1));
    loop_vertex = {0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5};
    for (int p = 0; p < 6; ++p) {
      loop_start.push_back(4 * p);
      loop_total.push_back(4);
      material.push_back(p % 2);
    }
    for (size_t l = 0; l < loop_vertex.size(); ++l) {
      const float* co = &positions[3 * size_t(loop_vertex[l])];
      for (int k = 0; k < 3; ++k) normals.push_back(2 * co[k] - 1);
      uvs.insert(uvs.end(), {co[0], co[1]});
      tangents.insert(tangents.end(), {1, 0, 0, 1});
      colors.insert(colors.end(), {co[0], co[1], co[2]});
    }
  }
};

void write_file(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::vector<uint8_t> header(gdpt::fuzz::MeshMode mode, bool per_loop) {
  return {uint8_t(mode), uint8_t(per_loop)};
}

void write_meshes(const std::string& dir) {
  using gdpt::fuzz::append_array;
  using gdpt::fuzz::MeshMode;
  const Cube c;
  for (const bool full : {false, true}) {
    const std::string tag = full ? "_attributes" : "";
    std::vector<uint8_t> polys = header(MeshMode::Polys, full);
    append_array(polys, c.positions.data(), c.positions.size());
    append_array(polys, c.loop_vertex.data(), c.loop_vertex.size());
    append_array(polys, c.normals.data(), full ? c.normals.size() : 0);
    append_array(polys, c.uvs.data(), full ? c.uvs.size() : 0);
    append_array(polys, c.tangents.data(), full ? c.tangents.size() : 0);
    append_array(polys, c.colors.data(), full ? c.colors.size() : 0);
    append_array(polys, c.loop_start.data(), c.loop_start.size());
    append_array(polys, c.loop_total.data(), c.loop_total.size());
    append_array(polys, c.material.data(), full ? c.material.size() : 0);
    write_file(dir + "/cube_polys" + tag, polys);

    // Blender's loop triangles of the same cube (0-1-2, 0-2-3 per quad).
    std::vector<int32_t> corners, tri_material;
    for (int p = 0; p < 6; ++p) {
      corners.insert(corners.end(), {4 * p, 4 * p + 1, 4 * p + 2, 4 * p, 4 * p + 2, 4 * p + 3});
      tri_material.insert(tri_material.end(), {p % 2, p % 2});
    }
    std::vector<uint8_t> loops = header(MeshMode::Loops, full);
    append_array(loops, c.positions.data(), c.positions.size());
    append_array(loops, c.loop_vertex.data(), c.loop_vertex.size());
    append_array(loops, c.normals.data(), full ? c.normals.size() : 0);
    append_array(loops, c.uvs.data(), full ? c.uvs.size() : 0);
    append_array(loops, c.tangents.data(), full ? c.tangents.size() : 0);
    append_array(loops, c.colors.data(), full ? c.colors.size() : 0);
    append_array(loops, corners.data(), corners.size());
    append_array(loops, tri_material.data(), full ? tri_material.size() : 0);
    write_file(dir + "/cube_loops" + tag, loops);

    std::vector<int32_t> indices;
    std::vector<float> corner_normals, corner_uvs;
    for (const int32_t l : corners) {
      indices.push_back(c.loop_vertex[size_t(l)]);
      corner_normals.insert(corner_normals.end(), &c.normals[3 * size_t(l)],
                            &c.normals[3 * size_t(l)] + 3);
      corner_uvs.insert(corner_uvs.end(), &c.uvs[2 * size_t(l)], &c.uvs[2 * size_t(l)] + 2);
    }
    std::vector<uint8_t> tris = header(MeshMode::Triangles, false);
    append_array(tris, c.positions.data(), c.positions.size());
    append_array(tris, indices.data(), indices.size());
    append_array(tris, corner_normals.data(), full ? corner_normals.size() : 0);
    append_array(tris, corner_uvs.data(), full ? corner_uvs.size() : 0);
    append_array(tris, tri_material.data(), full ? tri_material.size() : 0);
    write_file(dir + "/cube_triangles" + tag, tris);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string what = argc == 3 ? argv[1] : "";
  if (what == "exr") {
    write_exrs(argv[2]);
  } else if (what == "mesh") {
    write_meshes(argv[2]);
  } else {
    std::fprintf(stderr, "usage: fuzz_seeds exr|mesh DIR\n");
    return 2;
  }
  return 0;
}

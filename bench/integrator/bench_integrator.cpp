// Path tracer throughput: samples/s and rays/s on a Cornell box and on a ~1M-triangle sphere field,
// with 1 and 2 threads (PT, 8 bounces), plus what the per-scene kernel specialisation buys on a
// diffuse-only scene against the same scene with every feature path forced on.
//
// Usage: bench_integrator [seconds_per_case [cases]]   (default 3 s; cases: any of
// "cornell", "textured", "field", "features", "blender", "film", default all six; "blender" is
// compare_cycles.py's Cornell box with its 4 bounces, at 256x192; "film" times the construction
// of a render's two films at 1920x1080, PT and G-PT layout: zeroing fresh memory)
// Each case renders passes of 1 spp at 256x256 until the time budget is used, then reports
// samples/s = pixels * spp / wall time and rays/s (camera + extension + shadow rays).
//
// Instruction-count mode (for a loaded machine, where wall and CPU times drift): with the
// environment variable GDPT_BENCH_SPP=N, each requested case renders exactly N spp with 1 thread
// (no time limit) and prints the sample count, so that e.g.
//   GDPT_BENCH_SPP=4 valgrind --tool=callgrind --toggle-collect='*render_tile*'
//     bench_integrator 0 cornell
// gives instructions per sample = callgrind's total / the printed sample count; it also prints the
// mean per-pixel variance and an image checksum (equal checksums: a bit-identical image).
// GDPT_BENCH_THREADS (default 1), GDPT_BENCH_SEED and GDPT_BENCH_RR_DEPTH set the thread count,
// seed and roulette depth, and GDPT_BENCH_REFERENCE=PREFIX compares the image with
// PREFIX.<case>.f32 (luminance MSE and relMSE), or writes
// that file when it is missing: e.g. a 4096-spp reference, then MSE at 16 spp over a few seeds,
// for error-at-equal-cost comparisons of sampling techniques.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "bench/film_checksum.h"
#include "integrators/render_session.h"

using namespace gdpt;

namespace {

MaterialDesc diffuse(Spectrum c) {
  MaterialDesc m;
  ShaderNode n;
  n.kind = ShaderNodeKind::Diffuse;
  n.color = ColorInput(c);
  m.nodes.push_back(n);
  m.root = 0;
  return m;
}

Transform affine(float sx, float sy, float sz, float rot_z, Vec3f t) {
  Transform T;
  const float c = std::cos(rot_z), s = std::sin(rot_z);
  T.m[0][0] = c * sx;
  T.m[0][1] = -s * sy;
  T.m[1][0] = s * sx;
  T.m[1][1] = c * sy;
  T.m[2][2] = sz;
  T.m[0][3] = t.x;
  T.m[1][3] = t.y;
  T.m[2][3] = t.z;
  return T;
}

// Axis-aligned cube [-1, 1]^3 with outward faces.
Mesh cube() {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back({i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f});
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads)
    m.indices.insert(m.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  return m;
}

// Quad z = 0 facing +z, [-1, 1]^2.
Mesh quad() {
  Mesh m;
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  m.indices = {0, 1, 2, 0, 2, 3};
  // Planar UVs, 2x2 repeats over the quad (textured case).
  for (uint32_t i : m.indices) m.corner_uvs.push_back({m.positions[i].x + 1, m.positions[i].y + 1});
  return m;
}

Instance place(uint32_t mesh, int32_t mat, Transform t) {
  Instance i;
  i.mesh = mesh;
  i.slot_material = {mat};
  i.object_to_world = t;
  return i;
}

Camera camera_looking_y(float y, float focal, int res) {
  Camera c;
  // Rotate -Z onto +Y: camera x = world x, camera y = world z.
  Transform T;
  T.m[1][1] = 0;
  T.m[1][2] = -1;
  T.m[2][1] = 1;
  T.m[2][2] = 0;
  T.m[1][3] = y;
  c.camera_to_world = T;
  c.focal_length_mm = focal;
  c.width = c.height = res;
  return c;
}

// Cornell box 2 m wide: white floor/ceiling/back, red left, green right, two white boxes and a
// square area light under the ceiling.
Scene cornell_box(int res) {
  Scene s;
  s.meshes = {quad(), cube()};
  s.materials = {diffuse({0.73f, 0.73f, 0.73f}), diffuse({0.65f, 0.05f, 0.05f}),
                 diffuse({0.12f, 0.45f, 0.15f})};
  // Each wall is its own mesh, as Blender exports separate objects (single-use meshes are stored in
  // world space); the cube is shared by both boxes (Embree instances).
  auto wall = [&](int mat, Transform t) {
    s.meshes.push_back(quad());
    s.instances.push_back(place(uint32_t(s.meshes.size() - 1), mat, t));
  };
  Transform floor_t = affine(1, 1, 1, 0, {0, 0, -1});
  wall(0, floor_t);
  Transform ceil_t;  // z = 1 facing down
  ceil_t.m[1][1] = -1;
  ceil_t.m[2][2] = -1;
  ceil_t.m[2][3] = 1;
  wall(0, ceil_t);
  Transform back;  // y = 1 facing -y
  back.m[1][1] = 0;
  back.m[1][2] = -1;
  back.m[2][1] = 1;
  back.m[2][2] = 0;
  back.m[1][3] = 1;
  wall(0, back);
  Transform left;  // x = -1 facing +x
  left.m[0][0] = 0;
  left.m[0][2] = 1;
  left.m[2][0] = -1;
  left.m[2][2] = 0;
  left.m[0][3] = -1;
  wall(1, left);
  Transform right = left;
  right.m[0][2] = -1;
  right.m[2][0] = 1;
  right.m[0][3] = 1;
  wall(2, right);
  s.instances.push_back(place(1, 0, affine(0.3f, 0.3f, 0.3f, -0.3f, {0.33f, -0.35f, -0.7f})));
  s.instances.push_back(place(1, 0, affine(0.3f, 0.3f, 0.6f, 0.3f, {-0.33f, 0.3f, -0.4f})));
  Light area;
  area.type = Light::Type::Area;
  area.size_x = area.size_y = 0.5f;
  area.power = 60.0f;
  area.light_to_world.m[2][3] = 0.99f;  // emits along local -Z: down
  s.lights.push_back(area);
  s.world.color = Spectrum(0.0f);
  s.camera = camera_looking_y(-3.9f, 35.0f, res);
  return s;
}

// The Cornell box with a 256x256 8-bit sRGB colour grid (bilinear, repeat) as the base colour of
// the floor and the back wall: what an image texture costs per sample, through the same code as
// an 8-bit sRGB image from Blender (coded texels, the sRGB decode per lookup), which is also what
// the PGO training (scripts/pgo-train.sh) then sees.
Scene textured_cornell_box(int res) {
  Scene s = cornell_box(res);
  ImageDesc img;
  img.name = "grid";
  img.width = img.height = 256;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      const bool line = x % 32 == 0 || y % 32 == 0;
      // 8-bit values, as from a PNG: the texture keeps 8-bit codes (texture.h).
      const float r = float(line ? 230 : x) / 255.0f, g = float(line ? 230 : y) / 255.0f;
      img.rgba.insert(img.rgba.end(), {r, g, 0.49f, 1.0f});
    }
  img.srgb_encoded = true;
  s.images.push_back(std::move(img));
  MaterialDesc tex = diffuse(Spectrum(0.8f));
  tex.nodes[0].color.texture.image = 0;
  s.materials.push_back(tex);
  s.instances[0].slot_material = {int32_t(s.materials.size() - 1)};  // floor
  s.instances[2].slot_material = {int32_t(s.materials.size() - 1)};  // back wall
  return s;
}

// 64 separate UV spheres of ~16k triangles each (~1M unique triangles) on a ground plane, lit by a
// sun and a grey world.
Scene sphere_field(int res) {
  Scene s;
  s.materials = {diffuse({0.8f, 0.8f, 0.8f}), diffuse({0.6f, 0.3f, 0.2f})};
  s.meshes.push_back(quad());
  s.instances.push_back(place(0, 0, affine(20, 20, 1, 0, {0, 0, 0})));
  const int seg = 128, rings = 64;
  for (int gx = 0; gx < 8; ++gx)
    for (int gy = 0; gy < 8; ++gy) {
      Mesh m;
      const Vec3f c(-3.5f + float(gx), -3.5f + float(gy), 0.45f);
      for (int i = 0; i <= rings; ++i) {
        const float th = kPi * float(i) / float(rings);
        for (int j = 0; j < seg; ++j) {
          const float ph = 2.0f * kPi * float(j) / float(seg);
          m.positions.push_back(
              c + Vec3f(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)) *
                      0.45f);
        }
      }
      for (int i = 0; i < rings; ++i)
        for (int j = 0; j < seg; ++j) {
          const uint32_t a = uint32_t(i * seg + j), b = uint32_t(i * seg + (j + 1) % seg);
          m.indices.insert(m.indices.end(), {a, a + seg, b, b, a + seg, b + seg});
        }
      s.meshes.push_back(std::move(m));
      s.instances.push_back(place(uint32_t(s.meshes.size() - 1), 1, Transform()));
    }
  Light sun;
  sun.type = Light::Type::Sun;
  sun.power = 3.0f;
  sun.sun_angle = 0.01f;
  sun.light_to_world = affine(1, 1, 1, 0, {0, 0, 10});
  sun.light_to_world.m[1][1] = std::cos(0.6f);
  sun.light_to_world.m[1][2] = -std::sin(0.6f);
  sun.light_to_world.m[2][1] = std::sin(0.6f);
  sun.light_to_world.m[2][2] = std::cos(0.6f);
  s.lights.push_back(sun);
  s.world.color = Spectrum(0.3f);
  Camera cam = camera_looking_y(-9.0f, 35.0f, res);
  cam.camera_to_world.m[2][3] = 3.0f;
  s.camera = cam;
  return s;
}

// The Cornell-box scene of bench/blender/compare_cycles.py rebuilt in C++ (its GDPT-vs-Cycles
// comparison runs max_bounces 4): a 4 m open-front room (white 0.7, red and green walls), a
// diffuse and a GGX glossy (roughness 0.3) smooth-shaded UV sphere of 48 x 24 segments, a 1 m
// 150 W square area light under the ceiling. Profiling it here shows what the Blender bench's
// samples cost without Blender around them.
Mesh uv_sphere(float radius, int segments, int rings) {
  Mesh m;
  for (int i = 0; i <= rings; ++i) {
    const float th = kPi * float(i) / float(rings);
    for (int j = 0; j < segments; ++j) {
      const float ph = 2.0f * kPi * float(j) / float(segments);
      m.positions.push_back(
          Vec3f(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)) * radius);
    }
  }
  // Blender's quads (a, b, b + seg, a + seg) split along a - (b + seg), with smooth corner normals,
  // wound so that the geometric normal points outwards as the corner normals do (Blender's
  // meshes are consistent; the winding (a, b, c) made every hit back-facing with the shading
  // normal inside until the tenth session).
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i * segments + j),
                     b = uint32_t(i * segments + (j + 1) % segments);
      const uint32_t c = b + uint32_t(segments), d = a + uint32_t(segments);
      for (uint32_t v : {a, c, b, a, d, c}) {
        m.indices.push_back(v);
        m.corner_normals.push_back(normalize(m.positions[v]));
      }
    }
  return m;
}

Transform rotation_x(float angle, Vec3f t) {
  Transform T = affine(1, 1, 1, 0, t);
  T.m[1][1] = std::cos(angle);
  T.m[1][2] = -std::sin(angle);
  T.m[2][1] = std::sin(angle);
  T.m[2][2] = std::cos(angle);
  return T;
}

Transform rotation_y(float angle, Vec3f t) {
  Transform T = affine(1, 1, 1, 0, t);
  T.m[0][0] = std::cos(angle);
  T.m[0][2] = std::sin(angle);
  T.m[2][0] = -std::sin(angle);
  T.m[2][2] = std::cos(angle);
  return T;
}

Scene blender_cornell(int width, int height) {
  Scene s;
  MaterialDesc glossy;
  ShaderNode g;
  g.kind = ShaderNodeKind::Glossy;
  g.color = ColorInput(Spectrum(0.9f));
  g.roughness = FloatInput(0.3f);
  glossy.nodes.push_back(g);
  glossy.root = 0;
  s.materials = {diffuse(Spectrum(0.7f)), diffuse({0.7f, 0.2f, 0.2f}), diffuse({0.2f, 0.6f, 0.2f}),
                 diffuse(Spectrum(0.8f)), glossy};
  auto wall = [&](int mat, Transform t) {
    Mesh q = quad();
    for (Vec3f& p : q.positions) p = p * 2.0f;  // 4 m
    s.meshes.push_back(std::move(q));
    s.instances.push_back(place(uint32_t(s.meshes.size() - 1), mat, t));
  };
  wall(0, affine(1, 1, 1, 0, {0, 0, 0}));    // floor
  wall(0, rotation_x(kPi, {0, 0, 4}));       // ceiling
  wall(0, rotation_x(kPi / 2, {0, 2, 2}));   // back
  wall(1, rotation_y(kPi / 2, {-2, 0, 2}));  // left (red)
  wall(2, rotation_y(-kPi / 2, {2, 0, 2}));  // right (green)
  s.meshes.push_back(uv_sphere(0.7f, 48, 24));
  s.instances.push_back(
      place(uint32_t(s.meshes.size() - 1), 3, affine(1, 1, 1, 0, {-0.8f, 0.2f, 0.7f})));
  s.meshes.push_back(uv_sphere(0.7f, 48, 24));
  s.instances.push_back(
      place(uint32_t(s.meshes.size() - 1), 4, affine(1, 1, 1, 0, {0.8f, 0.6f, 0.7f})));
  Light area;
  area.type = Light::Type::Area;
  area.size_x = area.size_y = 1.0f;
  area.power = 150.0f;
  area.light_to_world.m[2][3] = 3.95f;  // emits along local -Z: down
  s.lights.push_back(area);
  s.world.color = Spectrum(0.0f);
  // Camera at (0, -5.5, 2) looking at (0, 0, 1.7), Y up (Blender's to_track_quat('-Z', 'Y')).
  const Vec3f z = normalize(Vec3f(0.0f, -5.5f, 0.3f)), x(1, 0, 0), y = cross(z, x);
  Camera c;
  for (int r = 0; r < 3; ++r) {
    c.camera_to_world.m[r][0] = x[r];
    c.camera_to_world.m[r][1] = y[r];
    c.camera_to_world.m[r][2] = z[r];
  }
  c.camera_to_world.m[0][3] = 0.0f;
  c.camera_to_world.m[1][3] = -5.5f;
  c.camera_to_world.m[2][3] = 2.0f;
  c.focal_length_mm = 30.0f;
  c.width = width;
  c.height = height;
  s.camera = c;
  return s;
}

struct Result {
  double samples_per_s = 0, rays_per_s = 0, rays_per_sample = 0, seconds = 0;
  double samples_per_cpu_s = 0;  // per second of process CPU time: robust on a loaded machine
  std::string summary;
};

int env_int(const char* name, int fallback) {
  const char* e = std::getenv(name);
  return e ? std::atoi(e) : fallback;
}

int fixed_spp() {
  return env_int("GDPT_BENCH_SPP", 0);
}

Result run(const Scene& scene, int threads, double budget, bool force_all = false,
           int bounces = 8) {
  RenderSettings st;
  st.mode = RenderSettings::Mode::PT;
  st.samples = 1 << 20;
  st.time_limit = budget;
  st.max_bounces = bounces;
  st.threads = threads;
  st.force_all_features = force_all;
  RenderSession session(scene, st);
  std::atomic<bool> cancel{false};
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  session.render(nullptr, cancel);
  const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double samples = double(session.film().pixel_count()) * session.film().min_samples();
  Result r;
  r.seconds = secs;
  r.samples_per_s = samples / secs;
  r.rays_per_s = double(session.rays_traced()) / secs;
  r.samples_per_cpu_s = samples / cpu;
  r.rays_per_sample = double(session.rays_traced()) / samples;
  r.summary = session.features_summary();
  return r;
}

void report(const char* name, int threads, const Result& r) {
  std::printf(
      "%-24s threads=%d  %7.3f Msamples/s  %7.2f Mrays/s  %5.2f rays/sample  |  %6.3f Msamples "
      "per CPU-second\n",
      name, threads, r.samples_per_s * 1e-6, r.rays_per_s * 1e-6, r.rays_per_sample,
      r.samples_per_cpu_s * 1e-6);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const double budget = argc > 1 ? std::atof(argv[1]) : 3.0;
  const std::string cases = argc > 2 ? argv[2] : "cornell,textured,field,features,blender,film";
  auto want = [&](const char* c) { return cases.find(c) != std::string::npos; };
  const int res = 256;
  std::printf("bench_integrator: PT, 8 bounces, %dx%d, %.1f s per case\n", res, res, budget);

  const Scene cornell = cornell_box(res);
  if (fixed_spp() > 0) {  // instruction-count mode: exact spp, 1 thread
    for (const char* c : {"cornell", "textured", "field", "blender"}) {
      if (!want(c)) continue;
      const std::string name = c;
      const Scene scene = name == "cornell"    ? cornell
                          : name == "textured" ? textured_cornell_box(res)
                          : name == "blender"  ? blender_cornell(res, res * 3 / 4)
                                               : sphere_field(res);
      RenderSettings st;
      st.mode = RenderSettings::Mode::PT;
      st.samples = fixed_spp();
      st.max_bounces = name == "blender" ? 4 : 8;
      st.threads = env_int("GDPT_BENCH_THREADS", 1);
      st.seed = uint32_t(env_int("GDPT_BENCH_SEED", int(st.seed)));
      st.rr_depth = env_int("GDPT_BENCH_RR_DEPTH", st.rr_depth);
      RenderSession session(scene, st);
      std::atomic<bool> cancel{false};
      session.render(nullptr, cancel);
      // Mean per-pixel variance of the luminance estimate: times the cost per sample, it compares
      // sampling techniques at equal time (efficiency = 1 / (variance * cost)).
      std::vector<float> var(3 * session.film().pixel_count());
      session.film().variance3(var.data());
      double mean_var = 0.0;
      for (size_t i = 0; i < session.film().pixel_count(); ++i) mean_var += var[3 * i];
      mean_var /= double(session.film().pixel_count());
      std::printf("%s: %.0f samples, %llu rays, mean pixel variance %.6g, image checksum %016llx\n",
                  c, double(session.film().pixel_count()) * session.film().min_samples(),
                  (unsigned long long)session.rays_traced(), mean_var,
                  (unsigned long long)bench::film_checksum(session.film()));
      // Error against a converged image: the per-pixel variance above ignores the sampler's
      // stratification (it rates Owen-scrambled Sobol no better than independent numbers), so
      // sampling techniques are compared by the luminance MSE to a reference, averaged over
      // seeds (GDPT_BENCH_SEED). A missing reference file is written from this render.
      if (const char* ref_path = std::getenv("GDPT_BENCH_REFERENCE")) {
        std::vector<float> primal(3 * session.film().pixel_count());
        session.film().primal_rgb(primal.data());
        const std::string path = std::string(ref_path) + "." + name + ".f32";
        if (FILE* f = std::fopen(path.c_str(), "rb")) {
          std::vector<float> ref(primal.size());
          const size_t got = std::fread(ref.data(), sizeof(float), ref.size(), f);
          std::fclose(f);
          if (got != ref.size()) {
            std::fprintf(stderr, "%s: wrong size\n", path.c_str());
            return 1;
          }
          double mse = 0.0, rel_mse = 0.0;
          for (size_t i = 0; i < primal.size(); i += 3) {
            const double d = luminance(Spectrum(primal[i], primal[i + 1], primal[i + 2])) -
                             luminance(Spectrum(ref[i], ref[i + 1], ref[i + 2]));
            mse += d * d;
            for (size_t k = i; k < i + 3; ++k)
              rel_mse += double(primal[k] - ref[k]) * double(primal[k] - ref[k]) /
                         (double(ref[k]) * double(ref[k]) + 0.01);
          }
          // relMSE as bench_equal_time and the Blender benchmark define it: it weighs dark
          // pixels (indirect light) as much as bright ones, which the luminance MSE does not.
          std::printf("%s: luminance MSE against %s: %.6g, relMSE %.6g\n", c, path.c_str(),
                      mse / double(primal.size() / 3), rel_mse / double(primal.size()));
        } else if (FILE* out = std::fopen(path.c_str(), "wb")) {
          std::fwrite(primal.data(), sizeof(float), primal.size(), out);
          std::fclose(out);
          std::printf("%s: reference written to %s\n", c, path.c_str());
        }
      }
    }
    return 0;
  }
  if (want("cornell"))
    for (int t : {1, 2}) report("cornell_box", t, run(cornell, t, budget));
  if (want("textured")) {
    const Scene textured = textured_cornell_box(res);
    for (int t : {1, 2}) report("cornell_box_textured", t, run(textured, t, budget));
  }

  if (want("blender")) {
    const Scene b = blender_cornell(res, res * 3 / 4);
    for (int t : {1, 2}) report("blender_cornell (4 bounces)", t, run(b, t, budget, false, 4));
  }

  if (want("film")) {
    // What RenderSession allocates for a 1920x1080 frame: the output film and the pass film.
    for (int round = 0; round < 3; ++round)
      for (bool pt : {true, false}) {
        const auto t0 = std::chrono::steady_clock::now();
        const Film output(1920, 1080, pt), pass(1920, 1080, pt);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        std::printf("film 1920x1080 (%s layout, two films): %.1f ms\n", pt ? "PT" : "G-PT", ms);
      }
  }

  if (want("field")) {
    const auto t0 = std::chrono::steady_clock::now();
    const Scene field = sphere_field(res);
    size_t tris = 0;
    for (const Mesh& m : field.meshes) tris += m.triangle_count();
    {
      Result r1 = run(field, 1, budget);
      const double build =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() - r1.seconds;
      std::printf("sphere_field: %zu triangles (scene generation + BVH build %.2f s)\n", tris,
                  build);
      report("sphere_field_1M", 1, r1);
      report("sphere_field_1M", 2, run(field, 2, budget));
    }
  }
  if (!want("features")) return 0;

  std::printf(
      "\nfeature specialisation (diffuse-only Cornell box, 1 thread, best of 3 alternating "
      "runs per kernel to damp the noise of a shared machine):\n");
  Result lean, all;
  for (int rep = 0; rep < 3; ++rep) {
    const Result a = run(cornell, 1, budget), b = run(cornell, 1, budget, true);
    if (a.samples_per_cpu_s > lean.samples_per_cpu_s) lean = a;
    if (b.samples_per_cpu_s > all.samples_per_cpu_s) all = b;
  }
  std::printf("  specialised:  %s\n", lean.summary.c_str());
  report("  specialised", 1, lean);
  std::printf("  forced-all:   %s\n", all.summary.c_str());
  report("  all features forced", 1, all);
  std::printf("  speed-up of the specialised kernel (per CPU-second): %.2fx\n",
              lean.samples_per_cpu_s / all.samples_per_cpu_s);
  return 0;
}

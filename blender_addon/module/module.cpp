// The `_gdpt` Python module: array conversion and the render call, nothing Blender-specific.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>

#include "blender_addon/module/render_job.h"
#include "blender_addon/module/scene_convert.h"
#include "blender_addon/module/viewport_job.h"
#include "reconstruct/exr_io.h"

namespace py = pybind11;
using namespace gdpt;
using namespace gdpt::python;

namespace {

RenderSettings settings_from_dict(const py::dict& d) {
  RenderSettings s;
  if (d.contains("mode")) {
    const auto mode = d["mode"].cast<std::string>();
    if (mode == "GPT")
      s.mode = RenderSettings::Mode::GPT;
    else if (mode == "PT")
      s.mode = RenderSettings::Mode::PT;
    else
      throw std::invalid_argument("unknown mode '" + mode + "'");
  }
  if (d.contains("pixel_filter")) {
    const auto filter = d["pixel_filter"].cast<std::string>();
    if (filter == "BOX")
      s.pixel_filter = PixelFilterType::Box;
    else if (filter == "GAUSSIAN")
      s.pixel_filter = PixelFilterType::Gaussian;
    else if (filter == "BLACKMAN_HARRIS")
      s.pixel_filter = PixelFilterType::BlackmanHarris;
    else
      throw std::invalid_argument("unknown pixel filter '" + filter + "'");
  }
  auto get = [&](const char* key, auto& out) {
    if (d.contains(key)) out = d[key].cast<std::decay_t<decltype(out)>>();
  };
  get("samples", s.samples);
  get("time_limit", s.time_limit);
  get("max_bounces", s.max_bounces);
  get("max_diffuse_bounces", s.max_diffuse_bounces);
  get("max_glossy_bounces", s.max_glossy_bounces);
  get("max_transmission_bounces", s.max_transmission_bounces);
  get("seed", s.seed);
  get("sample_offset", s.sample_offset);
  get("frame_samples", s.frame_samples);
  get("threads", s.threads);
  get("clamp", s.clamp);
  get("adaptive_threshold", s.adaptive_threshold);
  get("adaptive_min_samples", s.adaptive_min_samples);
  get("rr_depth", s.rr_depth);
  get("shift_threshold", s.shift_roughness_threshold);
  get("filter_width", s.filter_width);
  get("blur_glossy", s.blur_glossy);
  get("caustics_reflective", s.caustics_reflective);
  get("caustics_refractive", s.caustics_refractive);
  if (!(s.blur_glossy >= 0.0f)) throw std::invalid_argument("blur_glossy must be >= 0");
  get("samples_per_pass", s.samples_per_pass);
  get("transparent_background", s.transparent_background);
  get("normal_pass", s.normal_pass);
  get("mist_pass", s.mist_pass);
  get("mist_start", s.mist_start);
  get("mist_depth", s.mist_depth);
  get("mist_falloff", s.mist_falloff);
  get("feature_passes", s.feature_passes);
  return s;
}

ViewportDisplay display_from_dict(const py::dict& d) {
  ViewportDisplay v;
  if (d.contains("norm")) v.norm = d["norm"].cast<std::string>();
  if (d.contains("alpha")) v.alpha = d["alpha"].cast<float>();
  if (d.contains("start_divider")) v.start_divider = d["start_divider"].cast<int>();
  if (!(v.alpha > 0.0f)) throw std::invalid_argument("viewport: alpha must be > 0");
  return v;
}

// The passes of one view layer of a multilayer EXR (the compositor node reads files behind an
// Image node through this): {pass name: float32 (height, width, 3)}, rows bottom-up as Blender
// stores them. A missing required pass raises RuntimeError naming it.
py::dict read_exr_passes_dict(const std::string& path, const std::string& layer,
                              const std::vector<std::string>& required,
                              const std::vector<std::string>& optional) {
  ExrPasses passes;
  {
    py::gil_scoped_release no_gil;
    passes = read_exr_passes(path, layer, required, optional);
  }
  py::dict d;
  d["width"] = passes.width;
  d["height"] = passes.height;
  d["layer"] = passes.layer;
  for (const auto& [name, rgb] : passes.passes) {
    py::array_t<float> a({py::ssize_t(passes.height), py::ssize_t(passes.width), py::ssize_t(3)});
    std::memcpy(a.mutable_data(), rgb.data(), rgb.size() * sizeof(float));
    d[py::str(name)] = std::move(a);
  }
  return d;
}

}  // namespace

PYBIND11_MODULE(_gdpt, m) {
  m.doc() = "GDPT core bindings: build a scene from flat arrays, render it, reconstruct passes.";

  py::class_<StoredMesh>(m, "StoredMesh");

  py::class_<SceneBuilder>(m, "SceneBuilder")
      .def(py::init<>())
      .def("add_mesh", &SceneBuilder::add_mesh, py::arg("positions").noconvert(),
           py::arg("indices").noconvert(), py::arg("corner_normals").noconvert() = py::none(),
           py::arg("corner_uvs").noconvert() = py::none(),
           py::arg("material_slot").noconvert() = py::none())
      .def("add_mesh_loops", &SceneBuilder::add_mesh_loops, py::arg("positions").noconvert(),
           py::arg("loop_vertex").noconvert(), py::arg("corner_loops").noconvert(),
           py::arg("normals").noconvert(), py::arg("normals_per_loop"),
           py::arg("loop_uvs").noconvert(), py::arg("material_slot").noconvert(),
           py::arg("loop_tangents").noconvert() = py::none(),
           py::arg("loop_colors").noconvert() = py::none())
      .def("add_mesh_polys", &SceneBuilder::add_mesh_polys, py::arg("positions").noconvert(),
           py::arg("loop_vertex").noconvert(), py::arg("loop_start").noconvert(),
           py::arg("loop_total").noconvert(), py::arg("normals").noconvert(),
           py::arg("normals_per_loop"), py::arg("loop_uvs").noconvert(),
           py::arg("poly_material").noconvert(), py::arg("loop_tangents").noconvert() = py::none(),
           py::arg("loop_colors").noconvert() = py::none(),
           py::arg("smooth_vertex_normals") = false)
      .def("add_instance", &SceneBuilder::add_instance, py::arg("mesh"), py::arg("matrix"),
           py::arg("slot_material"), py::arg("pass_index") = 0,
           py::arg("visibility") = uint32_t(kRayAll), py::arg("holdout") = false,
           py::arg("terminator_geometry_offset") = 0.1f,
           py::arg("terminator_shading_offset") = 0.0f, py::arg("caustics_caster") = false,
           py::arg("caustics_receiver") = false)
      .def("add_material", &SceneBuilder::add_material)
      .def("add_image", &SceneBuilder::add_image, py::arg("name"), py::arg("width"),
           py::arg("height"), py::arg("rgba").noconvert(), py::arg("colorspace"))
      .def("add_light", &SceneBuilder::add_light)
      .def("set_camera", &SceneBuilder::set_camera)
      .def("set_world", &SceneBuilder::set_world)
      .def("mesh_arrays", &SceneBuilder::mesh_arrays, py::arg("index"))
      .def("instance_settings", &SceneBuilder::instance_settings, py::arg("index"))
      .def("light_settings", &SceneBuilder::light_settings, py::arg("index"))
      .def("stored_mesh", &SceneBuilder::stored_mesh, py::arg("index"))
      .def("add_stored_mesh", &SceneBuilder::add_stored_mesh, py::arg("stored"))
      .def("set_mesh_texspace", &SceneBuilder::set_mesh_texspace, py::arg("index"),
           py::arg("location"), py::arg("size"))
      .def("set_mesh_geometry_attributes", &SceneBuilder::set_mesh_geometry_attributes,
           py::arg("index"), py::arg("edges").noconvert(), py::arg("vertex_normals").noconvert(),
           py::arg("pointiness"), py::arg("random_per_island"))
      .def_property_readonly("mesh_count", &SceneBuilder::mesh_count)
      .def_property_readonly("instance_count", &SceneBuilder::instance_count)
      .def_property_readonly("triangle_count", &SceneBuilder::triangle_count);

  py::class_<RenderJob>(m, "RenderJob")
      .def(py::init([](SceneBuilder& builder, const py::dict& settings) {
             return std::make_unique<RenderJob>(builder, settings_from_dict(settings));
           }),
           py::arg("builder"), py::arg("settings"))
      .def("render", &RenderJob::render, py::arg("poll"), py::arg("poll_interval") = 0.1)
      .def("snapshot", [](py::object self) { return self.cast<RenderJob&>().snapshot(self); })
      .def("passes", &RenderJob::passes)
      .def("features_summary", &RenderJob::features_summary)
      .def("rays_traced", &RenderJob::rays_traced)
      .def("warnings", &RenderJob::warnings);

  py::class_<ViewportJob>(m, "ViewportJob")
      .def(py::init([](SceneBuilder& builder, const py::dict& settings, const py::dict& display) {
             return std::make_unique<ViewportJob>(builder, settings_from_dict(settings),
                                                  display_from_dict(display));
           }),
           py::arg("builder"), py::arg("settings"), py::arg("display"))
      .def("set_camera", &ViewportJob::set_camera, py::arg("camera"))
      .def(
          "update",
          [](ViewportJob& job, SceneBuilder& builder, const py::dict& settings,
             const py::dict& display) {
            job.update(builder, settings_from_dict(settings), display_from_dict(display));
          },
          py::arg("builder"), py::arg("settings"), py::arg("display"))
      .def("latest", &ViewportJob::latest, py::arg("seen") = -1)
      .def("status", &ViewportJob::status)
      .def("cancel", &ViewportJob::cancel)
      .def("stop", &ViewportJob::stop);

  m.def("empty", &empty_array, py::arg("count"), py::arg("dtype"),
        "numpy.empty((count,), dtype), its large pages advised as huge pages (faster first touch)");
  m.def("reconstruct", &reconstruct_arrays, py::arg("primal").noconvert(),
        py::arg("gradient_x").noconvert(), py::arg("gradient_y").noconvert(),
        py::arg("variance").noconvert() = py::none(), py::arg("emission").noconvert() = py::none(),
        py::arg("norm") = "L1", py::arg("alpha") = 0.2f, py::arg("threads") = 0,
        py::arg("features") = py::none(), py::arg("progress").noconvert() = py::none(),
        py::arg("initial").noconvert() = py::none(),
        "progress: optional float32 array; its first value is set to the solved fraction "
        "(0 to 1) while the solve runs without the GIL, for a caller polling from Python. "
        "initial: optional float32 array, a previous L1 result for the same passes (e.g. at "
        "another alpha): L1 starts from it with a much shorter schedule, WEIGHTED's solve "
        "starts from it");
  m.def("read_exr_passes", &read_exr_passes_dict, py::arg("path"), py::arg("layer"),
        py::arg("required"), py::arg("optional") = std::vector<std::string>{});
}

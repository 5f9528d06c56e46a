// See scene_convert.h for the dict layouts.
#include "blender_addon/module/scene_convert.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include <pybind11/stl.h>  // lists to std::vector (colour ramp tables)

#include "blender_addon/module/mesh_attributes.h"
#include "blender_addon/module/mesh_ingest.h"
#include "core/huge_pages.h"
#include "shaders/image_io.h"
#include "shaders/material.h"

namespace gdpt::python {

namespace {

// --- Small typed accessors: a missing key keeps the Scene's default --------------------------

template <typename T>
void get(const py::dict& d, const char* key, T& out) {
  if (d.contains(key)) out = d[key].cast<T>();
}

void get_vec3(const py::dict& d, const char* key, Vec3f& out) {
  if (!d.contains(key)) return;
  const auto seq = d[key].cast<py::sequence>();
  if (py::len(seq) < 3) throw std::invalid_argument(std::string(key) + ": expected 3 values");
  out = Vec3f(seq[0].cast<float>(), seq[1].cast<float>(), seq[2].cast<float>());
}

Transform to_transform(const py::handle& obj, const char* what) {
  const auto a = py::cast<FloatArray>(obj);
  if (a.size() != 12 && a.size() != 16)
    throw std::invalid_argument(std::string(what) + ": matrix needs 12 (3x4) or 16 (4x4) floats");
  return Transform::from_rows(a.data());  // the first three rows either way
}

void get_transform(const py::dict& d, const char* key, Transform& out) {
  if (d.contains(key)) out = to_transform(d[key], key);
}

std::string get_str(const py::dict& d, const char* key, const std::string& fallback) {
  return d.contains(key) ? d[key].cast<std::string>() : fallback;
}

[[noreturn]] void bad_enum(const char* what, const std::string& value) {
  throw std::invalid_argument(std::string("unknown ") + what + " '" + value + "'");
}

// d[key] (or `fallback` when missing) looked up by name in `table`; an unknown name is an error.
template <typename E, size_t N>
E get_enum(const py::dict& d, const char* key, const char* fallback,
           const std::pair<const char*, E> (&table)[N], const char* what) {
  const std::string name = get_str(d, key, fallback);
  for (const auto& [n, value] : table)
    if (name == n) return value;
  bad_enum(what, name);
}

// --- Material inputs ---------------------------------------------------------------------------

// {coordinates: 'UV' | 'GENERATED' | 'OBJECT' | 'POSITION' | 'NODE', vector_node: input node
// index (NODE), mapping: 12 floats}
void read_vector(const py::dict& d, TextureVector& v) {
  get_transform(d, "mapping", v.mapping);
  static const std::pair<const char*, TexCoordSource> kSources[] = {
      {"UV", TexCoordSource::UV},
      {"GENERATED", TexCoordSource::Generated},
      {"OBJECT", TexCoordSource::Object},
      {"POSITION", TexCoordSource::Position},
      {"NODE", TexCoordSource::Node}};
  v.source = get_enum(d, "coordinates", "UV", kSources, "texture coordinates");
  get(d, "vector_node", v.node);
}

void read_lookup(const py::dict& d, TextureLookup& t) {
  get(d, "image", t.image);
  read_vector(d, t.vector);
  const std::string interp = get_str(d, "interpolation", "Linear");
  if (interp == "Closest")
    t.interpolation = TextureLookup::Interpolation::Closest;
  else
    t.interpolation = TextureLookup::Interpolation::Linear;  // Cubic / Smart approximated
  const std::string ext = get_str(d, "extension", "REPEAT");
  if (ext == "REPEAT")
    t.extension = TextureLookup::Extension::Repeat;
  else if (ext == "EXTEND")
    t.extension = TextureLookup::Extension::Extend;
  else if (ext == "CLIP")
    t.extension = TextureLookup::Extension::Clip;
  else
    bad_enum("texture extension", ext);
}

void read_color(const py::dict& node, const char* key, ColorInput& out) {
  if (!node.contains(key)) return;
  const auto d = node[key].cast<py::dict>();
  get_vec3(d, "value", out.value);
  read_lookup(d, out.texture);
  get(d, "node", out.node);
}

void read_float(const py::dict& node, const char* key, FloatInput& out) {
  if (!node.contains(key)) return;
  const auto d = node[key].cast<py::dict>();
  get(d, "value", out.value);
  read_lookup(d, out.texture);
  get(d, "node", out.node);
  const std::string channel = get_str(d, "channel", "LUMINANCE");
  if (channel == "LUMINANCE")
    out.channel = FloatInput::Channel::Luminance;
  else if (channel == "RED")
    out.channel = FloatInput::Channel::Red;
  else if (channel == "ALPHA")
    out.channel = FloatInput::Channel::Alpha;
  else
    bad_enum("float channel", channel);
}

// {"kind": "MIX" | "MATH" | "INVERT", "blend": Blender's blend_type, "op": Blender's Math
// operation, "clamp_factor", "clamp_result", "fac", "a", "b" (colour inputs), "value_a",
// "value_b" (float inputs)}.
InputNode read_input_node(const py::dict& d) {
  InputNode n;
  static const std::pair<const char*, InputNodeKind> kKinds[] = {
      {"MIX", InputNodeKind::Mix},
      {"MATH", InputNodeKind::Math},
      {"INVERT", InputNodeKind::Invert},
      {"RAMP", InputNodeKind::Ramp},
      {"SEPARATE", InputNodeKind::Separate},
      {"COMBINE", InputNodeKind::Combine},
      {"COMBINE_XYZ", InputNodeKind::CombineXyz},
      {"GAMMA", InputNodeKind::Gamma},
      {"BRIGHT_CONTRAST", InputNodeKind::BrightContrast},
      {"HUE_SAT", InputNodeKind::HueSaturation},
      {"MAP_RANGE", InputNodeKind::MapRange},
      {"CLAMP", InputNodeKind::Clamp},
      {"RGB_TO_BW", InputNodeKind::ToBw},
      {"ATTRIBUTE", InputNodeKind::Attribute},
      {"CHECKER", InputNodeKind::Checker},
      {"NOISE", InputNodeKind::Noise},
      {"COORDINATES", InputNodeKind::Coordinates},
      {"VORONOI", InputNodeKind::Voronoi},
      {"GRADIENT", InputNodeKind::Gradient},
      {"WAVE", InputNodeKind::Wave},
      {"MUSGRAVE", InputNodeKind::Musgrave},
      {"WHITE_NOISE", InputNodeKind::WhiteNoise},
      {"MAGIC", InputNodeKind::Magic},
      {"VECTOR_MATH", InputNodeKind::VectorMath},
      {"BRICK", InputNodeKind::Brick},
      {"RGB_CURVES", InputNodeKind::RgbCurves},
      {"VECTOR_CURVES", InputNodeKind::VectorCurves},
      {"FLOAT_CURVE", InputNodeKind::FloatCurve},
      {"BLACKBODY", InputNodeKind::Blackbody},
      {"SEPARATE_HSV", InputNodeKind::SeparateHsv},
      {"COMBINE_HSV", InputNodeKind::CombineHsv},
      {"FRESNEL", InputNodeKind::Fresnel},
      {"LAYER_WEIGHT", InputNodeKind::LayerWeight},
      {"GEOMETRY", InputNodeKind::Geometry},
      {"LIGHT_PATH", InputNodeKind::LightPath},
      {"VECTOR_TRANSFORM", InputNodeKind::VectorTransform},
      {"WIREFRAME", InputNodeKind::Wireframe}};
  n.kind = get_enum(d, "kind", "MIX", kKinds, "input node kind");
  static const std::pair<const char*, MixBlend> kBlends[] = {{"MIX", MixBlend::Mix},
                                                             {"ADD", MixBlend::Add},
                                                             {"MULTIPLY", MixBlend::Multiply},
                                                             {"SUBTRACT", MixBlend::Subtract},
                                                             {"SCREEN", MixBlend::Screen},
                                                             {"DIVIDE", MixBlend::Divide},
                                                             {"DIFFERENCE", MixBlend::Difference},
                                                             {"DARKEN", MixBlend::Darken},
                                                             {"LIGHTEN", MixBlend::Lighten}};
  n.blend = get_enum(d, "blend", "MIX", kBlends, "mix blend");
  // Blender's Math node operation identifiers (bpy ShaderNodeMath.operation).
  static const std::pair<const char*, MathOp> kOps[] = {{"ADD", MathOp::Add},
                                                        {"SUBTRACT", MathOp::Subtract},
                                                        {"MULTIPLY", MathOp::Multiply},
                                                        {"DIVIDE", MathOp::Divide},
                                                        {"MULTIPLY_ADD", MathOp::MultiplyAdd},
                                                        {"POWER", MathOp::Power},
                                                        {"LOGARITHM", MathOp::Logarithm},
                                                        {"SQRT", MathOp::Sqrt},
                                                        {"INVERSE_SQRT", MathOp::InverseSqrt},
                                                        {"ABSOLUTE", MathOp::Absolute},
                                                        {"EXPONENT", MathOp::Exponent},
                                                        {"MINIMUM", MathOp::Minimum},
                                                        {"MAXIMUM", MathOp::Maximum},
                                                        {"LESS_THAN", MathOp::LessThan},
                                                        {"GREATER_THAN", MathOp::GreaterThan},
                                                        {"SIGN", MathOp::Sign},
                                                        {"COMPARE", MathOp::Compare},
                                                        {"SMOOTH_MIN", MathOp::SmoothMin},
                                                        {"SMOOTH_MAX", MathOp::SmoothMax},
                                                        {"ROUND", MathOp::Round},
                                                        {"FLOOR", MathOp::Floor},
                                                        {"CEIL", MathOp::Ceil},
                                                        {"TRUNC", MathOp::Trunc},
                                                        {"FRACT", MathOp::Fract},
                                                        {"MODULO", MathOp::Modulo},
                                                        {"WRAP", MathOp::Wrap},
                                                        {"SNAP", MathOp::Snap},
                                                        {"PINGPONG", MathOp::PingPong},
                                                        {"SINE", MathOp::Sine},
                                                        {"COSINE", MathOp::Cosine},
                                                        {"TANGENT", MathOp::Tangent},
                                                        {"ARCSINE", MathOp::Arcsine},
                                                        {"ARCCOSINE", MathOp::Arccosine},
                                                        {"ARCTANGENT", MathOp::Arctangent},
                                                        {"ARCTAN2", MathOp::Arctan2},
                                                        {"SINH", MathOp::Sinh},
                                                        {"COSH", MathOp::Cosh},
                                                        {"TANH", MathOp::Tanh},
                                                        {"RADIANS", MathOp::Radians},
                                                        {"DEGREES", MathOp::Degrees}};
  // Blender's Vector Math operation identifiers (bpy ShaderNodeVectorMath.operation).
  static const std::pair<const char*, VectorMathOp> kVectorOps[] = {
      {"ADD", VectorMathOp::Add},
      {"SUBTRACT", VectorMathOp::Subtract},
      {"MULTIPLY", VectorMathOp::Multiply},
      {"DIVIDE", VectorMathOp::Divide},
      {"MULTIPLY_ADD", VectorMathOp::MultiplyAdd},
      {"CROSS_PRODUCT", VectorMathOp::CrossProduct},
      {"PROJECT", VectorMathOp::Project},
      {"REFLECT", VectorMathOp::Reflect},
      {"REFRACT", VectorMathOp::Refract},
      {"FACEFORWARD", VectorMathOp::Faceforward},
      {"DOT_PRODUCT", VectorMathOp::DotProduct},
      {"DISTANCE", VectorMathOp::Distance},
      {"LENGTH", VectorMathOp::Length},
      {"SCALE", VectorMathOp::Scale},
      {"NORMALIZE", VectorMathOp::Normalize},
      {"SNAP", VectorMathOp::Snap},
      {"FLOOR", VectorMathOp::Floor},
      {"CEIL", VectorMathOp::Ceil},
      {"MODULO", VectorMathOp::Modulo},
      {"WRAP", VectorMathOp::Wrap},
      {"FRACTION", VectorMathOp::Fraction},
      {"ABSOLUTE", VectorMathOp::Absolute},
      {"MINIMUM", VectorMathOp::Minimum},
      {"MAXIMUM", VectorMathOp::Maximum},
      {"SINE", VectorMathOp::Sine},
      {"COSINE", VectorMathOp::Cosine},
      {"TANGENT", VectorMathOp::Tangent}};
  if (n.kind == InputNodeKind::VectorMath)
    n.vector_math = get_enum(d, "op", "ADD", kVectorOps, "vector math operation");
  else
    n.math = get_enum(d, "op", "ADD", kOps, "math operation");
  get(d, "clamp_factor", n.clamp_factor);
  get(d, "clamp_result", n.clamp_result);
  read_float(d, "fac", n.fac);
  read_color(d, "a", n.a);
  read_color(d, "b", n.b);
  read_color(d, "c", n.c);
  read_float(d, "value_a", n.value_a);
  read_float(d, "value_b", n.value_b);
  read_float(d, "value_c", n.value_c);
  read_float(d, "value_d", n.value_d);
  read_float(d, "value_e", n.value_e);
  read_float(d, "value_f", n.value_f);
  int channel = 0;
  get(d, "channel", channel);
  if (channel < 0 || channel > 2) throw std::invalid_argument("separate: channel out of range");
  n.channel = uint8_t(channel);
  if (d.contains("ramp")) n.ramp = d["ramp"].cast<std::vector<float>>();
  if (d.contains("bounds")) {
    const auto bounds = d["bounds"].cast<std::vector<float>>();
    if (bounds.size() != 4) throw std::invalid_argument("map range: expected 4 bounds");
    std::copy(bounds.begin(), bounds.end(), n.bounds.begin());
  }
  get(d, "ramp_interpolate", n.ramp_interpolate);
  get(d, "ramp_alpha", n.ramp_alpha);
  get(d, "clamp_range", n.clamp_range);
  if (d.contains("vector")) read_vector(d["vector"].cast<py::dict>(), n.vector);
  get(d, "fac_output", n.fac_output);
  get(d, "normal_linked", n.normal_linked);
  // Geometry: Blender's output names.
  static const std::pair<const char*, GeometryOutput> kGeometry[] = {
      {"Normal", GeometryOutput::Normal},
      {"True Normal", GeometryOutput::TrueNormal},
      {"Incoming", GeometryOutput::Incoming},
      {"Backfacing", GeometryOutput::Backfacing},
      {"Tangent", GeometryOutput::Tangent},
      {"Pointiness", GeometryOutput::Pointiness},
      {"Parametric", GeometryOutput::Parametric},
      {"Random Per Island", GeometryOutput::RandomPerIsland}};
  static const std::pair<const char*, LightPathOutput> kLightPath[] = {
      {"Is Camera Ray", LightPathOutput::IsCameraRay},
      {"Is Shadow Ray", LightPathOutput::IsShadowRay},
      {"Is Diffuse Ray", LightPathOutput::IsDiffuseRay},
      {"Is Glossy Ray", LightPathOutput::IsGlossyRay},
      {"Is Singular Ray", LightPathOutput::IsSingularRay},
      {"Is Reflection Ray", LightPathOutput::IsReflectionRay},
      {"Is Transmission Ray", LightPathOutput::IsTransmissionRay},
      {"Ray Length", LightPathOutput::RayLength},
      {"Ray Depth", LightPathOutput::RayDepth},
      {"Diffuse Depth", LightPathOutput::DiffuseDepth},
      {"Glossy Depth", LightPathOutput::GlossyDepth},
      {"Transparent Depth", LightPathOutput::TransparentDepth},
      {"Transmission Depth", LightPathOutput::TransmissionDepth}};
  if (n.kind == InputNodeKind::Geometry)
    n.geometry_output = get_enum(d, "output", "Normal", kGeometry, "geometry output");
  if (n.kind == InputNodeKind::LightPath)
    n.light_path_output = get_enum(d, "output", "Is Camera Ray", kLightPath, "light path output");
  // Vector Transform: Blender's vector_type, convert_from and convert_to.
  if (n.kind == InputNodeKind::VectorTransform) {
    using T = VectorTransformDesc;
    static const std::pair<const char*, T::Type> kTypes[] = {
        {"POINT", T::Type::Point}, {"VECTOR", T::Type::Vector}, {"NORMAL", T::Type::Normal}};
    static const std::pair<const char*, T::Space> kSpaces[] = {
        {"WORLD", T::Space::World}, {"OBJECT", T::Space::Object}, {"CAMERA", T::Space::Camera}};
    n.vector_transform.type = get_enum(d, "vector_type", "VECTOR", kTypes, "vector transform type");
    n.vector_transform.from = get_enum(d, "from", "WORLD", kSpaces, "vector transform space");
    n.vector_transform.to = get_enum(d, "to", "OBJECT", kSpaces, "vector transform space");
  }
  get(d, "pixel_size", n.pixel_size);
  // Brick: {"offset", "offset_frequency", "squash", "squash_frequency"} (the node's properties).
  if (d.contains("brick")) {
    const auto b = d["brick"].cast<py::dict>();
    get(b, "offset", n.brick.offset);
    get(b, "offset_frequency", n.brick.offset_frequency);
    get(b, "squash", n.brick.squash);
    get(b, "squash_frequency", n.brick.squash_frequency);
  }
  get(d, "position_output", n.position_output);
  int dimensions = 3;
  get(d, "dimensions", dimensions);
  if (dimensions < 1 || dimensions > 4) throw std::invalid_argument("noise: dimensions 1 to 4");
  n.noise_dimensions = uint8_t(dimensions);
  int depth = 2;
  get(d, "depth", depth);
  n.magic_depth = uint8_t(std::clamp(depth, 0, 10));
  static const std::pair<const char*, VoronoiMetric> kMetrics[] = {
      {"EUCLIDEAN", VoronoiMetric::Euclidean},
      {"MANHATTAN", VoronoiMetric::Manhattan},
      {"CHEBYCHEV", VoronoiMetric::Chebyshev},  // Blender's spelling
      {"MINKOWSKI", VoronoiMetric::Minkowski}};
  n.voronoi_metric = get_enum(d, "metric", "EUCLIDEAN", kMetrics, "voronoi metric");
  static const std::pair<const char*, InputNode::VoronoiFeature> kFeatures[] = {
      {"F1", InputNode::VoronoiFeature::F1},
      {"F2", InputNode::VoronoiFeature::F2},
      {"SMOOTH_F1", InputNode::VoronoiFeature::SmoothF1},
      {"DISTANCE_TO_EDGE", InputNode::VoronoiFeature::DistanceToEdge}};
  n.voronoi_feature = get_enum(d, "feature", "F1", kFeatures, "voronoi feature");
  static const std::pair<const char*, GradientType> kGradients[] = {
      {"LINEAR", GradientType::Linear},       {"QUADRATIC", GradientType::Quadratic},
      {"EASING", GradientType::Easing},       {"DIAGONAL", GradientType::Diagonal},
      {"SPHERICAL", GradientType::Spherical}, {"QUADRATIC_SPHERE", GradientType::QuadraticSphere},
      {"RADIAL", GradientType::Radial}};
  n.gradient_type = get_enum(d, "gradient", "LINEAR", kGradients, "gradient type");
  if (n.kind == InputNodeKind::Musgrave) {
    static const std::pair<const char*, MusgraveType> kTypes[] = {
        {"FBM", MusgraveType::Fbm},
        {"MULTIFRACTAL", MusgraveType::Multifractal},
        {"HETERO_TERRAIN", MusgraveType::HeteroTerrain},
        {"HYBRID_MULTIFRACTAL", MusgraveType::HybridMultifractal},
        {"RIDGED_MULTIFRACTAL", MusgraveType::RidgedMultifractal}};
    n.musgrave_type = get_enum(d, "musgrave_type", "FBM", kTypes, "musgrave type");
  }
  if (n.kind == InputNodeKind::Wave) {
    static const std::pair<const char*, WaveDesc::Type> kWaveTypes[] = {
        {"BANDS", WaveDesc::Type::Bands}, {"RINGS", WaveDesc::Type::Rings}};
    n.wave.type = get_enum(d, "wave_type", "BANDS", kWaveTypes, "wave type");
    static const std::pair<const char*, WaveDesc::Direction> kDirections[] = {
        {"X", WaveDesc::Direction::X},
        {"Y", WaveDesc::Direction::Y},
        {"Z", WaveDesc::Direction::Z},
        {"DIAGONAL", WaveDesc::Direction::Other},
        {"SPHERICAL", WaveDesc::Direction::Other}};
    n.wave.direction = get_enum(d, "direction", "X", kDirections, "wave direction");
    static const std::pair<const char*, WaveDesc::Profile> kProfiles[] = {
        {"SIN", WaveDesc::Profile::Sine},
        {"SAW", WaveDesc::Profile::Saw},
        {"TRI", WaveDesc::Profile::Triangle}};
    n.wave.profile = get_enum(d, "profile", "SIN", kProfiles, "wave profile");
  }
  return n;
}

// {"source": "RADIAL" | "UV_MAP" | "VECTOR", "axis": 0-2 (RADIAL), "vector": colour input}.
void read_tangent(const py::dict& d, TangentInput& t) {
  static const std::pair<const char*, TangentInput::Source> kSources[] = {
      {"RADIAL", TangentInput::Source::Radial},
      {"UV_MAP", TangentInput::Source::UVMap},
      {"VECTOR", TangentInput::Source::Vector}};
  t.source = get_enum(d, "source", "RADIAL", kSources, "tangent source");
  int axis = 2;
  get(d, "axis", axis);
  if (axis < 0 || axis > 2) throw std::invalid_argument("tangent axis out of range (0-2)");
  t.axis = uint8_t(axis);
  read_color(d, "vector", t.vector);
}

ShaderNodeKind to_kind(const std::string& kind) {
  if (kind == "DIFFUSE") return ShaderNodeKind::Diffuse;
  if (kind == "GLOSSY") return ShaderNodeKind::Glossy;
  if (kind == "GLASS") return ShaderNodeKind::Glass;
  if (kind == "PRINCIPLED") return ShaderNodeKind::Principled;
  if (kind == "EMISSION") return ShaderNodeKind::Emission;
  if (kind == "TRANSPARENT") return ShaderNodeKind::Transparent;
  if (kind == "TRANSLUCENT") return ShaderNodeKind::Translucent;
  if (kind == "REFRACTION") return ShaderNodeKind::Refraction;
  if (kind == "VELVET") return ShaderNodeKind::Velvet;
  if (kind == "ANISOTROPIC") return ShaderNodeKind::Anisotropic;
  if (kind == "MIX") return ShaderNodeKind::Mix;
  if (kind == "ADD") return ShaderNodeKind::Add;
  bad_enum("shader node kind", kind);
}

template <typename T>
const T* checked_data(const py::array_t<T, py::array::c_style>& a, size_t expected,
                      const char* what) {
  if (size_t(a.size()) != expected)
    throw std::invalid_argument(std::string(what) + ": expected " + std::to_string(expected) +
                                " values, got " + std::to_string(a.size()));
  return a.data();
}

}  // namespace

py::array empty_array(py::ssize_t count, const py::dtype& dtype) {
  if (count < 0) throw std::invalid_argument("empty: negative count");
  void* p = allocate_huge(size_t(count) * size_t(dtype.itemsize()));
  py::capsule owner(p, [](void* q) { free_huge(q); });
  return py::array(dtype, {count}, {}, p, owner);
}

// --- Geometry ----------------------------------------------------------------------------------

namespace {

template <typename T>
std::span<const T> view(const py::array_t<T, py::array::c_style>& a) {
  return {a.data(), size_t(a.size())};
}

template <typename T>
std::span<const T> view(const std::optional<py::array_t<T, py::array::c_style>>& a) {
  return a ? view(*a) : std::span<const T>{};
}

ingest::LoopArrays loop_arrays(const FloatArray& positions, const IntArray& loop_vertex,
                               const FloatArray& normals, bool normals_per_loop,
                               const FloatArray& loop_uvs,
                               const std::optional<FloatArray>& loop_tangents,
                               const std::optional<FloatArray>& loop_colors) {
  return {view(positions), view(loop_vertex),   view(normals),    normals_per_loop,
          view(loop_uvs),  view(loop_tangents), view(loop_colors)};
}

}  // namespace

// The ingest functions validate every array (std::invalid_argument -> ValueError) and read only
// numpy buffers the caller keeps alive, so they run without the GIL.
int SceneBuilder::add_mesh(const FloatArray& positions, const IntArray& indices,
                           const std::optional<FloatArray>& corner_normals,
                           const std::optional<FloatArray>& corner_uvs,
                           const std::optional<IntArray>& material_slot) {
  Mesh mesh;
  {
    py::gil_scoped_release no_gil;
    mesh = ingest::mesh_from_triangles(view(positions), view(indices), view(corner_normals),
                                       view(corner_uvs), view(material_slot));
  }
  scene_.meshes.push_back(std::move(mesh));
  return int(scene_.meshes.size()) - 1;
}

int SceneBuilder::add_mesh_loops(const FloatArray& positions, const IntArray& loop_vertex,
                                 const IntArray& corner_loops, const FloatArray& normals,
                                 bool normals_per_loop, const FloatArray& loop_uvs,
                                 const IntArray& material_slot,
                                 const std::optional<FloatArray>& loop_tangents,
                                 const std::optional<FloatArray>& loop_colors) {
  Mesh mesh;
  {
    py::gil_scoped_release no_gil;
    mesh = ingest::mesh_from_loops(loop_arrays(positions, loop_vertex, normals, normals_per_loop,
                                               loop_uvs, loop_tangents, loop_colors),
                                   view(corner_loops), view(material_slot));
  }
  scene_.meshes.push_back(std::move(mesh));
  return int(scene_.meshes.size()) - 1;
}

int SceneBuilder::add_mesh_polys(const FloatArray& positions, const IntArray& loop_vertex,
                                 const IntArray& loop_start, const IntArray& loop_total,
                                 const FloatArray& normals, bool normals_per_loop,
                                 const FloatArray& loop_uvs, const IntArray& poly_material,
                                 const std::optional<FloatArray>& loop_tangents,
                                 const std::optional<FloatArray>& loop_colors,
                                 bool smooth_vertex_normals) {
  Mesh mesh;
  {
    py::gil_scoped_release no_gil;
    mesh = ingest::mesh_from_polys(loop_arrays(positions, loop_vertex, normals, normals_per_loop,
                                               loop_uvs, loop_tangents, loop_colors),
                                   view(loop_start), view(loop_total), view(poly_material),
                                   smooth_vertex_normals);
  }
  scene_.meshes.push_back(std::move(mesh));
  return int(scene_.meshes.size()) - 1;
}

void SceneBuilder::set_mesh_texspace(int index, const py::sequence& location,
                                     const py::sequence& size) {
  if (index < 0 || size_t(index) >= scene_.meshes.size())
    throw std::invalid_argument("set_mesh_texspace: mesh index out of range");
  if (py::len(location) != 3 || py::len(size) != 3)
    throw std::invalid_argument("set_mesh_texspace: expected 3 values each");
  Mesh& m = scene_.meshes[size_t(index)];
  for (int k = 0; k < 3; ++k) {
    m.texspace_location[k] = location[k].cast<float>();
    m.texspace_size[k] = size[k].cast<float>();
  }
}

void SceneBuilder::set_mesh_geometry_attributes(int index, const IntArray& edges,
                                                const FloatArray& vertex_normals, bool pointiness,
                                                bool random_per_island) {
  if (index < 0 || size_t(index) >= scene_.meshes.size())
    throw std::invalid_argument("set_mesh_geometry_attributes: mesh index out of range");
  ingest::add_geometry_attributes(scene_.meshes[size_t(index)], view(edges), view(vertex_normals),
                                  pointiness, random_per_island);
}

py::dict SceneBuilder::mesh_arrays(int index) const {
  if (index < 0 || size_t(index) >= scene_.meshes.size())
    throw std::invalid_argument("mesh_arrays: mesh index out of range");
  const Mesh& m = scene_.meshes[size_t(index)];
  auto copy = [](const auto& v, std::vector<py::ssize_t> shape, auto scalar) {
    py::array_t<decltype(scalar)> a(shape);
    std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(v[0]));
    return a;
  };
  const auto t = py::ssize_t(m.triangle_count());
  py::dict d;
  d["positions"] = copy(m.positions, {py::ssize_t(m.positions.size()), 3}, 0.0f);
  d["indices"] = copy(m.indices, {t, 3}, uint32_t(0));
  d["vertex_normals"] = copy(m.vertex_normals, {py::ssize_t(m.vertex_normals.size()), 3}, 0.0f);
  d["corner_normals"] = copy(m.corner_normals, {m.corner_normals.empty() ? 0 : t, 3, 3}, 0.0f);
  d["corner_uvs"] = copy(m.corner_uvs, {m.corner_uvs.empty() ? 0 : t, 3, 2}, 0.0f);
  d["material_slot"] = copy(m.material_slot, {py::ssize_t(m.material_slot.size())}, int32_t(0));
  d["corner_tangents"] = copy(m.corner_tangents, {m.corner_tangents.empty() ? 0 : t, 3, 3}, 0.0f);
  d["corner_tangent_signs"] =
      copy(m.corner_tangent_signs, {m.corner_tangent_signs.empty() ? 0 : t, 3}, 0.0f);
  d["corner_colors"] = copy(m.corner_colors, {m.corner_colors.empty() ? 0 : t, 3, 3}, 0.0f);
  d["vertex_pointiness"] =
      copy(m.vertex_pointiness, {py::ssize_t(m.vertex_pointiness.size())}, 0.0f);
  d["triangle_island_random"] =
      copy(m.triangle_island_random, {py::ssize_t(m.triangle_island_random.size())}, 0.0f);
  return d;
}

void SceneBuilder::add_instance(int mesh, const FloatArray& matrix, const py::list& slot_material,
                                int pass_index, uint32_t visibility, bool holdout,
                                float terminator_geometry_offset, float terminator_shading_offset,
                                bool caustics_caster, bool caustics_receiver) {
  if (mesh < 0 || size_t(mesh) >= scene_.meshes.size())
    throw std::invalid_argument("add_instance: mesh index out of range");
  if (!(terminator_geometry_offset >= 0.0f && terminator_geometry_offset <= 1.0f))
    throw std::invalid_argument("add_instance: terminator_geometry_offset is " +
                                std::to_string(terminator_geometry_offset) +
                                ", outside [0, 1] (Cycles' Shadow Terminator Geometry Offset)");
  if (!(terminator_shading_offset >= 0.0f && terminator_shading_offset <= 1.0f))
    throw std::invalid_argument("add_instance: terminator_shading_offset is " +
                                std::to_string(terminator_shading_offset) +
                                ", outside [0, 1] (Cycles' Shadow Terminator Shading Offset)");
  Instance inst;
  inst.mesh = uint32_t(mesh);
  inst.object_to_world = to_transform(matrix, "instance");
  inst.pass_index = float(pass_index);
  inst.visibility = visibility;
  inst.holdout = holdout;
  inst.terminator_geometry_offset = terminator_geometry_offset;
  inst.terminator_shading_offset = terminator_shading_offset;
  inst.caustics_caster = caustics_caster;
  inst.caustics_receiver = caustics_receiver;
  inst.slot_material.reserve(py::len(slot_material));
  for (const auto& m : slot_material) {
    const int32_t index = m.cast<int32_t>();
    if (index < -1 || index >= int32_t(scene_.materials.size()))
      throw std::invalid_argument(
          "slot_material: value " + std::to_string(inst.slot_material.size()) + " is " +
          std::to_string(index) + ", out of range [-1, " + std::to_string(scene_.materials.size()) +
          ") (the scene's materials; -1: default)");
    inst.slot_material.push_back(index);
  }
  scene_.instances.push_back(std::move(inst));
}

py::dict SceneBuilder::instance_settings(int index) const {
  if (index < 0 || size_t(index) >= scene_.instances.size())
    throw std::invalid_argument("instance_settings: instance index out of range");
  const Instance& inst = scene_.instances[size_t(index)];
  py::dict d;
  d["pass_index"] = inst.pass_index;
  d["visibility"] = inst.visibility;
  d["holdout"] = inst.holdout;
  d["terminator_geometry_offset"] = inst.terminator_geometry_offset;
  d["terminator_shading_offset"] = inst.terminator_shading_offset;
  d["caustics_caster"] = inst.caustics_caster;
  d["caustics_receiver"] = inst.caustics_receiver;
  return d;
}

py::dict SceneBuilder::light_settings(int index) const {
  if (index < 0 || size_t(index) >= scene_.lights.size())
    throw std::invalid_argument("light_settings: light index out of range");
  const Light& light = scene_.lights[size_t(index)];
  py::dict d;
  d["camera_visible"] = light.camera_visible;
  d["cast_shadow"] = light.cast_shadow;
  d["caustics_light"] = light.caustics_light;
  return d;
}

size_t SceneBuilder::triangle_count() const {
  size_t n = 0;
  for (const Instance& inst : scene_.instances) n += scene_.meshes[inst.mesh].triangle_count();
  return n;
}

// --- Materials and images ----------------------------------------------------------------------

// Compiles the material once against 1x1 stand-ins for the images, so what the render would
// reject (cyclic or too deep trees, malformed tables) is reported now, naming the material, and
// the add-on can put a stand-in in its place instead of failing the render.
void SceneBuilder::validate_material(const MaterialDesc& desc) {
  ImageDesc pixel;
  pixel.width = pixel.height = 1;
  pixel.rgba = {0.0f, 0.0f, 0.0f, 1.0f};
  while (image_stand_ins_.size() < scene_.images.size()) image_stand_ins_.emplace_back(pixel);
  Material(desc, std::span<const Texture>(image_stand_ins_.data(), scene_.images.size()));
}

int SceneBuilder::add_material(const py::dict& material) {
  MaterialDesc desc;
  desc.name = get_str(material, "name", "");
  get(material, "root", desc.root);
  get(material, "pass_index", desc.pass_index);
  if (material.contains("nodes")) {
    for (const auto& item : material["nodes"].cast<py::list>()) {
      const auto d = item.cast<py::dict>();
      ShaderNode node;
      node.kind = to_kind(get_str(d, "kind", "DIFFUSE"));
      read_color(d, "color", node.color);
      read_float(d, "roughness", node.roughness);
      read_float(d, "ior", node.ior);
      static const std::pair<const char*, MicrofacetDistribution> kDistributions[] = {
          {"GGX", MicrofacetDistribution::GGX},
          {"BECKMANN", MicrofacetDistribution::Beckmann},
          {"ASHIKHMIN_SHIRLEY", MicrofacetDistribution::AshikhminShirley},
          {"MULTI_GGX", MicrofacetDistribution::MultiscatterGGX}};
      node.distribution =
          get_enum(d, "distribution", "GGX", kDistributions, "microfacet distribution");
      // Blender offers Ashikhmin-Shirley on the Glossy and Anisotropic BSDFs only.
      if (node.distribution == MicrofacetDistribution::AshikhminShirley &&
          node.kind != ShaderNodeKind::Glossy && node.kind != ShaderNodeKind::Anisotropic)
        throw std::invalid_argument("microfacet distribution 'ASHIKHMIN_SHIRLEY' on a " +
                                    get_str(d, "kind", "DIFFUSE") + " node");
      // Blender offers Multiscatter GGX on these.
      if (node.distribution == MicrofacetDistribution::MultiscatterGGX &&
          node.kind != ShaderNodeKind::Glossy && node.kind != ShaderNodeKind::Principled &&
          node.kind != ShaderNodeKind::Glass && node.kind != ShaderNodeKind::Anisotropic)
        throw std::invalid_argument("microfacet distribution 'MULTI_GGX' on a " +
                                    get_str(d, "kind", "DIFFUSE") + " node");
      read_float(d, "strength", node.strength);
      read_float(d, "fac", node.fac);
      get(d, "a", node.a);
      get(d, "b", node.b);
      read_float(d, "metallic", node.metallic);
      read_float(d, "specular", node.specular);
      read_float(d, "specular_tint", node.specular_tint);
      read_float(d, "transmission", node.transmission);
      read_float(d, "sheen", node.sheen);
      read_float(d, "sheen_tint", node.sheen_tint);
      read_float(d, "clearcoat", node.clearcoat);
      read_float(d, "clearcoat_roughness", node.clearcoat_roughness);
      get(d, "normal_linked", node.normal_linked);
      get(d, "clearcoat_normal_linked", node.clearcoat_normal_linked);
      read_float(d, "alpha", node.alpha);
      read_color(d, "emission", node.emission);
      read_float(d, "emission_strength", node.emission_strength);
      read_float(d, "subsurface", node.subsurface);
      read_color(d, "subsurface_color", node.subsurface_color);
      read_float(d, "anisotropy", node.anisotropy);
      read_float(d, "rotation", node.rotation);
      if (d.contains("tangent")) read_tangent(d["tangent"].cast<py::dict>(), node.tangent);
      desc.nodes.push_back(node);
    }
  }
  if (material.contains("inputs"))
    for (const auto& item : material["inputs"].cast<py::list>())
      desc.inputs.push_back(read_input_node(item.cast<py::dict>()));
  // Bump nodes, in MaterialDesc::bumps' order: [{"height": float input, "strength", "distance":
  // float, "invert": bool, "replaces_normal": bool (the Displacement output, first only)}, and
  // for a vector displacement "vector" and "vector_space" (BumpDesc)].
  if (material.contains("bumps"))
    for (const auto& item : material["bumps"].cast<py::list>()) {
      const auto d = item.cast<py::dict>();
      BumpDesc& bump = desc.bumps.emplace_back();
      read_float(d, "height", bump.height);
      get(d, "strength", bump.strength);
      get(d, "distance", bump.distance);
      get(d, "invert", bump.invert);
      get(d, "replaces_normal", bump.replaces_normal);
      // A vector displacement: "vector": colour input, "vector_space": TANGENT, OBJECT or WORLD.
      if (d.contains("vector_space")) {
        static const std::pair<const char*, BumpDesc::VectorSpace> kSpaces[] = {
            {"TANGENT", BumpDesc::VectorSpace::Tangent},
            {"OBJECT", BumpDesc::VectorSpace::Object},
            {"WORLD", BumpDesc::VectorSpace::World}};
        bump.vector_space = get_enum(d, "vector_space", "", kSpaces, "vector displacement space");
        read_color(d, "vector", bump.vector);
        if (!bump.replaces_normal)
          throw std::invalid_argument("material '" + desc.name +
                                      "': a vector displacement must replace the normal");
      }
      if (bump.replaces_normal && desc.bumps.size() > 1)
        throw std::invalid_argument("material '" + desc.name +
                                    "': only the first bump may replace the normal");
      if (bump.height.texture.image >= int32_t(scene_.images.size()) ||
          bump.vector.texture.image >= int32_t(scene_.images.size()))
        throw std::invalid_argument("material '" + desc.name + "': image index out of range");
    }
  // Normal Map node (tangent space): {"color": colour input, "strength": float}.
  if (material.contains("normal_map")) {
    const auto d = material["normal_map"].cast<py::dict>();
    desc.normal_map.enabled = true;
    read_color(d, "color", desc.normal_map.color);
    get(d, "strength", desc.normal_map.strength);
  }
  // Child and image indices are checked here so a bad export fails with a message, not a crash.
  const auto n = int32_t(desc.nodes.size());
  if (desc.root < -1 || desc.root >= n) throw std::invalid_argument("material root out of range");
  for (const ShaderNode& node : desc.nodes) {
    if (node.a < -1 || node.a >= n || node.b < -1 || node.b >= n)
      throw std::invalid_argument("material '" + desc.name + "': child index out of range");
    for (const TextureLookup* t : {&node.color.texture,
                                   &node.roughness.texture,
                                   &node.ior.texture,
                                   &node.strength.texture,
                                   &node.fac.texture,
                                   &node.metallic.texture,
                                   &node.specular.texture,
                                   &node.specular_tint.texture,
                                   &node.transmission.texture,
                                   &node.sheen.texture,
                                   &node.sheen_tint.texture,
                                   &node.clearcoat.texture,
                                   &node.clearcoat_roughness.texture,
                                   &node.alpha.texture,
                                   &node.emission.texture,
                                   &node.emission_strength.texture,
                                   &node.subsurface.texture,
                                   &node.subsurface_color.texture,
                                   &node.anisotropy.texture,
                                   &node.rotation.texture,
                                   &node.tangent.vector.texture}) {
      if (t->image >= int32_t(scene_.images.size()))
        throw std::invalid_argument("material '" + desc.name + "': image index out of range");
    }
  }
  if (desc.normal_map.color.texture.image >= int32_t(scene_.images.size()))
    throw std::invalid_argument("material '" + desc.name + "': image index out of range");
  for (const InputNode& node : desc.inputs)
    for (const TextureLookup* t :
         {&node.fac.texture, &node.a.texture, &node.b.texture, &node.c.texture,
          &node.value_a.texture, &node.value_b.texture, &node.value_c.texture,
          &node.value_d.texture, &node.value_e.texture, &node.value_f.texture})
      if (t->image >= int32_t(scene_.images.size()))
        throw std::invalid_argument("material '" + desc.name + "': image index out of range");
  validate_material(desc);
  scene_.materials.push_back(std::move(desc));
  return int(scene_.materials.size()) - 1;
}

int SceneBuilder::add_image(const std::string& name, int width, int height, const FloatArray& rgba,
                            const std::string& colorspace) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("image '" + name + "': empty");
  ImageDesc image;
  image.name = name;
  image.width = width;
  image.height = height;
  const size_t count = size_t(width) * size_t(height) * 4;
  const float* p = checked_data(rgba, count, "image pixels");
  image.rgba.assign(p, p + count);
  // 8-bit sRGB images stay encoded and are decoded after interpolation, as Cycles does.
  if (colorspace == "sRGB")
    image.srgb_encoded = true;
  else if (!colorspace.empty())
    convert_to_scene_linear(image, colorspace);
  scene_.images.push_back(std::move(image));
  return int(scene_.images.size()) - 1;
}

// --- Lights, camera, world ---------------------------------------------------------------------

void SceneBuilder::add_light(const py::dict& d) {
  Light light;
  const std::string type = get_str(d, "type", "POINT");
  if (type == "POINT")
    light.type = Light::Type::Point;
  else if (type == "SPOT")
    light.type = Light::Type::Spot;
  else if (type == "SUN")
    light.type = Light::Type::Sun;
  else if (type == "AREA")
    light.type = Light::Type::Area;
  else
    bad_enum("light type", type);
  const std::string shape = get_str(d, "shape", "SQUARE");
  if (shape == "SQUARE")
    light.shape = Light::Shape::Square;
  else if (shape == "RECTANGLE")
    light.shape = Light::Shape::Rectangle;
  else if (shape == "DISK")
    light.shape = Light::Shape::Disk;
  else if (shape == "ELLIPSE")
    light.shape = Light::Shape::Ellipse;
  else
    bad_enum("area light shape", shape);
  get_transform(d, "matrix", light.light_to_world);
  get_vec3(d, "color", light.color);
  get(d, "power", light.power);
  get(d, "radius", light.radius);
  get(d, "spot_size", light.spot_size);
  get(d, "spot_blend", light.spot_blend);
  get(d, "sun_angle", light.sun_angle);
  get(d, "size_x", light.size_x);
  get(d, "size_y", light.size_y);
  get(d, "camera_visible", light.camera_visible);
  get(d, "cast_shadow", light.cast_shadow);
  get(d, "caustics_light", light.caustics_light);
  scene_.lights.push_back(light);
}

void SceneBuilder::set_camera(const py::dict& d) {
  Camera& c = scene_.camera;
  const std::string projection = get_str(d, "projection", "PERSP");
  if (projection == "PERSP")
    c.projection = Camera::Projection::Perspective;
  else if (projection == "ORTHO")
    c.projection = Camera::Projection::Orthographic;
  else
    bad_enum("camera projection", projection);
  const std::string fit = get_str(d, "sensor_fit", "AUTO");
  if (fit == "AUTO")
    c.sensor_fit = Camera::SensorFit::Auto;
  else if (fit == "HORIZONTAL")
    c.sensor_fit = Camera::SensorFit::Horizontal;
  else if (fit == "VERTICAL")
    c.sensor_fit = Camera::SensorFit::Vertical;
  else
    bad_enum("sensor fit", fit);
  get_transform(d, "matrix", c.camera_to_world);
  get(d, "focal_length_mm", c.focal_length_mm);
  get(d, "sensor_width_mm", c.sensor_width_mm);
  get(d, "sensor_height_mm", c.sensor_height_mm);
  get(d, "shift_x", c.shift_x);
  get(d, "shift_y", c.shift_y);
  get(d, "ortho_scale", c.ortho_scale);
  get(d, "clip_start", c.clip_start);
  get(d, "clip_end", c.clip_end);
  get(d, "aperture_radius", c.aperture_radius);
  get(d, "focus_distance", c.focus_distance);
  get(d, "width", c.width);
  get(d, "height", c.height);
  get(d, "pixel_aspect", c.pixel_aspect);
  get(d, "region_x", c.region_x);
  get(d, "region_y", c.region_y);
  get(d, "region_width", c.region_width);
  get(d, "region_height", c.region_height);
}

namespace {
// {"color", "strength", "image", "rotation"}: a Background (`what` names it in errors).
void read_background(const py::dict& d, size_t images, const char* what, Background& b) {
  get_vec3(d, "color", b.color);
  get(d, "strength", b.strength);
  get(d, "image", b.image);
  if (b.image >= int32_t(images))
    throw std::invalid_argument(std::string(what) + ": image index out of range");
  get_transform(d, "rotation", b.rotation);
}
}  // namespace

void SceneBuilder::set_world(const py::dict& d) {
  World& w = scene_.world;
  read_background(d, scene_.images.size(), "world", w);
  // {"camera": the same keys}: the background camera rays see (World::camera_view).
  if (d.contains("camera")) {
    Background v;
    read_background(d["camera"].cast<py::dict>(), scene_.images.size(), "world camera view", v);
    w.camera_view = v;
  }
}

StoredMesh SceneBuilder::stored_mesh(int index) const {
  if (index < 0 || size_t(index) >= scene_.meshes.size())
    throw std::out_of_range("stored_mesh: no mesh " + std::to_string(index));
  return StoredMesh{std::make_shared<const Mesh>(scene_.meshes[size_t(index)])};
}

int SceneBuilder::add_stored_mesh(const StoredMesh& stored) {
  if (!stored.mesh) throw std::invalid_argument("add_stored_mesh: an empty stored mesh");
  scene_.meshes.push_back(*stored.mesh);
  return int(scene_.meshes.size()) - 1;
}

}  // namespace gdpt::python

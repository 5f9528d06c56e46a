// Material: a MaterialDesc node tree evaluated at a hit point into a ClosureSet.
//
// The tree is walked depth-first with a fixed-size explicit stack of (node, weight) pairs; Mix
// gives (1 - fac) w to its first child and fac w to its second (fac clamped to [0, 1], as
// Cycles), Add gives w to both. Each BSDF node adds its lobes with weight w, Emission nodes and
// Principled emission add colour * strength * w to the emission. Inputs are constants or image
// lookups at mapping.point(u, v, 0).
//
// The same walk, with texture inputs replaced by the texture's mean, gives average_emission().
#include "shaders/material.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "shaders/bsdf_ggx_multiscatter.h"
#include "shaders/curves_node.h"
#include "shaders/math_node.h"
#include "shaders/microfacet.h"
#include "shaders/object_nodes.h"
#include "shaders/principled.h"
#include "shaders/procedural_texture.h"
#include "shaders/vector_math_node.h"
#include "shaders/view_nodes.h"

namespace gdpt {

namespace {

// Deepest Mix/Add nesting accepted (the explicit stack holds at most depth + 1 entries).
constexpr int kMaxTreeDepth = 32;

struct StackEntry {
  int32_t node;
  float weight;
};

// The value a scalar input reads from a texel (Blender links Color or Alpha to a float socket).
float channel(const Rgba& c, FloatInput::Channel which) {
  switch (which) {
    case FloatInput::Channel::Red:
      return c.rgb.x;
    case FloatInput::Channel::Alpha:
      return c.a;
    case FloatInput::Channel::Luminance:
      break;
  }
  return luminance(c.rgb);
}

// Cycles' svm_mix for the supported blend types (t already clamped when the node asks).
Spectrum mix_blend(MixBlend blend, float t, Spectrum a, Spectrum b) {
  switch (blend) {
    case MixBlend::Mix:
      return lerp(a, b, t);
    case MixBlend::Add:
      return a + b * t;
    case MixBlend::Multiply:
      return a * (Spectrum(1.0f - t) + b * t);
    case MixBlend::Subtract:
      return a - b * t;
    case MixBlend::Screen:
      return Spectrum(1.0f) -
             (Spectrum(1.0f - t) + (Spectrum(1.0f) - b) * t) * (Spectrum(1.0f) - a);
    case MixBlend::Divide: {
      Spectrum r = a;
      for (int k = 0; k < 3; ++k)
        if (b[k] != 0.0f) r[k] = (1.0f - t) * a[k] + t * a[k] / b[k];
      return r;
    }
    case MixBlend::Difference:
      return lerp(a, Spectrum(std::fabs(a.x - b.x), std::fabs(a.y - b.y), std::fabs(a.z - b.z)), t);
    case MixBlend::Darken:
      return lerp(a, Spectrum(std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)), t);
    case MixBlend::Lighten:
      return lerp(a, Spectrum(std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)), t);
  }
  return a;
}

// Cycles' rgb_to_hsv / hsv_to_rgb (util/color.h).
Vec3f rgb_to_hsv(Spectrum rgb) {
  const float cmax = std::max(rgb.x, std::max(rgb.y, rgb.z));
  const float cmin = std::min(rgb.x, std::min(rgb.y, rgb.z));
  const float cdelta = cmax - cmin;
  const float s = cmax != 0.0f ? cdelta / cmax : 0.0f;
  float h = 0.0f;
  if (s != 0.0f) {
    const Spectrum c = (Spectrum(cmax) - rgb) / cdelta;
    if (rgb.x == cmax)
      h = c.z - c.y;
    else if (rgb.y == cmax)
      h = 2.0f + c.x - c.z;
    else
      h = 4.0f + c.y - c.x;
    h /= 6.0f;
    if (h < 0.0f) h += 1.0f;
  }
  return {h, s, cmax};
}
Spectrum hsv_to_rgb(Vec3f hsv) {
  float h = hsv.x;
  const float s = hsv.y, v = hsv.z;
  if (s == 0.0f) return Spectrum(v);
  if (h == 1.0f) h = 0.0f;
  h *= 6.0f;
  const float i = std::floor(h), f = h - i;
  const float p = v * (1.0f - s), q = v * (1.0f - s * f), t = v * (1.0f - s * (1.0f - f));
  if (i == 0.0f) return {v, t, p};
  if (i == 1.0f) return {q, v, p};
  if (i == 2.0f) return {p, v, t};
  if (i == 3.0f) return {p, q, v};
  if (i == 4.0f) return {t, p, v};
  return {v, p, q};
}

// The Light Path node's outputs for a surface shaded at the end of path `p` (Cycles'
// svm_node_light_path with the path flags of path_state_next: a delta event is singular and
// glossy, a transparent crossing keeps the flags of the event before it; no shadow rays shade).
float light_path_output(const PathView& p, LightPathOutput which) {
  const bool event = !p.light_sample;
  const uint8_t l = p.lobe;
  switch (which) {
    case LightPathOutput::IsCameraRay:
      return event && l == 0 ? 1.0f : 0.0f;
    case LightPathOutput::IsShadowRay:
      return 0.0f;
    case LightPathOutput::IsDiffuseRay:
      return event && (l & kLobeDiffuse) ? 1.0f : 0.0f;
    case LightPathOutput::IsGlossyRay:
      return event && (l & (kLobeGlossy | kLobeDelta)) ? 1.0f : 0.0f;
    case LightPathOutput::IsSingularRay:
      return event && (l & kLobeDelta) ? 1.0f : 0.0f;
    case LightPathOutput::IsReflectionRay:
      return event && (l & kLobeReflection) ? 1.0f : 0.0f;
    case LightPathOutput::IsTransmissionRay:
      return event && (l & kLobeTransmission) ? 1.0f : 0.0f;
    case LightPathOutput::RayLength:
      return p.ray_length;
    case LightPathOutput::RayDepth:
      return float(p.depth);
    case LightPathOutput::DiffuseDepth:
      return float(p.diffuse_depth);
    case LightPathOutput::GlossyDepth:
      return float(p.glossy_depth);
    case LightPathOutput::TransparentDepth:
      return float(p.transparent_depth);
    case LightPathOutput::TransmissionDepth:
      return float(p.transmission_depth);
  }
  return 0.0f;
}

// Input nodes that read InputNode::vector: procedural textures and coordinates.
bool reads_vector(InputNodeKind kind) {
  switch (kind) {
    case InputNodeKind::Checker:
    case InputNodeKind::Noise:
    case InputNodeKind::Coordinates:
    case InputNodeKind::Voronoi:
    case InputNodeKind::Gradient:
    case InputNodeKind::Wave:
    case InputNodeKind::Musgrave:
    case InputNodeKind::WhiteNoise:
    case InputNodeKind::Magic:
    case InputNodeKind::Brick:
      return true;
    default:
      return false;
  }
}

// One input node's result from its operands, read through `in` (PointInputs or AverageInputs,
// which come back here for nested nodes; the tree is acyclic and shallow, checked at load).
template <class Inputs>
Spectrum input_node_result(const InputNode& n, const Inputs& in) {
  // Over a whole surface (AverageInputs: power estimates) the noise-like patterns average to
  // mid grey.
  if constexpr (Inputs::kAverage)
    if (reads_vector(n.kind) && n.kind != InputNodeKind::Checker &&
        n.kind != InputNodeKind::Coordinates)
      return Spectrum(0.5f);
  Spectrum r;
  switch (n.kind) {
    case InputNodeKind::Mix: {
      float t = in.scalar(n.fac);
      if (n.clamp_factor) t = saturate(t);
      r = mix_blend(n.blend, t, in.color(n.a), in.color(n.b));
      break;
    }
    case InputNodeKind::Math:
      r = Spectrum(
          math_node(n.math, in.scalar(n.value_a), in.scalar(n.value_b), in.scalar(n.value_c)));
      break;
    case InputNodeKind::VectorMath: {
      float value;
      r = vector_math_node(n.vector_math, in.color(n.a), in.color(n.b), in.color(n.c),
                           in.scalar(n.value_a), value);
      if (n.fac_output) r = Spectrum(value);
      break;
    }
    case InputNodeKind::Invert: {
      const Spectrum a = in.color(n.a);
      r = lerp(a, Spectrum(1.0f) - a, in.scalar(n.fac));
      break;
    }
    case InputNodeKind::Ramp: {
      // Cycles' rgb_ramp_lookup without extrapolation.
      const int size = int(n.ramp.size() / 4);
      const float f = saturate(in.scalar(n.fac)) * float(size - 1);
      const int i = std::clamp(int(f), 0, size - 1);
      const float t = f - float(i);
      const float* e = &n.ramp[4 * size_t(i)];
      float v[4] = {e[0], e[1], e[2], e[3]};
      if (n.ramp_interpolate && t > 0.0f)
        for (int k = 0; k < 4; ++k) v[k] = (1.0f - t) * v[k] + t * e[4 + k];
      r = n.ramp_alpha ? Spectrum(v[3]) : Spectrum(v[0], v[1], v[2]);
      break;
    }
    case InputNodeKind::Separate:
      r = Spectrum(in.color(n.a)[std::min<int>(n.channel, 2)]);
      break;
    case InputNodeKind::Combine:
    case InputNodeKind::CombineXyz:
      r = Spectrum(in.scalar(n.value_a), in.scalar(n.value_b), in.scalar(n.value_c));
      break;
    case InputNodeKind::Gamma: {
      const float g = in.scalar(n.value_a);
      r = in.color(n.a);
      if (g == 0.0f) {
        r = Spectrum(1.0f);
      } else {
        for (int k = 0; k < 3; ++k)
          if (r[k] > 0.0f) r[k] = std::pow(r[k], g);
      }
      break;
    }
    case InputNodeKind::HueSaturation: {
      const Spectrum in_color = in.color(n.a);
      Vec3f hsv = rgb_to_hsv(in_color);
      hsv.x = std::fmod(hsv.x + in.scalar(n.value_a) + 0.5f, 1.0f);
      hsv.y = saturate(hsv.y * in.scalar(n.value_b));
      hsv.z *= in.scalar(n.value_c);
      const float fac = in.scalar(n.fac);
      const Spectrum c = hsv_to_rgb(hsv);
      r = c * fac + in_color * (1.0f - fac);
      r = max(r, Spectrum(0.0f));  // over-saturation can go negative
      break;
    }
    case InputNodeKind::MapRange: {
      // Blender's Map Range (Linear, float).
      const std::array<float, 4>& b = n.bounds;
      const float v = in.scalar(n.value_a);
      const float span = b[1] - b[0];
      float m = span != 0.0f ? b[2] + (v - b[0]) / span * (b[3] - b[2]) : 0.0f;
      if (n.clamp_result) m = b[3] > b[2] ? std::clamp(m, b[2], b[3]) : std::clamp(m, b[3], b[2]);
      return Spectrum(m);  // the clamp is the node's own (to the target range)
    }
    case InputNodeKind::Clamp: {
      const float v = in.scalar(n.value_a), lo = in.scalar(n.value_b), hi = in.scalar(n.value_c);
      r = Spectrum(lo > hi && n.clamp_range ? std::min(std::max(v, hi), lo)
                                            : std::min(std::max(v, lo), hi));
      break;
    }
    case InputNodeKind::ToBw:
      r = Spectrum(luminance(in.color(n.a)));
      break;
    case InputNodeKind::Attribute:
      r = in.attribute_color();
      break;
    case InputNodeKind::Checker: {
      const Vec3f p = in.vector(n.vector) * in.scalar(n.value_a);
      r = Inputs::kAverage ? (in.color(n.a) + in.color(n.b)) * 0.5f
                           : (checker_texture(p) == 1.0f ? in.color(n.a) : in.color(n.b));
      if (n.fac_output) r = Spectrum(Inputs::kAverage ? 0.5f : checker_texture(p));
      break;
    }
    case InputNodeKind::Coordinates:
      r = in.vector(n.vector);
      break;
    case InputNodeKind::Voronoi: {
      const float scale = in.scalar(n.value_a);
      const Vec3f p = in.vector(n.vector) * scale;
      const float randomness = saturate(in.scalar(n.value_b)), exponent = in.scalar(n.value_c);
      using Feature = InputNode::VoronoiFeature;
      if (n.voronoi_feature == Feature::DistanceToEdge) {
        r = Spectrum(voronoi_distance_to_edge(p, randomness));
        break;
      }
      const VoronoiResult v =
          n.voronoi_feature == Feature::F2 ? voronoi_f2(p, randomness, n.voronoi_metric, exponent)
          : n.voronoi_feature == Feature::SmoothF1
              ? voronoi_smooth_f1(p, std::clamp(in.scalar(n.value_d) / 2.0f, 0.0f, 0.5f),
                                  randomness, n.voronoi_metric, exponent)
              : voronoi_f1(p, randomness, n.voronoi_metric, exponent);
      // Position back in the input's units (safe_divide_float3_float: 0 for scale 0).
      r = n.fac_output        ? Spectrum(v.distance)
          : n.position_output ? (scale != 0.0f ? v.position / scale : Vec3f(0.0f))
                              : v.color;
      break;
    }
    case InputNodeKind::Wave:
      r = Spectrum(wave_texture(in.vector(n.vector) * in.scalar(n.value_a), n.wave,
                                in.scalar(n.value_b), in.scalar(n.value_c), in.scalar(n.value_d),
                                in.scalar(n.value_e), in.scalar(n.value_f)));
      break;
    case InputNodeKind::Magic: {
      const Spectrum c = magic_texture(in.vector(n.vector) * in.scalar(n.value_a), n.magic_depth,
                                       in.scalar(n.value_b));
      r = n.fac_output ? Spectrum((c.x + c.y + c.z) / 3.0f) : c;
      break;
    }
    case InputNodeKind::Brick: {
      const BrickSample b = brick_texture(
          in.vector(n.vector) * in.scalar(n.value_a), n.brick, in.scalar(n.value_b),
          in.scalar(n.value_c), in.scalar(n.value_d), in.scalar(n.value_e), in.scalar(n.value_f));
      if (n.fac_output) {
        r = Spectrum(b.mortar);
        break;
      }
      Spectrum brick = in.color(n.a);
      if (b.mortar != 1.0f) brick = brick * (1.0f - b.tint) + in.color(n.b) * b.tint;
      r = brick * (1.0f - b.mortar) + in.color(n.c) * b.mortar;
      break;
    }
    case InputNodeKind::WhiteNoise: {
      const Vec3f p = in.vector(n.vector);
      r = n.fac_output ? Spectrum(white_noise(p)) : white_noise_color(p);
      break;
    }
    case InputNodeKind::Musgrave:
      r = Spectrum(musgrave_texture(
          in.vector(n.vector) * in.scalar(n.value_a), n.musgrave_type, in.scalar(n.value_b),
          in.scalar(n.value_c), in.scalar(n.value_d), in.scalar(n.value_e), in.scalar(n.value_f)));
      break;
    case InputNodeKind::Gradient:
      r = Spectrum(saturate(gradient_texture(in.vector(n.vector), n.gradient_type)));
      break;
    case InputNodeKind::Noise: {
      const float scale = in.scalar(n.value_a);
      const NoiseTextureResult t = noise_texture(
          n.noise_dimensions, in.vector(n.vector) * scale, in.scalar(n.value_d) * scale,
          in.scalar(n.value_b), in.scalar(n.value_c), in.scalar(n.fac), !n.fac_output);
      r = n.fac_output ? Spectrum(t.fac) : t.color;
      break;
    }
    case InputNodeKind::RgbCurves:
    case InputNodeKind::VectorCurves:
      r = curves_node(n.ramp, n.bounds[0], n.bounds[1], in.color(n.a), in.scalar(n.fac), 3);
      break;
    case InputNodeKind::FloatCurve:
      r = Spectrum(curves_node(n.ramp, n.bounds[0], n.bounds[1], Vec3f(in.scalar(n.value_a)),
                               in.scalar(n.fac), 1)
                       .x);
      break;
    case InputNodeKind::Blackbody:
      r = blackbody_color(in.scalar(n.value_a));
      break;
    case InputNodeKind::SeparateHsv:
      r = Spectrum(rgb_to_hsv(in.color(n.a))[std::min<int>(n.channel, 2)]);
      break;
    case InputNodeKind::CombineHsv:
      r = hsv_to_rgb(Vec3f(in.scalar(n.value_a), in.scalar(n.value_b), in.scalar(n.value_c)));
      break;
    case InputNodeKind::Fresnel:
    case InputNodeKind::LayerWeight: {
      const float v = in.scalar(n.value_a);
      const float cos_in = in.view_cosine(n.normal_linked);
      const bool back = !in.front_facing();
      r = Spectrum(n.kind == InputNodeKind::Fresnel ? fresnel_node(v, cos_in, back)
                   : n.channel == 0                 ? layer_weight_fresnel(v, cos_in, back)
                                                    : layer_weight_facing(v, cos_in));
      break;
    }
    case InputNodeKind::Geometry:
      r = in.geometry_output(n.geometry_output);
      break;
    case InputNodeKind::LightPath:
      r = Spectrum(in.light_path(n.light_path_output));
      break;
    case InputNodeKind::VectorTransform:
      r = in.transformed(n.vector_transform, in.color(n.a));
      break;
    case InputNodeKind::Wireframe:
      r = Spectrum(in.wireframe_factor(in.scalar(n.value_a), n.pixel_size));
      break;
    case InputNodeKind::BrightContrast: {
      const float contrast = in.scalar(n.value_b);
      const float a = 1.0f + contrast, b = in.scalar(n.value_a) - contrast * 0.5f;
      r = in.color(n.a);
      for (int k = 0; k < 3; ++k) r[k] = std::max(a * r[k] + b, 0.0f);
      break;
    }
  }
  return n.clamp_result ? saturate(r) : r;
}

// A float socket fed by a node: Math results directly, colours by their luminance, vectors (a
// coordinate, a Vector Math Vector) by the mean of their components, as Cycles converts them.
template <class Inputs>
float input_node_scalar(const InputNode& n, const Inputs& in) {
  const Spectrum r = input_node_result(n, in);
  if ((n.kind == InputNodeKind::Coordinates || n.kind == InputNodeKind::VectorMath ||
       n.kind == InputNodeKind::CombineXyz || n.kind == InputNodeKind::VectorCurves ||
       n.kind == InputNodeKind::VectorTransform ||
       (n.kind == InputNodeKind::Geometry && n.geometry_output != GeometryOutput::Backfacing)) &&
      !n.fac_output)
    return (r.x + r.y + r.z) * (1.0f / 3.0f);
  const bool grey = n.kind == InputNodeKind::Math || n.kind == InputNodeKind::Separate ||
                    n.kind == InputNodeKind::MapRange || n.kind == InputNodeKind::Clamp ||
                    n.kind == InputNodeKind::ToBw || n.kind == InputNodeKind::FloatCurve ||
                    n.kind == InputNodeKind::SeparateHsv || n.kind == InputNodeKind::Fresnel ||
                    n.kind == InputNodeKind::LayerWeight || n.kind == InputNodeKind::Geometry ||
                    n.kind == InputNodeKind::LightPath || n.kind == InputNodeKind::Wireframe ||
                    (n.kind == InputNodeKind::Ramp && n.ramp_alpha) ||
                    n.fac_output;  // a texture's Fac / Distance
  return grey ? r.x : luminance(r);
}

// Inputs at a hit point: texture lookups at their mapped coordinates.
struct PointInputs {
  static constexpr bool kAverage = false;
  std::span<const Texture> textures;
  std::span<const InputNode> nodes;
  ShadingContext at;
  const ShadingCamera* camera;
  bool front_facing() const { return at.front_facing; }

  Spectrum attribute_color() const { return at.color ? *at.color : Spectrum(0.0f); }
  // Cosine between the incoming direction and the interpolated (or perturbed) normal; normal
  // incidence without a view.
  float view_cosine(bool perturbed) const {
    if (!at.geometry) return 1.0f;
    const ShadingGeometry& g = *at.geometry;
    return dot(g.incoming, perturbed ? g.perturbed_normal : g.normal);
  }
  float light_path(LightPathOutput which) const {
    return light_path_output(at.path ? *at.path : PathView{}, which);
  }
  // A Geometry output; without a view, the front of a surface facing +z seen head-on.
  Vec3f geometry_output(GeometryOutput which) const {
    if (which == GeometryOutput::Backfacing) return Vec3f(at.front_facing ? 0.0f : 1.0f);
    if (is_surface_attribute(which)) {
      if (!at.attributes) return Vec3f(0.0f);
      const SurfaceAttributes& a = *at.attributes;
      const Vec2f b = a.barycentric;
      return which == GeometryOutput::Pointiness        ? Vec3f(a.pointiness)
             : which == GeometryOutput::RandomPerIsland ? Vec3f(a.random_per_island)
                                                        : Vec3f(1.0f - b.x - b.y, b.x, 0.0f);
    }
    if (!at.geometry) return Vec3f(0.0f, 0.0f, 1.0f);
    const ShadingGeometry& g = *at.geometry;
    if (which == GeometryOutput::Tangent) {
      // Cycles' primitive_tangent: cross(N, normalize(cross(T, N))).
      const Vec3f c = cross(tangent(TangentInput{}), g.normal);
      const float len = length(c);
      return len > 0.0f ? cross(g.normal, c / len) : Vec3f(0.0f);
    }
    return which == GeometryOutput::Normal       ? g.normal
           : which == GeometryOutput::TrueNormal ? g.true_normal
                                                 : g.incoming;
  }

  Vec3f transformed(const VectorTransformDesc& t, Vec3f v) const {
    return vector_transform(v, t, at.instance, *camera);
  }
  // Wireframe of width `size` (world units, or pixels); 0 without the hit's triangle. The pixel
  // width seen without a view: the surface head-on.
  float wireframe_factor(float size, bool pixel_size) const {
    if (!at.instance || !at.coords) return 0.0f;
    Vec3f c[3];
    for (int k = 0; k < 3; ++k) c[k] = at.instance->corner(at.primitive, k);
    const Vec3f p = at.coords->position;
    float width = size;
    if (pixel_size) {
      const Vec3f ng =
          at.geometry ? at.geometry->true_normal : normalize(cross(c[1] - c[0], c[2] - c[0]));
      const Vec3f wi = at.geometry ? at.geometry->incoming : ng;
      width *= wireframe_pixel_width(pixel_footprint(*camera, p), ng, wi);
    }
    return wireframe(c, p, width);
  }

  // An anisotropic lobe's tangent, world space, neither normalised nor projected (TangentInput).
  Vec3f tangent(const TangentInput& t) const {
    if (t.source == TangentInput::Source::Vector) return color(t.vector);
    if (!at.coords) return Vec3f(0.0f);
    const Vec3f g = at.coords->generated - Vec3f(0.5f);
    const Vec3f local = t.source == TangentInput::Source::UVMap ? at.coords->uv_tangent
                        : t.axis == 0                           ? Vec3f(0.0f, -g.z, g.y)
                        : t.axis == 1                           ? Vec3f(-g.z, 0.0f, g.x)
                                                                : Vec3f(-g.y, g.x, 0.0f);
    const float(*n)[4] = at.coords->normal_cols;
    if (!n) return local;
    Vec3f w(0.0f);
    for (int c = 0; c < 3; ++c) w += Vec3f(n[c][0], n[c][1], n[c][2]) * local[c];
    return w;
  }

  // A texture's coordinates: the source (zero without object-space coordinates), then its
  // mapping.
  Vec3f vector(const TextureVector& v) const {
    Vec3f p(at.uv.x, at.uv.y, 0.0f);
    if (v.source == TexCoordSource::Node)
      p = input_node_result(nodes[size_t(v.node)], *this);
    else if (v.source != TexCoordSource::UV)
      p = !at.coords                              ? Vec3f(0.0f)
          : v.source == TexCoordSource::Generated ? at.coords->generated
          : v.source == TexCoordSource::Object    ? at.coords->object
                                                  : at.coords->position;
    return v.mapping.point(p);
  }
  Rgba fetch(const TextureLookup& t) const {
    const Vec3f p = vector(t.vector);
    return textures[size_t(t.image)].lookup(Vec2f(p.x, p.y), t.interpolation, t.extension);
  }
  Spectrum color(const ColorInput& in) const {
    if (in.node >= 0) return input_node_result(nodes[size_t(in.node)], *this);
    return in.texture.image < 0 ? in.value : fetch(in.texture).rgb;
  }
  float scalar(const FloatInput& in) const {
    if (in.node >= 0) return input_node_scalar(nodes[size_t(in.node)], *this);
    if (in.texture.image < 0) return in.value;
    const Rgba c = fetch(in.texture);
    return channel(c, in.channel);
  }
};

// Inputs averaged over the whole texture (for light power estimates; through input nodes this is
// the node of the means, an estimate).
struct AverageInputs {
  static constexpr bool kAverage = true;
  const std::vector<Rgba>* means;
  std::span<const InputNode> nodes;
  bool front_facing() const { return true; }
  // Procedural textures average to their mid value (Vec3f(0.5) through input_node_result).
  Vec3f vector(const TextureVector&) const { return Vec3f(0.5f); }
  Vec3f tangent(const TangentInput&) const { return Vec3f(1.0f, 0.0f, 0.0f); }  // unused

  // Unknown without the mesh: white, an upper bound for power estimates (emitter selection).
  Spectrum attribute_color() const { return Spectrum(1.0f); }
  // The view is unknown: a mid-range cosine, a surface facing +z seen from the front.
  float view_cosine(bool) const { return 0.5f; }
  Vec3f geometry_output(GeometryOutput which) const {
    if (which == GeometryOutput::Parametric) return Vec3f(1.0f / 3.0f, 1.0f / 3.0f, 0.0f);
    if (is_surface_attribute(which)) return Vec3f(0.5f);  // their mean over a mesh, roughly
    return which == GeometryOutput::Backfacing ? Vec3f(0.0f) : Vec3f(0.0f, 0.0f, 1.0f);
  }
  // Object and camera unknown: world space; wires over half of the surface.
  Vec3f transformed(const VectorTransformDesc&, Vec3f v) const { return v; }
  float wireframe_factor(float, bool) const { return 0.5f; }
  // As a light sample from a unit distance sees it (emitter power estimates).
  float light_path(LightPathOutput which) const {
    PathView p;
    p.light_sample = true;
    p.ray_length = 1.0f;
    return light_path_output(p, which);
  }

  Spectrum color(const ColorInput& in) const {
    if (in.node >= 0) return input_node_result(nodes[size_t(in.node)], *this);
    return in.texture.image < 0 ? in.value : (*means)[size_t(in.texture.image)].rgb;
  }
  float scalar(const FloatInput& in) const {
    if (in.node >= 0) return input_node_scalar(nodes[size_t(in.node)], *this);
    if (in.texture.image < 0) return in.value;
    const Rgba& c = (*means)[size_t(in.texture.image)];
    return channel(c, in.channel);
  }
};

// The Anisotropic BSDF's widths from alpha = r^2 and the clamped anisotropy a (Cycles 3.4):
// narrower along the tangent for a > 0, across it for a < 0; equal widths stay isotropic.
void set_anisotropy(Closure& c, float alpha, float a) {
  const float ax = a < 0.0f ? alpha / (1.0f + a) : alpha * (1.0f - a);
  const float ay = a < 0.0f ? alpha * (1.0f + a) : alpha / (1.0f - a);
  c.alpha = saturate(ax);
  c.alpha_y = saturate(ay);
  if (c.alpha == c.alpha_y) c.alpha_y = -1.0f;
}

// The lobe's tangent (world) and its rotation about the normal, `turns` of a full turn.
void orient(Closure& c, Vec3f tangent, float turns) {
  c.tangent = tangent;
  const float angle = 2.0f * kPi * turns;
  c.rotation = turns != 0.0f ? Vec2f(std::cos(angle), std::sin(angle)) : Vec2f(1.0f, 0.0f);
}

// A Glossy or Anisotropic BSDF's lobe `c` of `color` at weight w. Blender's Multiscatter GGX
// there is a GGX lobe (its distribution set here) and its multiple-scattering lobe, of no
// Fresnel: the colour is the lobe's average reflectance.
void add_reflection_lobe(Closure& c, Spectrum color, float w, ClosureSet& out) {
  c.weight = color * w;
  const bool multiscatter = c.distribution == MicrofacetDistribution::MultiscatterGGX;
  if (multiscatter) c.distribution = MicrofacetDistribution::GGX;
  out.add(c);
  if (multiscatter) out.add(ggx_multiscatter::lobe_of(c, color, Spectrum(w)));
}

// Adds the lobes of one BSDF node (weight w) to `out`.
template <class Inputs>
void add_bsdf(const ShaderNode& n, float w, const Inputs& in, ClosureSet& out) {
  Closure c;
  c.interpolated_normal = !n.normal_linked;
  switch (n.kind) {
    case ShaderNodeKind::Diffuse: {
      const float r = saturate(in.scalar(n.roughness));
      c.type = r > 0.0f ? ClosureType::OrenNayar : ClosureType::Lambert;
      c.alpha = r;
      c.weight = in.color(n.color) * w;
      out.add(c);
      return;
    }
    case ShaderNodeKind::Glossy: {
      const float r = saturate(in.scalar(n.roughness));
      c.type = ClosureType::GGXReflection;
      c.fresnel = FresnelMode::None;
      c.distribution = n.distribution;
      c.alpha = r * r;
      add_reflection_lobe(c, in.color(n.color), w, out);
      return;
    }
    case ShaderNodeKind::Anisotropic: {
      const float r = saturate(in.scalar(n.roughness));
      c.type = ClosureType::GGXReflection;
      c.fresnel = FresnelMode::None;
      c.distribution = n.distribution;
      set_anisotropy(c, r * r, std::clamp(in.scalar(n.anisotropy), -0.99f, 0.99f));
      if (is_anisotropic(c)) orient(c, in.tangent(n.tangent), in.scalar(n.rotation));
      add_reflection_lobe(c, in.color(n.color), w, out);
      return;
    }
    case ShaderNodeKind::Glass:
    case ShaderNodeKind::Refraction: {
      const float r = saturate(in.scalar(n.roughness));
      const float ior = std::max(in.scalar(n.ior), 1e-5f);
      c.weight = in.color(n.color) * w;
      if (std::fabs(ior - 1.0f) < 1e-4f) {
        // Index-matched: no reflection (F = 0), refraction is a straight pass-through.
        c.type = ClosureType::Transparent;
      } else {
        c.type = ClosureType::GGXDielectric;
        c.fresnel = n.kind == ShaderNodeKind::Refraction ? FresnelMode::RefractionOnly
                                                         : FresnelMode::Dielectric;
        c.distribution = n.distribution;
        if (n.distribution == MicrofacetDistribution::MultiscatterGGX) {
          c.distribution = MicrofacetDistribution::GGX;
          c.multiscatter = true;
          c.multiscatter_tint = saturate(in.color(n.color));
        }
        c.alpha = r * r;
        // The integrators orient the frame towards the incoming ray (as Cycles flips N for back
        // faces), so the closure's IOR is that of the far side: 1 / ior when leaving the object.
        c.ior = in.front_facing() ? ior : 1.0f / ior;
      }
      out.add(c);
      return;
    }
    case ShaderNodeKind::Transparent:
      c.type = ClosureType::Transparent;
      c.weight = in.color(n.color) * w;
      out.add(c);
      return;
    case ShaderNodeKind::Translucent:
      c.type = ClosureType::Translucent;
      c.weight = in.color(n.color) * w;
      out.add(c);
      return;
    case ShaderNodeKind::Velvet:
      c.type = ClosureType::Velvet;
      c.alpha = saturate(in.scalar(n.roughness));
      c.weight = in.color(n.color) * w;
      out.add(c);
      return;
    case ShaderNodeKind::Principled: {
      PrincipledParams p;
      p.base_color = in.color(n.color);
      p.metallic = in.scalar(n.metallic);
      p.specular = in.scalar(n.specular);
      p.specular_tint = in.scalar(n.specular_tint);
      p.roughness = in.scalar(n.roughness);
      p.ior = in.scalar(n.ior);
      p.transmission = in.scalar(n.transmission);
      p.sheen = in.scalar(n.sheen);
      p.sheen_tint = in.scalar(n.sheen_tint);
      p.clearcoat = in.scalar(n.clearcoat);
      p.clearcoat_roughness = in.scalar(n.clearcoat_roughness);
      p.alpha = in.scalar(n.alpha);
      p.emission = in.color(n.emission) * in.scalar(n.emission_strength);
      p.subsurface = in.scalar(n.subsurface);
      if (p.subsurface != 0.0f) {
        p.subsurface_color = in.color(n.subsurface_color);
        p.diffuse_ancestor = in.light_path(LightPathOutput::DiffuseDepth) > 0.0f;
      }
      p.front_facing = in.front_facing();
      p.interpolated_normal = !n.normal_linked;
      p.clearcoat_interpolated_normal = !n.clearcoat_normal_linked;
      p.multiscatter = n.distribution == MicrofacetDistribution::MultiscatterGGX;
      p.anisotropic = in.scalar(n.anisotropy);
      if (p.anisotropic != 0.0f) {
        Closure oriented;
        orient(oriented, in.tangent(n.tangent), in.scalar(n.rotation));
        p.tangent = oriented.tangent;
        p.rotation = oriented.rotation;
      }
      add_principled_closures(p, w, out);
      return;
    }
    default:
      return;
  }
}

// Emission of one node (weight w), without building BSDF lobes.
template <class Inputs>
Spectrum node_emission(const ShaderNode& n, float w, const Inputs& in) {
  if (n.kind == ShaderNodeKind::Emission) return in.color(n.color) * (in.scalar(n.strength) * w);
  if (n.kind == ShaderNodeKind::Principled)
    return in.color(n.emission) *
           (in.scalar(n.emission_strength) * saturate(in.scalar(n.alpha)) * w);
  return Spectrum(0.0f);
}

// The tree walk. With `out` null only emission is accumulated.
template <class Inputs>
Spectrum walk(const std::vector<ShaderNode>& nodes, int32_t root, const Inputs& in,
              ClosureSet* out) {
  Spectrum emission(0.0f);
  StackEntry stack[kMaxTreeDepth + 2];
  int top = 0;
  stack[top++] = {root, 1.0f};
  while (top > 0) {
    const StackEntry e = stack[--top];
    if (e.node < 0 || e.weight <= 0.0f) continue;  // an unlinked shader input: no closure
    const ShaderNode& n = nodes[size_t(e.node)];
    switch (n.kind) {
      case ShaderNodeKind::Mix: {
        const float fac = saturate(in.scalar(n.fac));
        // Second child pushed first so the first child's lobes come first.
        stack[top++] = {n.b, e.weight * fac};
        stack[top++] = {n.a, e.weight * (1.0f - fac)};
        break;
      }
      case ShaderNodeKind::Add:
        stack[top++] = {n.b, e.weight};
        stack[top++] = {n.a, e.weight};
        break;
      case ShaderNodeKind::Emission:
        emission += node_emission(n, e.weight, in);
        break;
      default:
        if (out) {
          add_bsdf(n, e.weight, in, *out);  // Principled emission goes through out
        } else {
          emission += node_emission(n, e.weight, in);
        }
        break;
    }
  }
  return emission;
}

// The input is not its constant value: an image lookup or an input node (whose result the
// constant does not bound: an emission colour from a Color Ramp has a black default).
bool varies(const ColorInput& c) {
  return c.texture.image >= 0 || c.node >= 0;
}
bool varies(const FloatInput& f) {
  return f.texture.image >= 0 || f.node >= 0;
}

// Could a roughness input give a delta lobe (alpha = r^2 below kDeltaAlpha)?
bool may_be_delta(const FloatInput& roughness) {
  if (varies(roughness)) return true;
  const float r = saturate(roughness.value);
  return is_delta_alpha(r * r);
}

}  // namespace

Material::Material() {
  ShaderNode diffuse;
  diffuse.kind = ShaderNodeKind::Diffuse;
  diffuse.color = ColorInput(Spectrum(0.8f));
  diffuse.roughness = FloatInput(0.0f);
  nodes_.push_back(diffuse);
  root_ = 0;
  cache_if_constant();
}

Material::Material(const MaterialDesc& desc, std::span<const Texture> textures)
    : textures_(textures) {
  if (desc.root < 0) {
    *this = Material();
    textures_ = textures;
    return;
  }
  nodes_ = desc.nodes;
  inputs_ = desc.inputs;
  root_ = desc.root;
  normal_map_ = desc.normal_map;
  bumps_ = desc.bumps;
  const std::string where = "material '" + desc.name + "': ";
  auto check_node = [&](int32_t i) {
    if (i < 0 || size_t(i) >= nodes_.size())
      throw std::invalid_argument(where + "node index " + std::to_string(i) + " out of range (" +
                                  std::to_string(nodes_.size()) + " nodes)");
  };
  auto check_lookup = [&](const TextureLookup& t) {
    if (t.image >= 0 && size_t(t.image) >= textures.size())
      throw std::invalid_argument(where + "image index " + std::to_string(t.image) +
                                  " out of range (" + std::to_string(textures.size()) +
                                  " textures)");
  };
  check_node(root_);

  // --- Validate the reachable tree (indices, depth, cycles) and collect features. Recursion is
  // fine here: this runs once at scene load, the per-hit walk uses the explicit stack.
  std::vector<bool> uses_image(textures.size(), false);
  // A texture's vector: its coordinates, or the input node it comes from (through note_fn).
  auto note_vector = [&](auto&& note_fn, const TextureVector& v, int depth) {
    if (v.source != TexCoordSource::Node) {
      reads_coordinates_ |= v.source != TexCoordSource::UV;
      return;
    }
    ColorInput via;  // a missing index is out of range: reported below
    via.node = v.node >= 0 ? v.node : int32_t(inputs_.size());
    note_fn(note_fn, via, depth + 1);
  };
  // An input: its texture, or its input node's operands (depth-limited: no cycles).
  auto note_input = [&](auto&& self, const auto& input, int depth) -> void {
    if (input.node >= 0) {
      if (size_t(input.node) >= inputs_.size())
        throw std::invalid_argument(where + "input node index " + std::to_string(input.node) +
                                    " out of range (" + std::to_string(inputs_.size()) +
                                    " input nodes)");
      if (depth > kMaxTreeDepth)
        throw std::invalid_argument(where + "input nodes nested deeper than " +
                                    std::to_string(kMaxTreeDepth) + " (or cyclic)");
      const InputNode& n = inputs_[size_t(input.node)];
      // Values that vary over the surface: no per-side constant closures (cache_if_constant).
      if (n.kind == InputNodeKind::Attribute) {
        features_ |= kFeatureTextures;
        reads_color_attribute_ = true;
      }
      // Backfacing alone is a function of the side, which the per-side cache keys on.
      const bool surface_attribute =
          n.kind == InputNodeKind::Geometry && is_surface_attribute(n.geometry_output);
      if (surface_attribute) {
        features_ |= kFeatureTextures;
        reads_surface_attributes_ = true;
      }
      if (n.kind == InputNodeKind::Fresnel || n.kind == InputNodeKind::LayerWeight ||
          (n.kind == InputNodeKind::Geometry && n.geometry_output != GeometryOutput::Backfacing &&
           !surface_attribute))
        reads_view_ = true;
      if (n.kind == InputNodeKind::Geometry && n.geometry_output == GeometryOutput::Tangent) {
        reads_coordinates_ = true;
        features_ |= kFeatureTextures;
      }
      if (n.kind == InputNodeKind::LightPath) reads_path_ = true;
      // Per instance and camera; Wireframe reads the hit's position and, in pixels, the view.
      if (n.kind == InputNodeKind::VectorTransform) features_ |= kFeatureTextures;
      if (n.kind == InputNodeKind::Wireframe) {
        features_ |= kFeatureTextures;
        reads_coordinates_ = true;
        reads_view_ = reads_view_ || n.pixel_size;
      }
      if (reads_vector(n.kind)) {
        features_ |= kFeatureTextures;
        note_vector(self, n.vector, depth);
      }
      const bool curves = n.kind == InputNodeKind::RgbCurves ||
                          n.kind == InputNodeKind::VectorCurves ||
                          n.kind == InputNodeKind::FloatCurve;
      if ((n.kind == InputNodeKind::Ramp || curves) &&
          (n.ramp.size() < 8 || n.ramp.size() % 4 != 0))
        throw std::invalid_argument(where + "colour ramp or curve table of " +
                                    std::to_string(n.ramp.size()) +
                                    " floats (expected 4 per entry, at least 2 entries)");
      if (curves && !(n.bounds[1] > n.bounds[0]))
        throw std::invalid_argument(where + "curve table over an empty range");
      for (const FloatInput* f :
           {&n.fac, &n.value_a, &n.value_b, &n.value_c, &n.value_d, &n.value_e, &n.value_f})
        self(self, *f, depth + 1);
      for (const ColorInput* c : {&n.a, &n.b, &n.c}) self(self, *c, depth + 1);
      return;
    }
    check_lookup(input.texture);
    if (input.texture.image >= 0) {
      features_ |= kFeatureTextures;
      uses_image[size_t(input.texture.image)] = true;
      note_vector(self, input.texture.vector, depth);
    }
  };
  auto note = [&](const auto& input) { note_input(note_input, input, 0); };
  // A tangent varies over the surface unless it is a constant vector: closures per hit.
  auto note_tangent = [&](const TangentInput& t) {
    if (t.source == TangentInput::Source::Vector) {
      note(t.vector);
      return;
    }
    reads_coordinates_ = true;  // TexCoords carries the generated coordinates and UV tangent
    features_ |= kFeatureTextures;
  };
  auto visit = [&](auto&& self, int32_t i, int depth) -> void {
    check_node(i);
    if (depth > kMaxTreeDepth)
      throw std::invalid_argument(where + "node tree deeper than " + std::to_string(kMaxTreeDepth) +
                                  " (or cyclic)");
    const ShaderNode& n = nodes_[size_t(i)];
    switch (n.kind) {
      case ShaderNodeKind::Mix:
      case ShaderNodeKind::Add:
        if (n.kind == ShaderNodeKind::Mix) note(n.fac);
        for (const int32_t child : {n.a, n.b})
          if (child != -1) self(self, child, depth + 1);
        return;
      case ShaderNodeKind::Diffuse:
        note(n.color);
        note(n.roughness);
        return;
      case ShaderNodeKind::Glossy:
        note(n.color);
        note(n.roughness);
        features_ |= kFeatureGlossy;
        if (may_be_delta(n.roughness)) features_ |= kFeatureDelta;
        return;
      case ShaderNodeKind::Anisotropic:
        note(n.color);
        note(n.roughness);
        note(n.anisotropy);
        note(n.rotation);
        note_tangent(n.tangent);
        features_ |= kFeatureGlossy;
        if (may_be_delta(n.roughness)) features_ |= kFeatureDelta;
        return;
      case ShaderNodeKind::Glass:
      case ShaderNodeKind::Refraction:
        note(n.color);
        note(n.roughness);
        note(n.ior);
        features_ |= kFeatureGlossy | kFeatureTransmission;
        if (may_be_delta(n.roughness) || varies(n.ior) || std::fabs(n.ior.value - 1.0f) < 1e-4f)
          features_ |= kFeatureDelta;
        return;
      case ShaderNodeKind::Transparent:
        note(n.color);
        features_ |= kFeatureTransparent | kFeatureDelta;
        return;
      case ShaderNodeKind::Translucent:
        note(n.color);
        features_ |= kFeatureTransmission;
        return;
      case ShaderNodeKind::Velvet:
        note(n.color);
        note(n.roughness);
        return;
      case ShaderNodeKind::Emission:
        note(n.color);
        note(n.strength);
        if ((varies(n.color) || !is_black(n.color.value)) &&
            (varies(n.strength) || n.strength.value != 0.0f))
          features_ |= kFeatureEmission;
        return;
      case ShaderNodeKind::Principled: {
        note(n.color);
        note(n.roughness);
        note(n.ior);
        note(n.metallic);
        note(n.specular);
        note(n.specular_tint);
        note(n.transmission);
        note(n.sheen);
        note(n.sheen_tint);
        note(n.clearcoat);
        note(n.clearcoat_roughness);
        note(n.alpha);
        note(n.emission);
        note(n.emission_strength);
        note(n.subsurface);
        note(n.subsurface_color);
        // After a diffuse bounce the subsurface mix becomes the base of the other lobes too.
        const auto may_be_nonzero = [](const FloatInput& f) {
          return varies(f) || f.value != 0.0f;
        };
        if (may_be_nonzero(n.subsurface) &&
            (may_be_nonzero(n.metallic) || may_be_nonzero(n.specular_tint) ||
             may_be_nonzero(n.sheen) || may_be_nonzero(n.transmission)))
          reads_path_ = true;
        note(n.anisotropy);
        if (varies(n.anisotropy) || n.anisotropy.value != 0.0f) {
          note(n.rotation);
          note_tangent(n.tangent);
        }
        const bool specular = varies(n.specular) || varies(n.metallic) || n.specular.value > 0.0f ||
                              n.metallic.value > 0.0f;
        const bool transmission = (varies(n.transmission) || n.transmission.value > 0.0f) &&
                                  (varies(n.metallic) || n.metallic.value < 1.0f);
        const bool clearcoat = varies(n.clearcoat) || n.clearcoat.value > 0.0f;
        if (specular || transmission || clearcoat) features_ |= kFeatureGlossy;
        if ((specular || transmission) && may_be_delta(n.roughness)) features_ |= kFeatureDelta;
        if (clearcoat && may_be_delta(n.clearcoat_roughness)) features_ |= kFeatureDelta;
        if (transmission) features_ |= kFeatureTransmission;
        if (varies(n.alpha) || n.alpha.value < 1.0f)
          features_ |= kFeatureTransparent | kFeatureDelta;
        if ((varies(n.emission) || !is_black(n.emission.value)) &&
            (varies(n.emission_strength) || n.emission_strength.value != 0.0f))
          features_ |= kFeatureEmission;
        return;
      }
    }
  };
  visit(visit, root_, 0);
  if (normal_map_.enabled) note(normal_map_.color);
  for (const BumpDesc& b : bumps_) {
    note(b.height);
    if (b.vector_space != BumpDesc::VectorSpace::None) note(b.vector);
  }

  // --- Mean of every texture the tree uses, for average_emission().
  std::vector<Rgba> means(textures.size());
  for (size_t i = 0; i < textures.size(); ++i) {
    if (!uses_image[i]) continue;
    means[i] = textures[i].mean();
  }
  if (features_ & kFeatureEmission)
    average_emission_ = walk(nodes_, root_, AverageInputs{&means, inputs_}, nullptr);
  cache_if_constant();
}

void Material::cache_if_constant() {
  constant_ = false;
  if ((features_ & kFeatureTextures) || reads_view_ || reads_path_) return;
  for (int side = 0; side < 2; ++side) {
    ClosureSet& set = constant_closures_[side];
    set.clear();
    const ShadingContext at{{0.0f, 0.0f}, side == 1};
    set.add_emission(walk(nodes_, root_, PointInputs{textures_, inputs_, at, &camera_}, &set));
  }
  constant_ = true;
}

void Material::evaluate(const ShadingContext& ctx, ClosureSet& out) const {
  if (constant_) {
    out.assign(constant_closures_[ctx.front_facing ? 1 : 0]);
    return;
  }
  out.clear();
  const Spectrum e = walk(nodes_, root_, PointInputs{textures_, inputs_, ctx, &camera_}, &out);
  out.add_emission(e);
}

Spectrum Material::emission(const ShadingContext& ctx) const {
  if (!(features_ & kFeatureEmission)) return Spectrum(0.0f);
  return walk(nodes_, root_, PointInputs{textures_, inputs_, ctx, &camera_}, nullptr);
}

Vec3f Material::normal_map_direction(const ShadingContext& at) const {
  const Spectrum c = PointInputs{textures_, inputs_, at, &camera_}.color(normal_map_.color);
  const float s = normal_map_.strength;
  return {2.0f * (c.x - 0.5f) * s, 2.0f * (c.y - 0.5f) * s,
          1.0f + (2.0f * (c.z - 0.5f) - 1.0f) * std::clamp(s, 0.0f, 1.0f)};
}

float Material::bump_height(size_t bump, const ShadingContext& at, Vec3f along) const {
  const BumpDesc& b = bumps_[bump];
  const PointInputs inputs{textures_, inputs_, at, &camera_};
  if (b.vector_space == BumpDesc::VectorSpace::None) return inputs.scalar(b.height);
  const Spectrum v = inputs.color(b.vector);
  return v.x * along.x + v.y * along.y + v.z * along.z;
}

}  // namespace gdpt

// The pure mathematics of the gradient-domain shift map (Kettunen et al. 2015): how an offset path
// is derived from a base path vertex by vertex, the change of measure (Jacobian determinant) each
// step introduces, and the power-heuristic MIS weights between a base path and its offset.
//
// Everything here is scene-independent and header-only so that it can be tested in isolation
// against finite differences. The bookkeeping is in double: path pdfs are products of many
// solid-angle densities and Jacobians, and their ratios are what the MIS weights see; in float the
// products under- or overflow on long glossy chains (the reference needs double for this too).
//
// Conventions (as shaders/bsdf.h): local shading frame with the normal on +z; wi points from the
// vertex towards the previous vertex, wo towards the next one. A Jacobian J of a shift T is the
// change of measure |d T(x) / d x| from the base's measure to the offset's measure: the offset
// contributes f(T(x)) * J in the base's measure.
//
// Parameters:
//  - roughness threshold (RenderSettings::shift_roughness_threshold, default 0.001): a vertex
//    whose (GGX alpha) roughness is strictly below it is "specular" and is shifted by the
//    half-vector copy; otherwise it is "diffuse" and can be reconnected.
#pragma once

#include <cmath>

#include "core/vec.h"

namespace gdpt::shift {

// ---------------------------------------------------------------------------------------------
// Double-precision 3-vector for the shift geometry.
// ---------------------------------------------------------------------------------------------
struct Vec3d {
  double x = 0.0, y = 0.0, z = 0.0;
  constexpr Vec3d() = default;
  constexpr Vec3d(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
  constexpr explicit Vec3d(Vec3f v) : x(v.x), y(v.y), z(v.z) {}
  constexpr Vec3d operator-() const { return {-x, -y, -z}; }
  constexpr Vec3d operator+(Vec3d o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3d operator-(Vec3d o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3d operator*(double s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3d operator/(double s) const { return {x / s, y / s, z / s}; }
  Vec3f to_float() const { return {float(x), float(y), float(z)}; }
};
constexpr double dot(Vec3d a, Vec3d b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3d cross(Vec3d a, Vec3d b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr double length_squared(Vec3d v) {
  return dot(v, v);
}
inline double length(Vec3d v) {
  return std::sqrt(dot(v, v));
}
inline Vec3d normalize(Vec3d v) {
  return v / length(v);
}
// Component-wise products (throughput times a BSDF value or radiance).
inline Vec3d mul(Vec3d a, Vec3d b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
inline Vec3d mul(Vec3d a, Vec3f b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
inline bool is_zero(Vec3d a) {
  return a.x == 0.0 && a.y == 0.0 && a.z == 0.0;
}

// ---------------------------------------------------------------------------------------------
// Vertex classification.
// ---------------------------------------------------------------------------------------------
enum class VertexType : uint8_t { Specular, Diffuse };

inline constexpr float kDefaultRoughnessThreshold = 0.001f;

// `roughness` is ClosureSet::roughness() for a smooth (non-delta) sample, 0 when the sampled lobe
// was delta; environment hits are classified Diffuse by the caller.
constexpr VertexType classify_vertex(float roughness,
                                     float threshold = kDefaultRoughnessThreshold) {
  return roughness < threshold ? VertexType::Specular : VertexType::Diffuse;
}

// ---------------------------------------------------------------------------------------------
// Reconnection shift: the offset vertex y_i connects to the base's next vertex x_{i+1}.
// The base sampled the direction x_i -> x_{i+1} in solid angle at x_i; the offset's direction is
// fixed by the shared target, so J = d omega'(y_i) / d omega(x_i)
//   = |cos theta'| |x_i - x_{i+1}|^2 / (|cos theta| |y_i - x_{i+1}|^2),
// both cosines at the target against its geometric normal. The same formula is the light-
// reconnection Jacobian of shifted next-event estimation (target = the shared point on the
// light): there the base sampled the point, but its density is expressed in solid angle at x_i.
// ---------------------------------------------------------------------------------------------
struct Reconnection {
  Vec3d direction;        // unit, offset vertex -> target (world space)
  double distance = 0.0;  // |y_i - target|
  double jacobian = 0.0;
  bool valid = false;  // false on degenerate geometry (coincident points, grazing target)
};

// The base's side of a reconnection (source x_i, target x_{i+1} and its normal): the same for the
// four offsets of a path, computed once.
struct ReconnectionBase {
  Vec3d target, normal;
  double base_d2 = 0.0;   // |x_i - x_{i+1}|^2
  double base_cos = 0.0;  // |cos theta| at the target, 0 when base_d2 is not positive
};

inline ReconnectionBase reconnection_base(Vec3f base_source, Vec3f target, Vec3f target_normal) {
  ReconnectionBase b;
  b.target = Vec3d(target);
  b.normal = Vec3d(target_normal);
  const Vec3d base_edge = Vec3d(base_source) - b.target;
  b.base_d2 = length_squared(base_edge);
  if (b.base_d2 > 0.0) b.base_cos = std::fabs(dot(base_edge, b.normal)) / std::sqrt(b.base_d2);
  return b;
}

inline Reconnection reconnect(const ReconnectionBase& b, Vec3f offset_source) {
  Reconnection r;
  const Vec3d offset_edge = Vec3d(offset_source) - b.target;
  const double offset_d2 = length_squared(offset_edge);
  if (!(b.base_d2 > 0.0) || !(offset_d2 > 0.0)) return r;
  const double offset_cos = std::fabs(dot(offset_edge, b.normal)) / std::sqrt(offset_d2);
  if (!(b.base_cos > 0.0)) return r;
  r.distance = std::sqrt(offset_d2);
  r.direction = -offset_edge / r.distance;
  r.jacobian = (offset_cos * b.base_d2) / (b.base_cos * offset_d2);
  r.valid = std::isfinite(r.jacobian);
  return r;
}

inline Reconnection reconnect(Vec3f base_source, Vec3f offset_source, Vec3f target,
                              Vec3f target_normal) {
  return reconnect(reconnection_base(base_source, target, target_normal), offset_source);
}

// Light reconnection for next-event estimation. A point-like light (zero normal) has no surface:
// the shared "vertex" is a position with a discrete density, the emitted intensity already carries
// each path's own 1/d^2, so the change of measure is 1. Infinite lights (sun, world) share the
// direction instead of a point: J = 1 as well.
inline double light_reconnection_jacobian(Vec3f base_source, Vec3f offset_source,
                                          Vec3f light_position, Vec3f light_normal,
                                          bool point_like_or_infinite) {
  if (point_like_or_infinite) return 1.0;
  const Reconnection r = reconnect(base_source, offset_source, light_position, light_normal);
  return r.valid ? r.jacobian : 0.0;
}
// The same for a surface light point whose base side is already computed.
inline double light_reconnection_jacobian(const ReconnectionBase& b, Vec3f offset_source) {
  const Reconnection r = reconnect(b, offset_source);
  return r.valid ? r.jacobian : 0.0;
}

// ---------------------------------------------------------------------------------------------
// Half-vector copy at a specular vertex, in the local shading frame of each vertex.
// The base's half vector (reflection: h = normalize(wi + wo); refraction: the generalised
// H = -(wi + e wo) with e = eta_o / eta_i the relative IOR across the interface in the direction
// of travel) is copied to the offset, whose outgoing direction follows from its own wi'.
// J = d omega'_o / d omega_o, from d omega_o / d omega_h:
//   reflection: 4 |wo . h|                 -> J = |wo' . h| / |wo . h|
//   refraction: |H|^2 / (e^2 |wo . h|)      -> J = (|H'|^2 / |H|^2) (|wo . h| / |wo' . h|)
//   (e^2/e'^2)
// (Walter et al. 2007, eq. 14 and 17). Failure (shift undefined, the offset path dies):
//  - refraction with e == 1 (H degenerates to zero for straight transmission),
//  - the offset's refraction is total internal reflection, or lands on the same side as wi'
//    (a transmission cannot map to a reflection: the inverse shift would not exist).
// ---------------------------------------------------------------------------------------------
struct HalfVectorShift {
  Vec3d wo;  // offset outgoing direction, local frame, unit
  double jacobian = 0.0;
  bool valid = false;
};

// Reflect v about the unit vector h (both pointing away from the surface).
constexpr Vec3d reflect(Vec3d v, Vec3d h) {
  return h * (2.0 * dot(v, h)) - v;
}

// Refraction of wi (pointing away from the surface on the side of n or not) through a surface with
// unit normal n and relative IOR e = eta_transmitted / eta_incident. Returns false on total
// internal reflection.
inline bool refract(Vec3d wi, Vec3d n, double e, Vec3d& wt) {
  double cos_i = dot(wi, n);
  if (cos_i < 0.0) {
    n = -n;
    cos_i = -cos_i;
  }
  const double sin2_t = (1.0 - cos_i * cos_i) / (e * e);
  if (sin2_t >= 1.0) return false;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  wt = -wi / e + n * (cos_i / e - cos_t);
  return true;
}

// Relative IOR in the direction of travel for a lobe of IOR `ior` (outside -> inside, the
// Closure convention) seen from wi: entering from the +z side crosses ior, leaving crosses 1/ior.
constexpr double relative_eta(double ior, Vec3d wi) {
  return wi.z >= 0.0 ? ior : 1.0 / ior;
}

inline HalfVectorShift half_vector_reflection(Vec3d base_wi, Vec3d base_wo, Vec3d offset_wi) {
  HalfVectorShift s;
  const Vec3d h_sum = base_wi + base_wo;
  const double h_len2 = length_squared(h_sum);
  if (!(h_len2 > 0.0)) return s;
  const Vec3d h = h_sum / std::sqrt(h_len2);
  const double base_dot = std::fabs(dot(base_wo, h));
  if (!(base_dot > 0.0)) return s;
  s.wo = reflect(offset_wi, h);
  s.jacobian = std::fabs(dot(s.wo, h)) / base_dot;
  s.valid = std::isfinite(s.jacobian);
  return s;
}

// `ior` is the lobe's IOR (outside -> inside). Base and offset may arrive from different sides.
inline HalfVectorShift half_vector_refraction(Vec3d base_wi, Vec3d base_wo, Vec3d offset_wi,
                                              double ior) {
  HalfVectorShift s;
  const double e = relative_eta(ior, base_wi);
  const double e_off = relative_eta(ior, offset_wi);
  if (e == 1.0 || e_off == 1.0) return s;
  // Only a transmission is shifted here: base_wi and base_wo on opposite sides.
  if (base_wi.z * base_wo.z >= 0.0) return s;
  const Vec3d H = -(base_wi + base_wo * e);
  const double H_len2 = length_squared(H);
  if (!(H_len2 > 0.0)) return s;
  const Vec3d h = H / std::sqrt(H_len2);
  Vec3d wo;
  if (!refract(offset_wi, h, e_off, wo)) return s;  // TIR where the base transmitted
  if (offset_wi.z * wo.z >= 0.0) return s;          // transmission mapped to a reflection
  const Vec3d H_off = -(offset_wi + wo * e_off);
  const double base_dot = std::fabs(dot(base_wo, h));
  const double off_dot = std::fabs(dot(wo, h));
  if (!(base_dot > 0.0) || !(off_dot > 0.0)) return s;
  s.wo = normalize(wo);
  s.jacobian = (length_squared(H_off) / H_len2) * (base_dot / off_dot) * (e * e) / (e_off * e_off);
  s.valid = std::isfinite(s.jacobian);
  return s;
}

// Dispatch on the base's event: transmission when wi and wo lie on opposite sides.
inline HalfVectorShift half_vector_shift(Vec3d base_wi, Vec3d base_wo, Vec3d offset_wi,
                                         double ior) {
  if (base_wi.z * base_wo.z < 0.0) return half_vector_refraction(base_wi, base_wo, offset_wi, ior);
  HalfVectorShift s = half_vector_reflection(base_wi, base_wo, offset_wi);
  // A reflection must stay a reflection (the inverse shift maps reflections to reflections).
  if (s.valid && offset_wi.z * s.wo.z <= 0.0) s.valid = false;
  return s;
}

// ---------------------------------------------------------------------------------------------
// MIS between the base and the offset path (power heuristic, f and p kept apart).
// One path pair x (base) / y = T(x) (offset) ending on a light can be produced by four
// techniques: {sampled from this pixel as base, sampled from the neighbour as base and shifted
// back} x {light sample, BSDF sample at the last vertex}. With
//   p  = base path pdf up to the last vertex, p_L / p_B its light / BSDF density of the last
//        segment (solid angle), and
//   q  = J * p', J the full Jacobian of the shift including the last segment, p', p'_L, p'_B
//        the offset's densities,
// the base light-sample term is weighted (divided by its own pdf p p_L)
//   w = p p_L / [p^2 (p_L^2 + p_B^2) + q^2 (p'_L^2 + p'_B^2)]
// and the base BSDF term the same with p_B in the numerator. The same w multiplies the base term
// f, the offset term f' J and the gradient f' J - f. A failed shift has q = 0.
// When next-event estimation is not shifted for a pair, both sides drop their light terms:
// pass p_L = p'_L = 0 for the BSDF technique, and the light technique is not used.
// The weights of a pair's four techniques sum to one for any density used in place of p_L, p'_L
// as long as all four see the same function of the light point and its vertex: the integrator
// weighs area lights with their area-sampling density (mis_light_pdf in
// mis_weights.h) and passes p_mis^2 / pdf as the light technique's `technique_pdf`,
// so that the base term stays divided by the density it was sampled with.
// ---------------------------------------------------------------------------------------------
struct PathDensities {
  double path = 0.0;   // p (base) or J * p' (offset, Jacobian included)
  double light = 0.0;  // p_L of the last segment, 0 when light sampling cannot produce it
  double bsdf = 0.0;   // p_B of the last segment, 0 when BSDF sampling cannot produce it
};

// The offset side of a pair: `offset_path_pdf` is p' with the Jacobians of the shifted prefix
// already multiplied in, `last_jacobian` the Jacobian of the last segment (light or BSDF-hit
// reconnection, 1 when connected). Both techniques must see the same J: otherwise the weights of
// one path pair no longer sum to one (tested in tests/gradient/test_shift_mapping.cpp).
constexpr PathDensities offset_densities(double offset_path_pdf, double last_jacobian, double light,
                                         double bsdf) {
  return {offset_path_pdf * last_jacobian, light, bsdf};
}

// Denominator term of one side: p^2 (p_L^2 + p_B^2).
constexpr double mis_side(const PathDensities& d) {
  return d.path * d.path * (d.light * d.light + d.bsdf * d.bsdf);
}

// Weight divided by the base's pdf of the technique: multiply f (not f/p) by it.
// `technique_pdf` is base.light or base.bsdf.
constexpr double mis_weight_over_pdf(const PathDensities& base, const PathDensities& offset,
                                     double technique_pdf) {
  const double denom = mis_side(base) + mis_side(offset);
  return denom > 0.0 ? base.path * technique_pdf / denom : 0.0;
}

// The dimensionless power-heuristic weight (what mis_weight_over_pdf times p * p_technique is).
constexpr double mis_weight(const PathDensities& base, const PathDensities& offset,
                            double technique_pdf) {
  return mis_weight_over_pdf(base, offset, technique_pdf) * base.path * technique_pdf;
}

}  // namespace gdpt::shift

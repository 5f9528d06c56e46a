// Pair-level oracles for the G-PT integrator: one base path and one offset, fixed by hand in a
// small scene, run through the integrator's own phases (shift_segment, lamp_events, end_events,
// nee_pairs, advance), and the offset's gradient half compared with w (C' - C) computed here
// from the paper's definitions:
//  - the shift Jacobian by finite differences of the offset mapping (perturb the base direction,
//    map it the way the shift does, measure the ratio of the solid angles spanned),
//  - the power-heuristic pair weight written out (p p_tech / [p^2 (p_L^2 + p_B^2) + (J p')^2
//    (p'_L^2 + p'_B^2)]), with Lambert values and densities and area-sampling light densities
//    written out too (BSDF values of glossy lobes are taken from the closures, which the BSDF
//    chi-square tests cover).
// The statistical tests cannot see a symmetric 3% error in a Jacobian or in a pair term (the two
// MIS halves' errors cancel to first order, docs/gradient.md); these tests compare one pair to
// 2e-5 and check that the oracle itself moves by more than 20 times that under such an error.
// What each guards (docs/gradient.md, "Power"): the reconnection Jacobian (offset_path.cpp, and
// reconnect_to_light for lamps), the half-vector Jacobian, the BSDF-hit pair terms of
// end_events and lamp_events, the next-event Jacobian and pair term, the invertibility kill.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "integrators/gpt/emission_events.h"
#include "integrators/gpt/nee_pairs.h"
#include "integrators/gpt/offset_path.h"
#include "integrators/gpt/path_scratch.h"
#include "testing/gradient_scenes.h"

namespace gdpt::gradient_test {
namespace {

using shift::Vec3d;
using shift::VertexType;
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kTol = 2e-5;  // relative to the larger of w C and w C'

// ---------------------------------------------------------------------------------------------
// Oracle geometry, in double.
// ---------------------------------------------------------------------------------------------
Vec3d d3(Vec3f v) {
  return Vec3d(v);
}

void tangents(Vec3d w, Vec3d& u, Vec3d& v) {
  const Vec3d a = std::fabs(w.x) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
  u = shift::normalize(shift::cross(w, a));
  v = shift::cross(w, u);
}

// J = d omega' / d omega of a map `shifted` from the base direction (perturbed around `d0`) to
// the offset direction, by central differences of both direction fields.
template <typename F>
double fd_jacobian(Vec3d d0, F&& shifted) {
  const double eps = 1e-5;
  Vec3d u, v;
  tangents(d0, u, v);
  auto base_dir = [&](double a, double b) { return shift::normalize(d0 + u * a + v * b); };
  auto element = [&](auto&& dir) {
    const Vec3d da = (dir(eps, 0.0) - dir(-eps, 0.0)) / (2.0 * eps);
    const Vec3d db = (dir(0.0, eps) - dir(0.0, -eps)) / (2.0 * eps);
    return shift::length(shift::cross(da, db));
  };
  const double base = element(base_dir);
  const double off = element([&](double a, double b) { return shifted(base_dir(a, b)); });
  return off / base;
}

Vec3d hit_plane(Vec3d o, Vec3d d, Vec3d p, Vec3d n) {
  return o + d * (shift::dot(p - o, n) / shift::dot(d, n));
}

// Reconnection: the base direction from x meets the plane (p, n) of the target; the offset at y
// connects to that moved point.
double reconnection_jacobian(Vec3d x, Vec3d y, Vec3d target, Vec3d n) {
  return fd_jacobian(shift::normalize(target - x),
                     [&](Vec3d d) { return shift::normalize(hit_plane(x, d, target, n) - y); });
}

// Half-vector copy (reflection) in world space for two vertices with the same frame: the base's
// half vector of (wi, wo) reflects the offset's wi'.
Vec3d reflect_about_half(Vec3d wi, Vec3d wo, Vec3d wi_off) {
  const Vec3d h = shift::normalize(wi + wo);
  return h * (2.0 * shift::dot(wi_off, h)) - wi_off;
}

// Area-sampling density of a light point in solid angle at `from`: d^2 / (A |cos_L|).
double area_density(Vec3d from, Vec3d point, Vec3d normal, double area) {
  const Vec3d e = point - from;
  const double d2 = shift::length_squared(e);
  return d2 / (area * std::fabs(shift::dot(e, normal)) / std::sqrt(d2));
}

// Solid angle of the triangle (a, b, c) seen from `from` (Van Oosterom and Strackee 1983). A
// triangle this large next to the point is sampled uniformly in that solid angle
// (render/lights/triangle_light.h): its light density is 1 / omega.
double triangle_solid_angle(Vec3d from, Vec3d a, Vec3d b, Vec3d c) {
  a = a - from;
  b = b - from;
  c = c - from;
  const double la = shift::length(a), lb = shift::length(b), lc = shift::length(c);
  const double num = std::fabs(shift::dot(a, shift::cross(b, c)));
  const double den =
      la * lb * lc + shift::dot(a, b) * lc + shift::dot(a, c) * lb + shift::dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

// The pair weight over the base technique's density (p = p' = 1 at a camera vertex).
double pair_weight(double p_tech, double pl, double pb, double J, double pl_o, double pb_o) {
  return p_tech / (pl * pl + pb * pb + J * J * (pl_o * pl_o + pb_o * pb_o));
}

// ---------------------------------------------------------------------------------------------
// A scene, its contexts and one base vertex with one offset.
// ---------------------------------------------------------------------------------------------
struct Pair {
  Scene scene;
  RenderSettings settings;
  std::unique_ptr<SceneContext> ctx;
  std::unique_ptr<GptContext> g;
  std::unique_ptr<PathScratch> scratch{new PathScratch};
  Vec3f eye{0.0f, -1.0f, 0.9f};  // where both first vertices are seen from (the camera)

  Pair() {
    scene.world.color = Spectrum(0.0f);
    scene.meshes.push_back(quad(3.0f));  // 0: floor at z = 0, normal +z
    settings.mode = RenderSettings::Mode::GPT;
  }
  void build() {
    ctx = std::make_unique<SceneContext>(scene, settings);
    g = std::make_unique<GptContext>(*ctx, settings);
  }
  SurfaceHit hit_from_eye(Vec3f at) const {
    Ray r;
    r.origin = eye;
    r.direction = normalize(at - eye);
    SurfaceHit h;
    EXPECT_TRUE(ctx->bvh().intersect(r, h));
    return h;
  }
  Vertex& base() { return scratch->verts[0]; }
  Offset& offset() { return scratch->off[0]; }
  // Base vertex seen from the eye towards `x`, offset vertex towards `y` (offset 0 only).
  void place(Vec3f x, Vec3f y) {
    const SurfaceHit hx = hit_from_eye(x), hy = hit_from_eye(y);
    setup_vertex(*ctx, g->sides, g->rules(PathState{}), hx, normalize(hx.position - eye),
                 PathView{}, base());
    for (Offset& o : scratch->off) o.active = o.alive = false;
    Offset& o = offset();
    o.active = o.alive = true;
    o.failed = false;
    o.link = Link::NotConnected;
    o.f = Vec3d(1.0, 1.0, 1.0);
    o.p = 1.0;
    o.grad = Vec3d();
    setup_vertex(*ctx, g->sides, g->rules(PathState{}), hy, normalize(hy.position - eye),
                 PathView{}, o.v);
    o.nee_on = g->classify(base().roughness) == VertexType::Diffuse &&
               g->classify(o.v.roughness) == VertexType::Diffuse;
  }
};

// The base's BSDF "sample" towards a chosen direction, with its closures' value and density.
BsdfSample sample_towards(const Vertex& v, Vec3f dir, uint8_t lobe) {
  BsdfSample bs;
  bs.wo = v.frame.to_local(normalize(dir));
  float pdf = 0.0f;
  bs.value = v.closures->eval_pdf(v.wi, bs.wo, pdf);
  bs.pdf = pdf;
  bs.lobe = lobe;
  bs.roughness = v.roughness;
  bs.valid = pdf > 0.0f;
  return bs;
}

// The base's segment along `bs`, the offset shifted over it and the segment's emission events,
// as trace() runs them for one open offset.
struct Segment {
  BsdfSample bs;
  Ray ray;
  SurfaceHit next;
  bool found = false;
  LightHit lh;
  bool light_hit = false;
  SampleResult out{};
};

void run_segment(Pair& p, Segment& s, bool events = true) {
  const GptContext& g = *p.g;
  const Vertex& base = p.base();
  const Vec3f wo_world = base.frame.to_world(s.bs.wo);
  const float cos_ng = dot(wo_world, base.ng);
  s.ray.origin = ray_origin(base, cos_ng > 0.0f);
  s.ray.direction = normalize(wo_world);
  s.ray.t_max = kInf;
  s.ray.kind = ray_kind_of_lobe(s.bs.lobe);
  s.found = g.ctx.bvh().intersect(s.ray, s.next);
  s.light_hit =
      g.ctx.lights().intersect(s.ray.origin, s.ray.direction, s.found ? s.next.t : kInf, s.lh);
  const VertexType base_type = g.classify(base.roughness);
  static const PathState kFirstBounce;  // the test's materials follow no light-path rule
  const VertexType next_type = s.found ? g.classify_hit(s.next, kFirstBounce) : VertexType::Diffuse;
  BaseStep& st = p.scratch->step;
  st = BaseStep{&base,      &s.bs,   base_type,     next_type,
                wo_world,   s.found, &s.next,       delta_event_unique(base, s.bs),
                s.ray.kind, false,   &kFirstBounce, {},
                false};
  if (s.found && base_type == VertexType::Diffuse && next_type == VertexType::Diffuse) {
    st.target =
        shift::reconnection_base(base.hit.position, s.next.position, s.next.geometric_normal);
    st.base_front = dot(base.hit.position - s.next.position, s.next.geometric_normal) > 0;
  }
  shift_segment(g, p.offset(), st, s.out.rays);
  if (!events) return;
  const SegmentEnd e{&base,
                     base_type,
                     &s.ray,
                     false,
                     Vec3d(s.bs.value),
                     s.bs.pdf,
                     s.found,
                     false,
                     &s.next,
                     false,
                     g.has_world,
                     s.light_hit,
                     &s.lh,
                     &p.scratch->shadow_closures};
  BasePath bp;
  Vec3d merged = lamp_events(g, e, bp, 1u, p.scratch->off, s.out);
  end_events(g, e, bp, 1u, p.scratch->off, merged, s.out);
}

// Gradient half against w (C' - C), per channel; and the oracle's own power: a 3% error in J
// (when `jacobian_matters`) or in the pair term moves it by more than 20 tolerances.
void expect_pair_term(const Vec3d& grad, Vec3d cb, Vec3d co_per_j, double J, double pb, double pl,
                      double pl_o, double pb_o, double p_tech, const char* what) {
  auto term = [&](double j) {
    const double w = pair_weight(p_tech, pl, pb, j, pl_o, pb_o);
    return std::pair<Vec3d, double>{(co_per_j * j - cb) * w,
                                    w * std::max(shift::length(cb), shift::length(co_per_j * j))};
  };
  const auto [expected, scale] = term(J);
  const double tol = kTol * scale;
  EXPECT_NEAR(grad.x, expected.x, tol) << what;
  EXPECT_NEAR(grad.y, expected.y, tol) << what;
  EXPECT_NEAR(grad.z, expected.z, tol) << what;
  const double moved_j = shift::length(term(1.03 * J).first - expected);
  const double moved_term = 0.03 * shift::length(expected);
  EXPECT_GT(moved_j, 20.0 * tol) << what << ": the oracle cannot see a 3% Jacobian error";
  EXPECT_GT(moved_term, 20.0 * tol) << what << ": the oracle cannot see a 3% pair-term error";
  std::printf(
      "[%s] J %.6f, w(C'-C) %.6g %.6g %.6g; 3%% J error moves it by %.0f tol, 3%% term "
      "error by %.0f tol\n",
      what, J, expected.x, expected.y, expected.z, moved_j / tol, moved_term / tol);
}

constexpr uint8_t kDiffuseReflection = kLobeReflection | kLobeDiffuse;
constexpr uint8_t kGlossyReflection = kLobeReflection | kLobeGlossy;
constexpr double kInvPi = 1.0 / M_PI;

// A single emissive triangle of area 72 at z = 1.5 facing down (normal -z), over the floor.
void add_emissive_ceiling(Pair& p) {
  Mesh tri;
  tri.positions = {{-4, -4, 0}, {-4, 8, 0}, {8, -4, 0}};
  tri.indices = {0, 1, 2};
  p.scene.meshes.push_back(tri);
  p.scene.materials.push_back(emissive({1.0f, 0.9f, 0.8f}, 2.0f));
  p.scene.instances.push_back(place(uint32_t(p.scene.meshes.size() - 1),
                                    int32_t(p.scene.materials.size() - 1),
                                    transform(0, 0, {0, 0, 1.5f})));
}

// A square area light of side `size` at z = 1.5 emitting down.
void add_area_light(Pair& p, float size) {
  Light l;
  l.type = Light::Type::Area;
  l.power = 20.0f;
  l.size_x = l.size_y = size;
  l.light_to_world = transform(0, 0, {0, 0, 1.5f});
  p.scene.lights.push_back(l);
}

// ---------------------------------------------------------------------------------------------
// Reconnection at a diffuse vertex to an emissive triangle hit by the base's BSDF sample
// (end_events, Shift::Reconnect): J of the reconnection, both techniques on both sides.
// ---------------------------------------------------------------------------------------------
TEST(GradientPairTerms, ReconnectionToAnEmissiveTriangleHitByBsdfSampling) {
  Pair p;
  p.scene.materials.push_back(diffuse({0.5f, 0.5f, 0.5f}));
  p.scene.instances.push_back(place(0, 0, Transform()));
  add_emissive_ceiling(p);
  p.build();
  p.place({0.0f, 0.0f, 0.0f}, {0.25f, 0.15f, 0.0f});
  Segment s;
  s.bs =
      sample_towards(p.base(), Vec3f(0.6f, 0.9f, 1.5f) - p.base().hit.position, kDiffuseReflection);
  run_segment(p, s);
  ASSERT_TRUE(s.found);
  ASSERT_EQ(p.offset().shift, Shift::Reconnect);

  const Vec3d x = d3(p.base().hit.position), y = d3(p.offset().v.hit.position);
  const Vec3d t = d3(s.next.position), nl(0, 0, -1);
  const double J = reconnection_jacobian(x, y, t, nl);
  const double cos_x = shift::normalize(t - x).z, cos_y = shift::normalize(t - y).z;
  const Vec3d le(2.0, 1.8, 1.6);
  const Vec3d cb = le * (0.5 * kInvPi * cos_x), co = le * (0.5 * kInvPi * cos_y);
  const double pb = cos_x * kInvPi, pb_o = cos_y * kInvPi;
  const Vec3d a(-4, -4, 1.5), b(-4, 8, 1.5), c(8, -4, 1.5);
  const double pl = 1.0 / triangle_solid_angle(x, a, b, c);
  const double pl_o = 1.0 / triangle_solid_angle(y, a, b, c);
  expect_pair_term(p.offset().grad, cb, co, J, pb, pl, pl_o, pb_o, pb, "reconnect, BSDF hit");
}

// ---------------------------------------------------------------------------------------------
// Half-vector copy at a glossy vertex classified specular (threshold raised above its alpha):
// the offset's own ray, J of the copy, the BSDF technique alone (NEE not shifted at specular
// vertices).
// ---------------------------------------------------------------------------------------------
TEST(GradientPairTerms, HalfVectorCopyToAnEmissiveTriangle) {
  Pair p;
  p.settings.shift_roughness_threshold = 0.5f;                    // alpha 0.09 is specular
  p.scene.materials.push_back(glossy({0.8f, 0.8f, 0.8f}, 0.3f));  // GGX alpha 0.09
  p.scene.instances.push_back(place(0, 0, Transform()));
  add_emissive_ceiling(p);
  p.build();
  p.place({0.0f, 0.0f, 0.0f}, {0.5f, -0.3f, 0.0f});
  Segment s;
  s.bs =
      sample_towards(p.base(), Vec3f(0.1f, 1.55f, 1.5f) - p.base().hit.position, kGlossyReflection);
  run_segment(p, s);
  ASSERT_TRUE(s.found);
  const Offset& o = p.offset();
  ASSERT_EQ(o.shift, Shift::HalfVector);
  ASSERT_TRUE(o.next_found);
  ASSERT_FALSE(o.killed);

  const Vec3d x = d3(p.base().hit.position), y = d3(o.v.hit.position), e = d3(p.eye);
  const Vec3d wi = shift::normalize(e - x), wi_o = shift::normalize(e - y);
  const Vec3d wo = shift::normalize(d3(s.next.position) - x);
  const Vec3d wo_o = reflect_about_half(wi, wo, wi_o);
  EXPECT_NEAR(shift::length(d3(o.seg_dir) - wo_o), 0.0, 1e-5);
  const double J = fd_jacobian(wo, [&](Vec3d d) { return reflect_about_half(wi, d, wi_o); });
  // The glossy lobe's value and density at both vertices (its own tests cover them).
  float pdf_b = 0.0f, pdf_o = 0.0f;
  const Spectrum fb = p.base().closures->eval_pdf(p.base().wi, s.bs.wo, pdf_b);
  const Spectrum fo = o.v.closures->eval_pdf(o.v.wi, o.v.frame.to_local(wo_o.to_float()), pdf_o);
  const Vec3d le(2.0, 1.8, 1.6);
  const Vec3d cb = shift::mul(le, fb), co = shift::mul(le, fo);
  expect_pair_term(o.grad, cb, co, J, pdf_b, 0.0, 0.0, pdf_o, pdf_b, "half-vector, BSDF hit");
}

// ---------------------------------------------------------------------------------------------
// The base's BSDF sample crosses an analytic area light (lamp_events): the offset reconnects to
// the same light point; the weights use the area-sampling density on both sides.
// ---------------------------------------------------------------------------------------------
TEST(GradientPairTerms, ReconnectionToAnAreaLightHitByBsdfSampling) {
  Pair p;
  p.scene.materials.push_back(diffuse({0.5f, 0.5f, 0.5f}));
  p.scene.instances.push_back(place(0, 0, Transform()));
  add_area_light(p, 0.4f);
  p.build();
  p.place({0.0f, 0.0f, 0.0f}, {0.25f, 0.15f, 0.0f});
  Segment s;
  s.bs = sample_towards(p.base(), Vec3f(-0.15f, -0.12f, 1.5f) - p.base().hit.position,
                        kDiffuseReflection);
  run_segment(p, s);
  ASSERT_FALSE(s.found);
  ASSERT_TRUE(s.light_hit);

  const Vec3d x = d3(p.base().hit.position), y = d3(p.offset().v.hit.position);
  const Vec3d t = d3(s.lh.position), nl(0, 0, -1);
  const double J = reconnection_jacobian(x, y, t, nl);
  const double cos_x = shift::normalize(t - x).z, cos_y = shift::normalize(t - y).z;
  const Vec3d le = d3(s.lh.radiance);
  const Vec3d cb = le * (0.5 * kInvPi * cos_x), co = le * (0.5 * kInvPi * cos_y);
  const double pb = cos_x * kInvPi, pb_o = cos_y * kInvPi;
  const double pl = area_density(x, t, nl, 0.16), pl_o = area_density(y, t, nl, 0.16);
  expect_pair_term(p.offset().grad, cb, co, J, pb, pl, pl_o, pb_o, pb, "reconnect, lamp hit");
}

// ---------------------------------------------------------------------------------------------
// Next-event estimation (nee_pairs): the offset reuses the base's point on the area light.
// ---------------------------------------------------------------------------------------------
TEST(GradientPairTerms, NextEventSampleSharedByTheOffset) {
  Pair p;
  p.scene.materials.push_back(diffuse({0.5f, 0.5f, 0.5f}));
  p.scene.instances.push_back(place(0, 0, Transform()));
  add_area_light(p, 0.4f);
  p.build();
  p.place({0.0f, 0.0f, 0.0f}, {0.25f, 0.15f, 0.0f});
  const Vec2f u(0.3f, 0.7f);
  const LightSample ls = p.ctx->lights().sample(p.base().hit.position, 0.0f, u);
  ASSERT_TRUE(ls.valid);
  BasePath bp;
  SampleResult out{};
  nee_pairs(*p.g, p.base(), bp, ls, 0.0f, u, 1u, *p.scratch, out);

  const Vec3d x = d3(p.base().hit.position), y = d3(p.offset().v.hit.position);
  const Vec3d t = d3(ls.position), nl(0, 0, -1);
  // The light point is fixed: J = d omega_y / d omega_x of that point's area element.
  const double J = area_density(x, t, nl, 1.0) / area_density(y, t, nl, 1.0);
  const double cos_x = shift::normalize(t - x).z, cos_y = shift::normalize(t - y).z;
  const Vec3d le = d3(ls.radiance);
  const Vec3d cb = le * (0.5 * kInvPi * cos_x), co = le * (0.5 * kInvPi * cos_y);
  const double pb = cos_x * kInvPi, pb_o = cos_y * kInvPi;
  const double pl = area_density(x, t, nl, 0.16), pl_o = area_density(y, t, nl, 0.16);
  ASSERT_NEAR(ls.pdf, pl, 1e-5 * pl);  // a small light: sampled by area
  expect_pair_term(p.offset().grad, cb, co, J, pb, pl, pl_o, pb_o, pl, "next event");
}

// ---------------------------------------------------------------------------------------------
// The invertibility kill: x_d and y_d diffuse, x_{d+1} specular, so the offset takes the
// half-vector copy; where its own next vertex y_{d+1} is diffuse the reverse shift would
// reconnect, so the offset must die and add -w C (density 0). Where y_{d+1} is specular too it
// lives. Both panels emit: the offset's end point would otherwise give C'.
// ---------------------------------------------------------------------------------------------
MaterialDesc emitting(MaterialDesc bsdf) {
  MaterialDesc m = bsdf;
  m.nodes.push_back(emissive({1.0f, 1.0f, 1.0f}, 1.0f).nodes[0]);
  ShaderNode add;
  add.kind = ShaderNodeKind::Add;
  add.a = 0;
  add.b = 1;
  m.nodes.push_back(add);
  m.root = 2;
  return m;
}

// Floor, and two panels at z = 1 facing down meeting at x = 0.2: glossy (specular at threshold
// 0.5) for x < 0.2, the right one `right` for x > 0.2.
Pair kill_scene(MaterialDesc right) {
  Pair p;
  p.settings.shift_roughness_threshold = 0.5f;
  p.scene.materials.push_back(diffuse({0.5f, 0.5f, 0.5f}));
  p.scene.materials.push_back(emitting(glossy({0.8f, 0.8f, 0.8f}, 0.3f)));
  p.scene.materials.push_back(emitting(right));
  p.scene.meshes.push_back(quad(0.5f));
  p.scene.instances.push_back(place(0, 0, Transform()));
  const float h = kPi;  // rotated half a turn about y: normal -z
  p.scene.instances.push_back(place(1, 1, transform(0, h, {-0.3f, 0, 1})));
  p.scene.instances.push_back(place(1, 2, transform(0, h, {0.7f, 0, 1})));
  return p;
}

TEST(GradientPairTerms, InvertibilityKill) {
  for (const bool right_diffuse : {true, false}) {
    Pair p =
        kill_scene(right_diffuse ? diffuse({0.5f, 0.5f, 0.5f}) : glossy({0.8f, 0.8f, 0.8f}, 0.3f));
    p.build();
    p.place({0.0f, 0.0f, 0.0f}, {0.3f, 0.02f, 0.0f});
    Segment s;
    s.bs = sample_towards(p.base(), Vec3f(0.1f, 0.3f, 1.0f) - p.base().hit.position,
                          kDiffuseReflection);
    run_segment(p, s);
    ASSERT_TRUE(s.found);
    ASSERT_LT(s.next.position.x, 0.2f);  // the base meets the glossy panel
    Offset& o = p.offset();
    ASSERT_EQ(o.shift, Shift::HalfVector);
    ASSERT_TRUE(o.next_found);
    ASSERT_GT(o.next_hit.position.x, 0.2f);  // the offset meets the right panel
    EXPECT_EQ(o.killed, right_diffuse);
    // The pair term: the base's emission C weighted with the BSDF and light techniques, the
    // offset's C' = 0 when killed.
    const double pb = s.bs.pdf;
    const double pl =
        p.ctx->lights().pdf_triangle(s.next.instance, s.next.primitive, p.base().hit.position,
                                     s.next.position, s.next.geometric_normal);
    const Vec3d cb = shift::mul(Vec3d(1, 1, 1), s.bs.value);
    if (right_diffuse) {
      const Vec3d expected = cb * (-pb / (pl * pl + pb * pb));
      EXPECT_NEAR(o.grad.x, expected.x, kTol * shift::length(expected)) << "killed offset";
      EXPECT_GT(shift::length(expected), 0.0);
    } else {
      EXPECT_NE(o.grad.x, -pb / (pl * pl + pb * pb) * cb.x) << "a living offset adds its C'";
    }
    advance(*p.g, o, false, PathState{}, PathView{});
    EXPECT_EQ(o.alive, !right_diffuse);
    EXPECT_EQ(o.failed, right_diffuse);
  }
}

}  // namespace
}  // namespace gdpt::gradient_test

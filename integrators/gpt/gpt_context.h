// What every phase of the G-PT reads of the scene and the settings, fixed for a session.
#pragma once

#include <vector>

#include "integrators/common/data_passes.h"
#include "integrators/common/feature_passes.h"
#include "integrators/gpt/path_vertex.h"
#include "integrators/gpt/shift_mapping.h"
#include "render/features.h"
#include "render/scene_context.h"
#include "scene/render_settings.h"

namespace gdpt {

// Offset order: +x (right), +y (up), -x (left), -y (down), as CameraModel::generate_offset_rays.
inline constexpr int kOffsets = 4;
enum : int { kRight = 0, kUp = 1, kLeft = 2, kDown = 3 };

struct GptContext {
  GptContext(const SceneContext& c, const RenderSettings& s)
      : ctx(c),
        settings(s),
        has_world(c.lights().has_environment()),
        has_camera_world(c.lights().has_camera_environment()),
        has_visible_lamps(c.lights().has_camera_visible_lights()),
        has_dof(c.camera().has_dof()),
        has_emissive((c.features() & kSceneEmissiveTriangles) != 0),
        transparent_shadows((c.features() & kFeatureTransparent) != 0),
        sides(material_sides(c)),
        data(s, c.camera()),
        features(s),
        filters(s) {}

  const SceneContext& ctx;
  RenderSettings settings;
  bool has_world, has_camera_world, has_visible_lamps, has_dof, has_emissive;
  bool transparent_shadows;  // some material has a Transparent closure
  std::vector<MaterialSide> sides;
  DataPasses data;
  FeaturePasses features;
  LightPathFilters filters;  // Filter Glossy and caustics (light_path_filters.h)

  // Kettunen et al.'s vertex classification: specular (half-vector copy) or diffuse (reconnect).
  shift::VertexType classify(float roughness) const {
    return shift::classify_vertex(roughness, settings.shift_roughness_threshold);
  }
  // Emission of an emissive triangle at `hit` towards `from`, reached by `path` (its ray length
  // is the distance to `from`); none without emissive triangles.
  Spectrum triangle_le(const SurfaceHit& hit, Vec3f from, const PathView& path) const {
    return has_emissive ? triangle_emission(ctx, hit, from, path) : Spectrum(0.0f);
  }
  // The classification of a path's end point that is not set up as a vertex, reached with the
  // base's path state `state`.
  shift::VertexType classify_hit(const SurfaceHit& h, const PathState& state) const {
    return classify(hit_roughness(ctx, sides, rules(state), h));
  }
  VertexRules rules(const PathState& state) const { return {filters, state}; }
};

// Starts the sample of sequence index `index` (Film::sequence_index) of pixel (x, y).
inline void start_sample(const GptContext& g, Sampler& sampler, int x, int y, uint32_t index) {
  sampler.start(g.settings.seed, x, y, index);
}

}  // namespace gdpt

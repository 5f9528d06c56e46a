// Blender's Normal and Mist data passes, per camera sample, as Cycles 3.4 writes them
// (kernel/film/data_passes.h):
//  - Normal: at the first surface of the camera path whose coverage (1 - the Transparent
//    closures' weight, averaged over RGB) is at least 0.5 (Cycles' pass_alpha_threshold), the
//    shading normal turned towards the camera ray; nothing without such a surface. The film
//    averages over samples (edges blend, lengths drop below 1, as in Cycles).
//  - Mist: at every surface of the camera path, (1 - mist(d)) x mean(throughput x coverage),
//    mist(d) = clamp((d - start) / depth, 0, 1) ^ falloff, d the distance from the camera
//    (CameraModel::camera_distance); the film outputs 1 - the mean, so the sky reads 1.
// The camera path is the camera ray and the straight transparent crossings after it (PT and
// G-PT alike).
#pragma once

#include <algorithm>
#include <cmath>

#include "render/camera.h"
#include "render/embree_scene.h"
#include "scene/render_settings.h"
#include "shaders/bsdf.h"

namespace gdpt {

// One camera sample's values, filled along its camera path.
struct DataSample {
  Vec3f normal;
  float mist = 0.0f;
  bool normal_done = false;
};

class DataPasses {
 public:
  DataPasses(const RenderSettings& s, const CameraModel& camera)
      : camera_(camera),
        normal_(s.normal_pass),
        mist_(s.mist_pass),
        start_(s.mist_start),
        inv_depth_(s.mist_depth > 0.0f ? 1.0f / s.mist_depth : 0.0f),
        falloff_(s.mist_falloff) {}

  bool active() const { return normal_ || mist_; }

  // A surface of the camera path, reached with throughput `beta`, its closures evaluated.
  void at_surface(const SurfaceHit& hit, const ClosureSet& closures, Spectrum beta,
                  DataSample& out) const {
    const Spectrum transparency = closures.transparency();
    const Spectrum coverage(std::clamp(1.0f - transparency.x, 0.0f, 1.0f),
                            std::clamp(1.0f - transparency.y, 0.0f, 1.0f),
                            std::clamp(1.0f - transparency.z, 0.0f, 1.0f));
    const float mean_coverage = (coverage.x + coverage.y + coverage.z) / 3.0f;
    if (normal_ && !out.normal_done && mean_coverage >= 0.5f) {
      out.normal = hit.front_facing ? hit.shading_normal : -hit.shading_normal;
      out.normal_done = true;
    }
    if (mist_) {
      float m =
          std::clamp((camera_.camera_distance(hit.position) - start_) * inv_depth_, 0.0f, 1.0f);
      if (falloff_ == 2.0f)
        m *= m;
      else if (falloff_ == 0.5f)
        m = std::sqrt(m);
      else if (falloff_ != 1.0f)
        m = std::pow(m, falloff_);
      const Spectrum w = beta * coverage;
      out.mist += (1.0f - m) * (w.x + w.y + w.z) / 3.0f;
    }
  }

 private:
  const CameraModel& camera_;
  bool normal_, mist_;
  float start_, inv_depth_, falloff_;
};

}  // namespace gdpt

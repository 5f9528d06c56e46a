// Brightness against Cycles itself: irradiance at the origin (normal +Z) for the six light set-ups
// of cycles_reference.py (eight of them), compared with the radiance Blender 3.4.1 Cycles rendered
// on a white Lambert plane there (256 spp, 1024 for the two lights with a radius; 0 bounces;
// radiance = E / pi). This pins the units (area P / (4 A) with object scale, point P / (4 pi),
// radius as a facing disc, spot cos * smoothstep, sun disc) to Cycles.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "light_test_util.h"
#include "render/light_sampler.h"

namespace gdpt {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// Blender's default light frame: rotation only where the script sets one (local -Z down).
Transform frame(Vec3f position, float rot_x_deg = 0.0f, float scale_x = 1.0f) {
  const float r = rot_x_deg * float(kPiD) / 180.0f, c = std::cos(r), s = std::sin(r);
  // Rotation about X (Blender Euler XYZ with only X set), then scale on local X.
  const float rows[12] = {scale_x, 0, 0, position.x, 0, c, -s, position.y, 0, s, c, position.z};
  return Transform::from_rows(rows);
}

double plane_radiance(const Light& l) {
  Scene scene = test::black_scene();
  scene.lights.push_back(l);
  const LightSampler lights(scene, {}, {});
  return test::estimate(lights, {0, 0, 0}, {0, 0, 1}, 250000).irradiance / kPiD;
}

TEST(CyclesReference, RenderedRadianceOfALambertPlane) {
  struct Case {
    const char* name;
    Light light;
    double cycles;  // mean pixel value rendered by Blender 3.4.1 Cycles
  };
  Light area;
  area.type = Light::Type::Area;
  area.shape = Light::Shape::Square;
  area.size_x = 1.0f;
  area.power = 100.0f;
  area.light_to_world = frame({0, 0, 2});
  Light area_scaled = area;
  area_scaled.shape = Light::Shape::Rectangle;
  area_scaled.size_y = 0.5f;
  area_scaled.light_to_world = frame({0, 0, 2}, 0.0f, 2.0f);
  Light disk = area;
  disk.shape = Light::Shape::Disk;
  disk.size_x = 2.0f;
  disk.light_to_world = frame({0, 0, 1.5f});
  Light point;
  point.type = Light::Type::Point;
  point.radius = 0.0f;
  point.power = 100.0f;
  point.light_to_world = frame({0, 0, 3});
  Light spot = point;
  spot.type = Light::Type::Spot;
  spot.spot_size = 1.0f;
  spot.spot_blend = 0.5f;
  spot.light_to_world = frame({3.0f * std::tan(0.35f), 0, 3});
  Light point_radius = point;
  point_radius.radius = 0.5f;
  point_radius.light_to_world = frame({0, 0, 1.5f});
  Light spot_radius = spot;
  spot_radius.radius = 0.3f;
  spot_radius.power = 80.0f;
  spot_radius.spot_size = 0.8f;
  spot_radius.spot_blend = 0.6f;
  spot_radius.light_to_world = frame({0.4f, 0, 1.5f});
  Light sun;
  sun.type = Light::Type::Sun;
  sun.power = 3.0f;
  sun.sun_angle = 10.0f * float(kPiD) / 180.0f;
  sun.light_to_world = frame({0, 0, 0}, 30.0f);
  const Case cases[] = {{"area", area, 1.8372802380472422},
                        {"area_scaled", area_scaled, 1.7016874235123396},
                        {"disk", disk, 2.4488340467214584},
                        {"point", point, 0.2814468815922737},
                        {"point_radius", point_radius, 1.0131703354418278},
                        {"spot", spot, 0.21915356907993555},
                        {"spot_radius", spot_radius, 0.5208117729052901},
                        {"sun", sun, 0.825493011623621}};
  for (const Case& c : cases) {
    const double ours = plane_radiance(c.light);
    EXPECT_NEAR(ours, c.cycles, 2e-3 * c.cycles) << c.name << ": ours " << ours;
  }
}

// Equirectangular world (16 x 8 image, strength 0.7), plane tilted 60 degrees towards +X, with
// and without a Mapping rotation of 90 degrees about Z: checks the image orientation (Cycles'
// direction_to_equirectangular) and the rotation convention, not only the units.
TEST(CyclesReference, EquirectangularWorldOnATiltedPlane) {
  ImageDesc img;
  img.name = "env";
  img.width = 16;
  img.height = 8;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      img.rgba.push_back(0.1f + float((x * 7 + y * 3) % 11) * 0.3f);
      img.rgba.push_back(0.2f + float((x * 5 + y * 11) % 7) * 0.25f);
      img.rgba.push_back(0.05f + float((x * 3 + y * 5) % 13) * 0.1f);
      img.rgba.push_back(1.0f);
    }
  const float a = 60.0f * float(kPiD) / 180.0f;
  const Vec3f n(std::sin(a), 0.0f, std::cos(a));
  const float rot_z90[12] = {0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0};
  struct Case {
    const char* name;
    Transform rotation;
    double cycles;  // red channel rendered by Blender 3.4.1 Cycles, 1024 spp
  };
  const Case cases[] = {{"world", Transform(), 1.1566553208976984},
                        {"world_rotated", Transform::from_rows(rot_z90), 1.1167695838958025}};
  for (const Case& c : cases) {
    Scene scene = test::black_scene();
    scene.images.push_back(img);
    scene.world.image = 0;
    scene.world.strength = 0.7f;
    scene.world.rotation = c.rotation;
    const LightSampler lights(scene, {}, {});
    const double ours = test::estimate(lights, {0, 0, 0}, n, 1000000).irradiance / kPiD;
    EXPECT_NEAR(ours, c.cycles, 3e-3 * c.cycles) << c.name << ": ours " << ours;
  }
}

// Emission plane (strength 2, 1 x 1 m at z = 1, normal +Z) seen from its back: Cycles' mesh
// lights emit colour * strength on both sides.
TEST(CyclesReference, EmissionPlaneSeenFromBehind) {
  Scene scene = test::black_scene();
  scene.materials.push_back(test::emission_material({1, 1, 1}, 2.0f));
  Mesh mesh;  // Blender's plane: counter-clockwise seen from +Z
  mesh.positions = {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}};
  mesh.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(mesh);
  Instance inst;
  const float rows[12] = {1, 0, 0, 0.2f, 0, 1, 0, 0.1f, 0, 0, 1, 1.0f};
  inst.object_to_world = Transform::from_rows(rows);
  inst.slot_material = {0};
  scene.instances.push_back(inst);
  const std::vector<Material> materials = {Material(scene.materials[0], {})};
  const LightSampler lights(scene, materials, {});
  const double ours = test::estimate(lights, {0, 0, 0}, {0, 0, 1}, 250000).irradiance / kPiD;
  const double cycles = 0.4524377346970141;  // Blender 3.4.1 Cycles, 1024 spp
  EXPECT_NEAR(ours, cycles, 3e-3 * cycles) << "ours " << ours;
}

}  // namespace
}  // namespace gdpt

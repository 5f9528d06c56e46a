// Plain-data description of a material, translated from a Blender node tree by the add-on
// (or built directly by tests). A material is a small expression tree of shader nodes; inputs are
// constants, image-texture lookups, or small expression trees of colour / math nodes over them
// (InputNode). shaders/ compiles it into closures at each hit point.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/transform.h"
#include "core/vec.h"
#include "scene/node_types.h"

namespace gdpt {

// Blender's Texture Coordinate outputs a texture can read (Cycles' names): UV is (u, v, 0) of the
// mesh's UV map; Object the object-space position; Generated the object-space position mapped
// from the mesh's texture space (Mesh::texspace_*) to [0, 1]^3; Position the world-space position
// (the Geometry node's Position output); Node the result of an input node (InputNode), e.g. a
// Vector Math node or coordinates distorted by a Noise Texture's colour.
enum class TexCoordSource : uint8_t { UV, Generated, Object, Position, Node };

// The vector a texture reads: a coordinate source through an optional Mapping node.
struct TextureVector {
  TexCoordSource source = TexCoordSource::UV;
  int32_t node = -1;  // Node: index into MaterialDesc::inputs
  Transform mapping;  // Blender's Mapping node (Point / Texture type) applied to the coordinates
};

// Texture lookup: Scene::images[image] sampled at (x, y) of its vector (Image Texture, Flat).
struct TextureLookup {
  int32_t image = -1;  // -1: no texture, use the constant
  TextureVector vector;
  enum class Interpolation : uint8_t { Linear, Closest } interpolation = Interpolation::Linear;
  enum class Extension : uint8_t { Repeat, Extend, Clip } extension = Extension::Repeat;
};

struct ColorInput {
  ColorInput() = default;
  explicit ColorInput(Spectrum v) : value(v) {}
  Spectrum value{0.8f, 0.8f, 0.8f};
  TextureLookup texture;  // when texture.image >= 0, the texture's RGB replaces value
  int32_t node = -1;      // when >= 0: MaterialDesc::inputs[node]'s result replaces both
};

struct FloatInput {
  FloatInput() = default;
  explicit FloatInput(float v) : value(v) {}
  float value = 0.0f;
  TextureLookup texture;  // when texture.image >= 0: the texture's channel below replaces value
  enum class Channel : uint8_t { Luminance, Red, Alpha } channel = Channel::Luminance;
  // When >= 0: MaterialDesc::inputs[node]'s result replaces value and texture (a colour result is
  // read as its luminance, as Blender converts a colour socket to a float one).
  int32_t node = -1;
};

// Colour and math nodes between textures / constants and shader inputs, with Cycles' semantics
// (kernel/svm/mix.h, math_util.h, invert.h). Results are colours (a Math result is grey).
enum class InputNodeKind : uint8_t {
  Mix,         // Blender's Mix (colour) / MixRGB: blend of a and b by fac, `blend` below
  Math,        // Blender's Math on value_a, value_b: `math` below
  Invert,      // mix(a, 1 - a, fac)
  Ramp,        // Blender's Color Ramp read at fac: `ramp` table, Cycles' lookup (rgb_ramp_lookup)
  Separate,    // one channel (`channel`) of a, as grey (Separate RGB / Separate Color in RGB)
  Combine,     // (value_a, value_b, value_c) (Combine RGB / Combine Color in RGB)
  CombineXyz,  // the vector (value_a, value_b, value_c) (Combine XYZ)
  Gamma,       // a^value_a per positive channel; 1 for gamma 0 (svm_math_gamma_color)
  BrightContrast,  // max((1 + c) a + b - c / 2, 0), b = value_a, c = value_b
  HueSaturation,   // Hue/Saturation/Value of a: hue value_a, saturation value_b, value value_c,
                   // blended by fac (svm_node_hsv)
  MapRange,        // linear Map Range of value_a from [bounds 0, 1] to [bounds 2, 3], clamp_result
  Clamp,           // value_a clamped to [value_b, value_c] (Min Max; swapped bounds: Range)
  ToBw,            // luminance of a, as grey (RGB to BW)
  Attribute,       // the mesh's colour attribute (Color Attribute node; ShadingContext::color)
  Checker,         // Checker Texture at `vector` x scale value_a: colour a or b (svm_checker)
  Noise,           // Noise Texture of `noise_dimensions` at `vector` and W value_d, both x scale
                   // value_a: detail value_b, roughness value_c, distortion fac (Blender 3.4's fBm
                   // of Perlin noise, noise_texture_Nd)
  Coordinates,     // `vector` itself as a colour (a Texture Coordinate / Mapping output plugged
                   // into a colour or float input)
  Voronoi,         // 3D Voronoi Texture `voronoi_feature` at `vector` x scale value_a: randomness
                   // value_b, Minkowski exponent value_c, metric `voronoi_metric`, smoothness
                   // value_d; Distance (fac_output), Color or Position (position_output)
  Gradient,        // Gradient Texture of type `gradient_type` at `vector`, clamped to [0, 1]
  Wave,            // Wave Texture `wave` at `vector` x scale value_a: distortion value_b, detail
                   // value_c, detail scale value_d, detail roughness value_e, phase value_f
  WhiteNoise,      // 3D White Noise Texture at `vector`: a hash of its bits, Value (fac_output)
                   // or Color
  Magic,           // Magic Texture at `vector` x scale value_a, distortion value_b, depth
                   // `magic_depth`; Fac (the colour's mean) or Color
  Musgrave,        // 3D Musgrave Texture `musgrave_type` at `vector` x scale value_a: detail
                   // value_b, dimension value_c, lacunarity value_d, offset value_e, gain value_f
  VectorMath,      // Vector Math `vector_math` of vectors a, b, c and scale value_a: the Vector,
                   // or the Value (fac_output, as grey)
  Brick,           // Brick Texture `brick` at `vector` x scale value_a: colours a, b, mortar c;
                   // mortar size value_b, smooth value_c, bias value_d, brick width value_e, row
                   // height value_f; Color, or the mortar factor (Fac, fac_output)
  // RGB / Vector Curves of a, Float Curve of value_a, mixed with the input by fac: each channel k
  // looked up in column k (Float Curve: column 0) of the `ramp` table, the curve mapping sampled
  // over [bounds 0, bounds 1] as Cycles bakes it (RGB Curves: the combined curve applied first),
  // extrapolated linearly outside it (svm_node_curves, rgb_ramp_lookup).
  RgbCurves,
  VectorCurves,  // a vector result (a float socket reads the mean of its components)
  FloatCurve,
  Blackbody,    // Cycles' piecewise fit of the colour of a black body at value_a kelvin (Rec.709)
  SeparateHsv,  // one channel (`channel`: hue, saturation, value) of a, as grey (Cycles'
                // rgb_to_hsv)
  CombineHsv,   // the colour of hue value_a, saturation value_b, value value_c (hsv_to_rgb)
  // Nodes that read the view of the hit (ShadingContext::geometry), at the interpolated normal
  // or, with normal_linked, the material's normal map / bump:
  Fresnel,      // the dielectric reflectance of IOR value_a (Cycles' svm_node_fresnel)
  LayerWeight,  // blend value_a; `channel` 0: the Fresnel output, 1: Facing (svm_node_layer_weight)
  Geometry,     // the Geometry node's `geometry_output` (Position is a Coordinates node)
  LightPath,    // the Light Path node's `light_path_output` (ShadingContext::path)
  // Nodes that read the hit's instance, triangle or the camera (ShadingContext::instance,
  // ShadingCamera), as Cycles 3.4's svm_node_vector_transform and svm_node_wireframe:
  VectorTransform,  // vector a through `vector_transform` (a vector result)
  Wireframe,        // 1 within value_a / 2 of the hit triangle's edge lines, else 0; in world
                    // units, or with pixel_size in pixels of the camera's footprint at the hit
};
// The Light Path node's outputs (Cycles' svm_node_light_path for surface shading).
enum class LightPathOutput : uint8_t {
  IsCameraRay,
  IsShadowRay,
  IsDiffuseRay,
  IsGlossyRay,
  IsSingularRay,
  IsReflectionRay,
  IsTransmissionRay,
  RayLength,
  RayDepth,
  DiffuseDepth,
  GlossyDepth,
  TransparentDepth,
  TransmissionDepth,
};
// The Geometry node's outputs read from ShadingContext::geometry (world space, flipped to the
// incoming side as Cycles' sd->N / sd->Ng), Backfacing (1 on a back face, else 0), Tangent
// (Cycles' default tangent, TangentInput's radial about Z, made normal to the interpolated normal),
// and those read from ShadingContext::attributes (Mesh::vertex_pointiness,
// Mesh::triangle_island_random, and Parametric: Cycles' (1 - u - v, u, 0) of the hit's
// barycentrics).
enum class GeometryOutput : uint8_t {
  Normal,
  TrueNormal,
  Incoming,
  Backfacing,
  Tangent,
  Pointiness,
  Parametric,
  RandomPerIsland
};
// Geometry outputs that come from the mesh at the hit rather than from the view.
inline bool is_surface_attribute(GeometryOutput o) {
  return o == GeometryOutput::Pointiness || o == GeometryOutput::Parametric ||
         o == GeometryOutput::RandomPerIsland;
}
enum class MixBlend : uint8_t {
  Mix,
  Add,
  Multiply,
  Subtract,
  Screen,
  Divide,
  Difference,
  Darken,
  Lighten,
};

struct InputNode {
  InputNodeKind kind = InputNodeKind::Mix;
  MixBlend blend = MixBlend::Mix;
  MathOp math = MathOp::Add;
  bool clamp_factor = true;   // Mix: fac clamped to [0, 1] first
  bool clamp_result = false;  // result clamped to [0, 1] per channel
  FloatInput fac{0.5f};       // Mix, Invert
  ColorInput a, b;            // Mix (a, b), Invert (a), Vector Math (vectors a, b)
  ColorInput c;               // Vector Math (vector c)
  VectorMathOp vector_math = VectorMathOp::Add;
  FloatInput value_a, value_b;  // Math, Gamma (a), Bright / Contrast (a, b), Combine (a, b)
  FloatInput value_c;           // Combine
  FloatInput value_d, value_e, value_f;  // Wave, Musgrave
  uint8_t channel = 0;                   // Separate: 0 red, 1 green, 2 blue
  bool normal_linked = false;  // Fresnel, Layer Weight: Normal takes the normal map / bump
  GeometryOutput geometry_output = GeometryOutput::Normal;
  LightPathOutput light_path_output = LightPathOutput::IsCameraRay;
  VectorTransformDesc vector_transform;
  bool pixel_size = false;  // Wireframe: Use Pixel Size
  // Ramp: RGBA at fac = i / (n - 1), i < n (Blender's ColorRamp.evaluate, as Cycles bakes it),
  // interpolated linearly between entries unless the ramp is Constant; the result is the colour,
  // or the alpha as grey for the node's Alpha output.
  std::vector<float> ramp;  // 4 n floats
  // MapRange: from min, from max, to min, to max (constants; Blender's default range). Curves:
  // the table's input range in bounds 0 and 1.
  std::array<float, 4> bounds{0.0f, 1.0f, 0.0f, 1.0f};
  bool ramp_interpolate = true;
  bool ramp_alpha = false;
  bool clamp_range = false;  // Clamp: Range type (swapped bounds clamp to [max, min])
  TextureVector vector;      // Checker, Noise: where they are read; Coordinates: the value
  bool fac_output = false;   // a texture's grey output (Fac; Voronoi: Distance) instead of Color
  bool position_output = false;  // Voronoi: the Position output
  VoronoiMetric voronoi_metric = VoronoiMetric::Euclidean;
  // Voronoi: F1, F2, Smooth F1 (smoothness value_d) or Distance to Edge (a Distance only).
  enum class VoronoiFeature : uint8_t { F1, F2, SmoothF1, DistanceToEdge };
  VoronoiFeature voronoi_feature = VoronoiFeature::F1;
  GradientType gradient_type = GradientType::Linear;
  WaveDesc wave;
  uint8_t noise_dimensions = 3;  // Noise: 1, 2, 3 or 4
  uint8_t magic_depth = 2;       // Magic: 0 to 10
  MusgraveType musgrave_type = MusgraveType::Fbm;
  BrickDesc brick;
};

enum class ShaderNodeKind : uint8_t {
  Diffuse,  // Blender Diffuse BSDF: Lambert (roughness 0) or Oren-Nayar (roughness > 0)
  Glossy,   // Blender Glossy BSDF, GGX, Beckmann or Ashikhmin-Shirley (no Fresnel; colour scales),
            // alpha = r^2
  Glass,    // Blender Glass BSDF, GGX, Beckmann or Multiscatter GGX dielectric; roughness 0 =
            // smooth (delta)
  Principled,   // Blender 3.4 Principled BSDF v1
  Emission,     // colour * strength (radiance, W/m^2/sr per unit strength as in Cycles)
  Transparent,  // straight-through transmission, colour scales
  Translucent,  // Blender Translucent BSDF: Lambertian transmission (diffuse, to the far side)
  Refraction,   // Blender Refraction BSDF: the Glass BSDF's refraction alone, no Fresnel
  Velvet,       // Blender Velvet BSDF: Ashikhmin velvet, sigma = saturated roughness (Sigma)
  // Blender Anisotropic BSDF (GGX, Beckmann, Ashikhmin-Shirley or Multiscatter GGX): alpha =
  // r^2 scaled by (1 - anisotropy) along the tangent and divided by it across (the reverse for
  // negative anisotropy, clamped to +-0.99), the tangent turned by Rotation * 2 pi about the
  // normal (Cycles 3.4's svm anisotropic closure).
  Anisotropic,
  Mix,  // (1 - fac) * a + fac * b
  Add,  // a + b
};

// The tangent an anisotropic lobe reads (Anisotropic BSDF / Principled Tangent inputs). Radial:
// Blender's Tangent node, Radial, about an object axis: the direction around that axis through
// the generated coordinates (object space, centred on 0.5), taken to world space as a normal is
// (Cycles' svm_node_tangent); an unlinked input is the Geometry node's Tangent, Radial about Z.
// UVMap: the mesh's MikkTSpace tangent of its UV map (Mesh::corner_tangents). Vector: another
// node's world-space vector.
struct TangentInput {
  enum class Source : uint8_t { Radial, UVMap, Vector } source = Source::Radial;
  uint8_t axis = 2;  // Radial: 0 X, 1 Y, 2 Z
  ColorInput vector{Spectrum(0.0f)};
};

struct ShaderNode {
  ShaderNodeKind kind = ShaderNodeKind::Diffuse;
  ColorInput color;       // base colour for every BSDF, emission colour for Emission
  FloatInput roughness;   // Diffuse, Glossy, Glass, Principled
  FloatInput ior{1.45f};  // Glass, Principled
  MicrofacetDistribution distribution =
      MicrofacetDistribution::GGX;  // Glossy, Glass, Refraction, Anisotropic, Principled
  FloatInput strength{1.0f};        // Emission
  FloatInput fac{0.5f};             // Mix
  // Mix / Add children (indices into Material::nodes); -1: an unlinked shader input, no closure
  // (black, as Cycles).
  int32_t a = -1, b = -1;
  // Whether the BSDF's Normal input (Principled: also its Clearcoat Normal) takes the material's
  // normal map or bump; false: the interpolated normal, which Cycles gives an unlinked input.
  bool normal_linked = true;
  bool clearcoat_normal_linked = true;

  // Principled BSDF v1 inputs beyond colour / roughness / ior.
  FloatInput metallic{0.0f};
  FloatInput specular{0.5f};
  FloatInput specular_tint{0.0f};
  FloatInput transmission{0.0f};
  FloatInput sheen{0.0f};
  FloatInput sheen_tint{0.5f};
  // Clearcoat (Cycles 3.4, shaders/bsdf_clearcoat.h): weight 0.25 clearcoat, on top of the
  // other lobes.
  FloatInput clearcoat{0.0f};
  FloatInput clearcoat_roughness{0.03f};
  FloatInput alpha{1.0f};
  // Anisotropic BSDF (Anisotropy, Rotation, Tangent), Principled (Anisotropic, Anisotropic
  // Rotation, Tangent).
  FloatInput anisotropy{0.0f};
  FloatInput rotation{0.0f};
  TangentInput tangent;
  ColorInput emission{Spectrum(0.0f)};
  FloatInput emission_strength{1.0f};
  // Subsurface weight and colour: the diffuse Cycles falls back to for a radius below its
  // minimum (shaders/principled.h); a larger radius renders the same (the add-on reports it).
  FloatInput subsurface{0.0f};
  ColorInput subsurface_color{Spectrum(0.8f)};
};

// Blender's Normal Map node in tangent space, feeding the material's BSDF Normal inputs: the
// colour c, read as the tangent-space direction 2 (c - 0.5) (x along the UV map's tangent, y along
// the bitangent, z along the interpolated normal), replaces the shading normal. Strength s scales
// x and y by s and moves z from 1 to its value by clamp(s, 0, 1), as Cycles (svm_node_normal_map).
struct NormalMapDesc {
  bool enabled = false;
  ColorInput color{Spectrum(0.5f, 0.5f, 1.0f)};  // non-colour data: used as stored
  float strength = 1.0f;
};

// Blender's Bump node on the material's BSDF Normal inputs: the shading normal tilts against the
// surface gradient of `height`, N' = normalize(N - distance grad h) (Cycles' svm_node_set_bump to
// first order in its ray differentials; the gradient here is a forward difference in UV), then
// mixed with N by strength. Invert negates the distance.
// The Material Output's Displacement rendered as Cycles' "Bump Only" (its default method) is the
// same tilt, of height (Height - Midlevel) Scale with distance and strength 1, except that it
// replaces the surface's own normal (replaces_normal: Cycles' set_normal writes sd->N), so no
// bump shadowing follows and every lobe and Geometry Normal reads it. The gradient is taken in
// world units, where Cycles takes an object-space displacement's in object units: the two agree
// for objects of unit scale only.
// A Vector Displacement node on the Displacement output (vector_space not None) gives the height
// from `vector`, its (Vector - Midlevel) Scale in that space: the height is the displacement's
// component along the interpolated normal, as Cycles' bump_from_displacement dots the
// displacement with the normal. The frame that takes the vector to world space (tangent: x along
// the UV map's tangent, y along the normal, z along the bitangent; object: the object's transform)
// is the shading point's for every sample of the gradient, as Cycles evaluates the node's frame
// at the centre only.
// A Bump node whose Normal input is another Bump (or a Normal Map) tilts that node's normal: the
// gradient is taken in the plane normal to it (Cycles' surface gradient against its N).
struct BumpDesc {
  FloatInput height{0.0f};
  float strength = 1.0f;
  float distance = 1.0f;
  bool invert = false;
  bool replaces_normal = false;
  enum class VectorSpace : uint8_t {
    None,
    Tangent,
    Object,
    World
  } vector_space = VectorSpace::None;
  ColorInput vector{Spectrum(0.0f)};  // with vector_space: replaces height
};

struct MaterialDesc {
  std::string name;
  std::vector<ShaderNode> nodes;
  int32_t root = -1;         // -1: Blender's default grey diffuse (0.8)
  NormalMapDesc normal_map;  // needs the meshes' corner tangents (Mesh::corner_tangents)
  // The normal's chain, in Cycles' order: a bump that replaces the normal (the displacement) comes
  // first, then the normal map, then the other bumps, each tilting the normal the one before gave.
  std::vector<BumpDesc> bumps;
  std::vector<InputNode> inputs;  // referenced by ColorInput::node / FloatInput::node
  float pass_index = 0.0f;        // Blender's Material > Settings > Pass Index (the IndexMA pass)
};

// Image pixels in scene-linear RGBA float (the loader converts from the file's colour space via
// OCIO).
struct ImageDesc {
  std::string name;
  int width = 0, height = 0;
  std::vector<float> rgba;  // width * height * 4, row 0 at the bottom (Blender's convention)
  // RGB holds sRGB-encoded values (an 8-bit sRGB image): lookups interpolate them encoded and
  // decode the result with the sRGB curve, as Cycles does for such images (it keeps them as
  // bytes and linearises after interpolation). Alpha is linear either way.
  bool srgb_encoded = false;
};

}  // namespace gdpt

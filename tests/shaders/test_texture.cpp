// Image texture lookups against hand-computed values: pixel centres at (i + 0.5) / w, v = 0 at
// the bottom row, closest / bilinear, repeat / extend / clip.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "shaders/texture.h"

namespace gdpt {
namespace {

// 2x2 image, row 0 at the bottom: A B (bottom), C D (top). Alpha = 0.1, 0.2, 0.3, 0.4.
const Spectrum A(1, 0, 0), B(0, 1, 0), C(0, 0, 1), D(1, 1, 1);

Texture make_texture() {
  ImageDesc img;
  img.name = "quad";
  img.width = 2;
  img.height = 2;
  img.rgba = {1, 0, 0, 0.1f, 0, 1, 0, 0.2f, 0, 0, 1, 0.3f, 1, 1, 1, 0.4f};
  return Texture(img);
}

using I = TextureLookup::Interpolation;
using E = TextureLookup::Extension;

void expect_rgba(const Rgba& got, Spectrum rgb, float a) {
  EXPECT_NEAR(got.rgb.x, rgb.x, 1e-6f);
  EXPECT_NEAR(got.rgb.y, rgb.y, 1e-6f);
  EXPECT_NEAR(got.rgb.z, rgb.z, 1e-6f);
  EXPECT_NEAR(got.a, a, 1e-6f);
}

TEST(Texture, ClosestPicksThePixelContainingUv) {
  const Texture t = make_texture();
  expect_rgba(t.lookup({0.25f, 0.25f}, I::Closest, E::Repeat), A, 0.1f);
  expect_rgba(t.lookup({0.75f, 0.25f}, I::Closest, E::Repeat), B, 0.2f);
  expect_rgba(t.lookup({0.25f, 0.75f}, I::Closest, E::Repeat), C, 0.3f);  // v up = top row
  expect_rgba(t.lookup({0.99f, 0.99f}, I::Closest, E::Repeat), D, 0.4f);
  expect_rgba(t.lookup({1.25f, -0.75f}, I::Closest, E::Repeat), A, 0.1f);  // wraps
  expect_rgba(t.lookup({1.0f, 1.0f}, I::Closest, E::Clip), D, 0.4f);       // edge is inside
  expect_rgba(t.lookup({1.5f, 0.25f}, I::Closest, E::Extend), B, 0.2f);
}

TEST(Texture, BilinearIsExactAtCentresAndBlendsBetween) {
  const Texture t = make_texture();
  expect_rgba(t.lookup({0.25f, 0.25f}, I::Linear, E::Repeat), A, 0.1f);
  expect_rgba(t.lookup({0.75f, 0.75f}, I::Linear, E::Repeat), D, 0.4f);
  expect_rgba(t.lookup({0.5f, 0.25f}, I::Linear, E::Repeat), (A + B) * 0.5f, 0.15f);
  expect_rgba(t.lookup({0.5f, 0.5f}, I::Linear, E::Repeat), (A + B + C + D) * 0.25f, 0.25f);
  // 1/4 of the way from A's centre to B's centre.
  expect_rgba(t.lookup({0.375f, 0.25f}, I::Linear, E::Extend), A * 0.75f + B * 0.25f, 0.125f);
}

TEST(Texture, ExtensionModesAtTheBorder) {
  const Texture t = make_texture();
  // u = 0: halfway between pixel -1 and pixel 0.
  expect_rgba(t.lookup({0.0f, 0.25f}, I::Linear, E::Repeat), (A + B) * 0.5f, 0.15f);  // -1 -> B
  expect_rgba(t.lookup({0.0f, 0.25f}, I::Linear, E::Extend), A, 0.1f);
  expect_rgba(t.lookup({0.0f, 0.25f}, I::Linear, E::Clip), A * 0.5f, 0.05f);        // blends to 0
  expect_rgba(t.lookup({1.3f, 0.5f}, I::Linear, E::Clip), Spectrum(0.0f), 0.0f);    // > 0.5 px out
  expect_rgba(t.lookup({1.2f, 0.5f}, I::Linear, E::Clip), (B + D) * 0.05f, 0.03f);  // 0.4 px out
  // Half a pixel outside: still a quarter of the border pixel's centre away (Cycles 3.4).
  expect_rgba(t.lookup({-0.125f, 0.25f}, I::Linear, E::Clip), A * 0.25f, 0.025f);
  expect_rgba(t.lookup({-0.01f, 0.5f}, I::Closest, E::Clip), Spectrum(0.0f), 0.0f);
  expect_rgba(t.lookup({1.25f, 0.25f}, I::Linear, E::Repeat), A, 0.1f);
  expect_rgba(t.lookup({-0.75f, 0.25f}, I::Linear, E::Repeat), A, 0.1f);
  expect_rgba(t.lookup({-3.0f, 5.0f}, I::Linear, E::Extend), C, 0.3f);  // left, top
  expect_rgba(t.lookup({1e9f, 0.25f}, I::Linear, E::Repeat), (A + B) * 0.5f, 0.15f);
  // u - floor(u) rounds to 1 exactly: the last pixel blends with the first, wrapped by compare.
  expect_rgba(t.lookup({-1e-9f, 0.25f}, I::Linear, E::Repeat), (A + B) * 0.5f, 0.15f);
  const Rgba at_zero = t.lookup({0.25f, 0.0f}, I::Linear, E::Repeat);
  expect_rgba(t.lookup({0.25f, -1e-9f}, I::Linear, E::Repeat), at_zero.rgb, at_zero.a);
}

TEST(Texture, MissingImageIsMagentaAndBadSizesThrow) {
  const Texture empty{ImageDesc{}};
  expect_rgba(empty.lookup({0.3f, 0.3f}, I::Linear, E::Repeat), Spectrum(1, 0, 1), 1.0f);
  ImageDesc bad;
  bad.name = "bad";
  bad.width = 2;
  bad.height = 2;
  bad.rgba.resize(12);
  EXPECT_THROW(Texture{bad}, std::invalid_argument);
}

// An 8-bit image decoded to linear (any per-channel function of the byte: here the square)
// is stored as 8-bit codes; the same image with one extra value in one channel (257 distinct)
// falls back to floats. Lookups away from that texel are bit-identical between the two.
TEST(Texture, EightBitImagesAreCodedAndLookUpTheSameValues) {
  const int n = 64;
  ImageDesc img;
  img.name = "bytes";
  img.width = img.height = n;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const auto byte = [](int v) { return float(v & 255) / 255.0f; };
      const float r = byte(x * 4 + y), g = byte(x * 4 + 3 * y), b = byte(255 - x);
      img.rgba.insert(img.rgba.end(), {r * r, g * g, b * b, byte(x + 3 * y)});
    }
  img.rgba[2] = -0.0f;  // a value's bits are its identity: -0 gets its own code
  const Texture coded(img);
  EXPECT_TRUE(coded.coded());
  ImageDesc floats = img;
  // Green takes all 256 byte values; a 257th in the top-right texel.
  floats.rgba[(size_t(n) * n - 1) * 4 + 1] = 0.123456f;
  const Texture plain(floats);
  EXPECT_FALSE(plain.coded());
  uint32_t rng = 12345;
  auto next = [&] {
    rng = rng * 1664525u + 1013904223u;
    return float(rng >> 8) * 0x1p-24f;
  };
  for (int i = 0; i < 2000; ++i) {
    const Vec2f uv(next() * 0.9f, next() * 0.9f);  // away from the altered texel
    for (I interp : {I::Linear, I::Closest})
      for (E ext : {E::Repeat, E::Extend, E::Clip}) {
        const Rgba a = coded.lookup(uv, interp, ext), b = plain.lookup(uv, interp, ext);
        ASSERT_EQ(a.rgb.x, b.rgb.x);
        ASSERT_EQ(a.rgb.y, b.rgb.y);
        ASSERT_EQ(a.rgb.z, b.rgb.z);
        ASSERT_EQ(a.a, b.a);
      }
  }
  EXPECT_TRUE(std::signbit(coded.lookup({0.5f / n, 0.5f / n}, I::Closest, E::Repeat).rgb.z));
  // The mean is over the stored values, whichever the storage.
  EXPECT_NEAR(coded.mean().rgb.x, plain.mean().rgb.x, 1e-7f);
  EXPECT_NEAR(coded.mean().a, plain.mean().a, 1e-7f);
}

// The exact sRGB curve (IEC 61966-2-1), in double.
double srgb_exact(double c) {
  return c < 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

TEST(Texture, SrgbCurveTableMatchesTheExactCurve) {
  double worst = 0.0;
  for (int i = 0; i <= 100000; ++i) {
    const double c = i / 100000.0;
    worst = std::max(worst, std::fabs(double(srgb_to_linear(float(c))) - srgb_exact(c)));
  }
  EXPECT_LT(worst, 2e-7);
}

// 8-bit sRGB images (ImageDesc::srgb_encoded) interpolate the encoded values and decode the
// result, as Cycles does: between two pixels the value is decode(mean of codes), not the mean
// of the decoded values. Pixel centres, Closest and the mean decode per pixel; alpha is linear.
TEST(Texture, SrgbEncodedImagesInterpolateBeforeDecoding) {
  ImageDesc img;
  img.name = "srgb";
  img.width = 2;
  img.height = 1;
  const float a = 51.0f / 255.0f, b = 204.0f / 255.0f;  // 8-bit codes 51 and 204
  img.rgba = {a, a, a, 0.2f, b, b, b, 0.6f};
  img.srgb_encoded = true;
  const Texture t(img);
  EXPECT_TRUE(t.coded());
  const float da = float(srgb_exact(a)), db = float(srgb_exact(b));
  expect_rgba(t.lookup({0.25f, 0.5f}, I::Linear, E::Extend), Spectrum(da), 0.2f);
  expect_rgba(t.lookup({0.75f, 0.5f}, I::Closest, E::Extend), Spectrum(db), 0.6f);
  const float mid = float(srgb_exact(0.5 * (double(a) + double(b))));
  expect_rgba(t.lookup({0.5f, 0.5f}, I::Linear, E::Extend), Spectrum(mid), 0.4f);
  EXPECT_GT(std::fabs(mid - 0.5f * (da + db)), 0.05f);  // the order matters here
  expect_rgba(t.mean(), Spectrum(0.5f * (da + db)), 0.4f);
}

}  // namespace
}  // namespace gdpt

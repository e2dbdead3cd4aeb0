// Scale and placement: the Cornell box scaled by 1e-4 and 1e4, and translated 1e4 away from the
// origin together with its camera, renders like the original.
//
// Expectation: radiance does not depend on the unit of length, so each variant is the same image.
// With the same seed every variant draws the same random numbers, so their paths differ only by
// float rounding of the geometry (and, where that flips a decision, by a whole path): the relMSE
// against the original is far below the noise of either image (each is ~0.05 from the converged
// image at 32 spp). Acne shows as a darker image (self-shadowing), leaks as light in contact shadows
// (brighter), holes as black pixels: mean luminance must agree and no pixel may turn black.
//
// Measured (64x64, 32 spp, seed 7, Release) with error-bound ray offsets: scale 1e4: relMSE 1.3e-12,
// mean ratio 1.000000, no black pixel. Scale 1e-4: relMSE 3.7e-13, 1.000000, none. Translate 1e3:
// 3.75e-3, 0.99880, none. Translate 1e4 needs its own expectation (see there).
#include "hardcases/hardcase_support.h"
#include "test_support.h"

#include <cstdio>

namespace tessera {
namespace {

constexpr int kSize = 64, kSpp = 32;

std::string cornell_path() { return test::shared_path("scenes/cornell-box/scene.xml"); }

Image render_variant(const Transform& world, const std::string& name) {
  LoadResult r = test::load_cornell(cornell_path(), world, kSize, kSpp);
  EXPECT_TRUE(r.unsupported.empty()) << name;
  return test::render_checked(*r.scene, test::hard_settings(kSpp), name).to_image();
}

const Image& original() {
  static const Image img = render_variant(Transform(), "original");
  return img;
}

/// `max_rel_mse`: the bound on the relMSE against the untransformed render (same seed).
void expect_like_original(const Transform& world, const std::string& name, double max_rel_mse) {
  const Image& ref = original();
  const double mean0 = test::mean_luminance(ref), black0 = test::black_fraction(ref);
  ASSERT_GT(mean0, 0.05);
  ASSERT_EQ(black0, 0.0) << "the original shows no black pixel at this resolution";
  const Image img = render_variant(world, name);
  const double err = rel_mse(img, ref), ratio = test::mean_luminance(img) / mean0;
  const double black = test::black_fraction(img);
  std::printf("%-14s relMSE vs original %.3g, mean ratio %.6f, black pixels %.0f\n", name.c_str(), err, ratio,
              black * kSize * kSize);
  EXPECT_LT(err, max_rel_mse) << name;
  EXPECT_NEAR(ratio, 1.0, 2e-3) << name << ": acne (darker) or leaks (brighter)";
  EXPECT_EQ(black, 0.0) << name << ": holes";
}

// 1e4 is not a power of two, so every vertex rounds differently, but relatively: the same paths
// up to ~1 ulp. Measured 1.0e-6; bound 1e-4 (100x margin, still 500x below the noise level).
TEST(HardScale, CornellBoxScaledBy1e4) {
  TESSERA_REQUIRE_FILE(cornell_path());
  expect_like_original(Transform::scale(Vec3(1e4f)), "scale 1e4", 1e-4);
}

// Fixed by error-bound offsets (render/interaction.cpp): measured relMSE 3.7e-13, mean ratio
// 1.000000, no black pixel (the fixed 1/65536 offset below |p| < 1/32 measured 6.5e-3, +1.4%, 2).
TEST(HardScale, CornellBoxScaledBy1eMinus4) {
  TESSERA_REQUIRE_FILE(cornell_path());
  expect_like_original(Transform::scale(Vec3(1e-4f)), "scale 1e-4", 1e-4);
}

// At 1e4 from the origin floats are 2^-10 ~ 1e-3 apart, 0.05% of the box: every vertex and hit point
// rounds, and a hit point's error bound is ~6e-3 per axis, so spawned rays start ~7e-3 off their
// surface (0.35% of the box). Same-seed paths then decorrelate far more than at 1e3: at 32 spp the
// image differs from the original by relMSE 4.0e-3, its mean by +0.58%, and one pixel of the short
// block's indirectly lit front face (0.0028 in the original, lit by a handful of the 32 paths) got
// none of them. At 256 spp that pixel is 0.0040 in the original and 0.0044 here, and the mean ratio
// is 1.0019: noise of decorrelated paths, not a defect. (Nor can camera rays be compared one by one:
// the box's front edges lie on the image border, and ~5% of the rays graze them, hitting the edge in
// one placement and passing 1e-4 beside it in the other.) So this case renders both at 256 spp:
// - holes: no black pixel (the original has none);
// - acne (darker) and leaks (brighter): the mean within 0.5% (measured +0.20%, of which ~0.12% is the
//   light's vertices rounding to a larger area);
// - relMSE against the original below 2e-3 (measured 5.2e-4; independent 256-spp renders would differ
//   by about 1e-2, scaling the ~0.05 of each 32-spp image from the converged one above).
TEST(HardScale, CornellBoxTranslated1e4WithItsCamera) {
  TESSERA_REQUIRE_FILE(cornell_path());
  constexpr int kConvergedSpp = 256;
  LoadResult moved = test::load_cornell(cornell_path(), Transform::translate(Vec3(1e4f)), kSize, kConvergedSpp);
  LoadResult orig = test::load_cornell(cornell_path(), Transform(), kSize, kConvergedSpp);
  ASSERT_TRUE(moved.unsupported.empty() && orig.unsupported.empty());

  const Image ref = test::render_checked(*orig.scene, test::hard_settings(kConvergedSpp), "original").to_image();
  const Image img = test::render_checked(*moved.scene, test::hard_settings(kConvergedSpp), "1e4").to_image();
  const double err = rel_mse(img, ref), ratio = test::mean_luminance(img) / test::mean_luminance(ref);
  const double black = test::black_fraction(img);
  std::printf("translate 1e4  %d spp: relMSE vs original %.3g, mean ratio %.6f, black pixels %.0f\n",
              kConvergedSpp, err, ratio, black * kSize * kSize);
  EXPECT_EQ(test::black_fraction(ref), 0.0);
  EXPECT_LT(err, 2e-3);
  EXPECT_NEAR(ratio, 1.0, 5e-3) << "acne (darker) or leaks (brighter)";
  EXPECT_EQ(black, 0.0) << "holes";
}

// With the fixed 256-ulp offsets this failed at 1e3 too (relMSE 4.3e-3, 1.3% darker, 1 black pixel:
// 256 ulps are 0.016..0.03 there, more than the 0.02 the light hangs below the ceiling). With
// error-bound offsets: measured relMSE 3.75e-3, mean ratio 0.99880, no black pixel.
TEST(HardScale, CornellBoxTranslated1e3WithItsCamera) {
  TESSERA_REQUIRE_FILE(cornell_path());
  expect_like_original(Transform::translate(Vec3(1e3f, 1e3f, 1e3f)), "translate 1e3", 1e-2);
}

// At 1e2 (ulp 7.6e-6 .. 1.5e-5, 256 ulps <= 4e-3 world units, 1/5 of the light's gap to the
// ceiling) the offsets are still small against every feature of the box. Translation rounds every
// vertex and hit point in absolute terms, so long paths decorrelate more than under scaling:
// measured relMSE 3.7e-3, mean ratio 0.99933. Bound 1e-2 (still ~10x below the relMSE of two
// independent 32-spp renders), the mean within 0.2% and no black pixel carry the bias check.
TEST(HardScale, CornellBoxTranslated1e2WithItsCamera) {
  TESSERA_REQUIRE_FILE(cornell_path());
  expect_like_original(Transform::translate(Vec3(1e2f, 1e2f, 1e2f)), "translate 1e2", 1e-2);
}

}  // namespace
}  // namespace tessera

// AnimatedTransform: Mitsuba 0.6 interpolation (linear translation and stretch, slerped rotation,
// clamped outside the keyframes) and conservative motion bounds.
#include "tessera/core/animated_transform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace tessera {
namespace {

float dist(Vec3 a, Vec3 b) { return length(a - b); }

TEST(AnimatedTransform, TranslationIsLinearAndClamped) {
  AnimatedTransform a({{1.f, Transform::translate({0.f, 0.f, 0.f})}, {3.f, Transform::translate({4.f, -2.f, 6.f})}});
  EXPECT_FALSE(a.is_static());
  EXPECT_LT(dist(a.at(2.f).apply_point(Vec3(1.f)), Vec3(3.f, 0.f, 4.f)), 1e-6f);
  EXPECT_LT(dist(a.at(1.5f).apply_point(Vec3(0.f)), Vec3(1.f, -0.5f, 1.5f)), 1e-6f);
  // Outside the keyframes: clamped to the first / last.
  EXPECT_EQ(a.at(-5.f).apply_point(Vec3(1.f)), Vec3(1.f));
  EXPECT_EQ(a.at(7.f).apply_point(Vec3(0.f)), Vec3(4.f, -2.f, 6.f));
}

TEST(AnimatedTransform, RotationIsSlerped) {
  // 0 -> 90 degrees about z: half way is 45 degrees, not the (shrinking) matrix average.
  AnimatedTransform a({{0.f, Transform()}, {1.f, Transform::rotate({0.f, 0.f, 1.f}, 90.f)}});
  const float s = std::sqrt(0.5f);
  EXPECT_LT(dist(a.at(0.5f).apply_point({1.f, 0.f, 0.f}), Vec3(s, s, 0.f)), 1e-6f);
  const float c30 = std::cos(kPi / 6), s30 = std::sin(kPi / 6);
  EXPECT_LT(dist(a.at(1.f / 3.f).apply_point({2.f, 0.f, 0.f}), Vec3(2 * c30, 2 * s30, 0.f)), 1e-5f);
  // The short way round: -170 -> 170 degrees passes through 180, not through 0.
  AnimatedTransform b({{0.f, Transform::rotate({0.f, 0.f, 1.f}, -170.f)}, {1.f, Transform::rotate({0.f, 0.f, 1.f}, 170.f)}});
  EXPECT_LT(dist(b.at(0.5f).apply_point({1.f, 0.f, 0.f}), Vec3(-1.f, 0.f, 0.f)), 1e-5f);
}

TEST(AnimatedTransform, ScaleRotationTranslationTogether) {
  const Transform k0 = Transform::translate({1.f, 2.f, 3.f}) * Transform::scale({1.f, 2.f, 3.f});
  const Transform k1 = Transform::translate({3.f, 2.f, 1.f}) * Transform::rotate({1.f, 0.f, 0.f}, 60.f) *
                       Transform::scale({3.f, 2.f, 1.f});
  AnimatedTransform a({{0.f, k0}, {2.f, k1}});
  const Transform expected = Transform::translate({2.f, 2.f, 2.f}) * Transform::rotate({1.f, 0.f, 0.f}, 30.f) *
                             Transform::scale({2.f, 2.f, 2.f});
  const Transform got = a.at(1.f);
  for (Vec3 p : {Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), Vec3(0.3f, -0.7f, 0.9f)})
    EXPECT_LT(dist(got.apply_point(p), expected.apply_point(p)), 1e-5f);
  // Keyframe times give the keyframe matrices exactly.
  EXPECT_EQ(a.at(0.f).matrix(), k0.matrix());
  EXPECT_EQ(a.at(2.f).matrix(), k1.matrix());
  // A mirror in every keyframe stays a mirror in between (folded into the stretch).
  AnimatedTransform m({{0.f, Transform::scale({-1.f, 1.f, 1.f})}, {1.f, Transform::scale({-3.f, 1.f, 1.f})}});
  EXPECT_TRUE(m.at(0.5f).swaps_handedness());
  EXPECT_LT(dist(m.at(0.5f).apply_point({1.f, 1.f, 1.f}), Vec3(-2.f, 1.f, 1.f)), 1e-6f);
}

TEST(AnimatedTransform, ThreeKeyframesAndStaticDetection) {
  AnimatedTransform a({{0.f, Transform::translate({0.f, 0.f, 0.f})},
                       {1.f, Transform::translate({1.f, 0.f, 0.f})},
                       {3.f, Transform::translate({1.f, 4.f, 0.f})}});
  EXPECT_LT(dist(a.at(0.5f).apply_point(Vec3(0.f)), Vec3(0.5f, 0.f, 0.f)), 1e-6f);
  EXPECT_LT(dist(a.at(2.f).apply_point(Vec3(0.f)), Vec3(1.f, 2.f, 0.f)), 1e-6f);
  const Transform t = Transform::rotate({0.f, 1.f, 0.f}, 33.f);
  AnimatedTransform s({{0.f, t}, {1.f, t}, {2.f, t}});
  EXPECT_TRUE(s.is_static());
  EXPECT_EQ(s.at(1.3f).matrix(), t.matrix());
  EXPECT_TRUE(AnimatedTransform(t).is_static());
}

TEST(AnimatedTransform, ComposedAppliesFixedFactorsOnEitherSide) {
  AnimatedTransform a({{0.f, Transform()}, {1.f, Transform::rotate({0.f, 0.f, 1.f}, 90.f)}});
  const Transform pre = Transform::translate({5.f, 0.f, 0.f}), post = Transform::scale(Vec3(2.f));
  AnimatedTransform c = a.composed(pre, post);
  for (float t : {0.f, 0.25f, 0.5f, 1.f}) {
    const Transform expected = pre * a.at(t) * post;
    for (Vec3 p : {Vec3(1.f, 0.f, 0.f), Vec3(0.2f, 0.3f, -0.4f)})
      EXPECT_LT(dist(c.at(t).apply_point(p), expected.apply_point(p)), 1e-5f) << t;
  }
}

// The motion bounds hold the moving box at every time of the interval (and nothing absurd).
TEST(AnimatedTransform, MotionBoundsContainTheShapeAtAllTimes) {
  const Transform k0 = Transform::translate({-2.f, 0.f, 1.f});
  const Transform k1 = Transform::translate({1.f, 1.f, 0.f}) * Transform::rotate(normalize(Vec3(1.f, 2.f, 3.f)), 170.f) *
                       Transform::scale({1.5f, 0.5f, 1.f});
  const Transform k2 = Transform::translate({3.f, -1.f, 0.f}) * Transform::rotate({0.f, 0.f, 1.f}, -90.f);
  AnimatedTransform a({{0.f, k0}, {1.f, k1}, {2.f, k2}});
  Bounds3 object;
  object.extend(Vec3(-0.5f, -1.f, -0.25f));
  object.extend(Vec3(0.5f, 1.f, 0.25f));
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (auto [t0, t1] : {std::pair{0.f, 2.f}, std::pair{0.3f, 1.4f}, std::pair{-1.f, 0.5f}}) {
    const Bounds3 b = a.motion_bounds(object, t0, t1);
    for (int i = 0; i <= 4000; ++i) {
      const float t = t0 + (t1 - t0) * float(i) / 4000.f;
      Vec3 p(object.lo.x + u(rng) * 1.f, object.lo.y + u(rng) * 2.f, object.lo.z + u(rng) * 0.5f);
      if (i % 8 == 0)  // corners too
        p = Vec3((i & 16) ? object.hi.x : object.lo.x, (i & 32) ? object.hi.y : object.lo.y, (i & 64) ? object.hi.z : object.lo.z);
      ASSERT_TRUE(b.contains(a.at(t).apply_point(p))) << "t=" << t;
    }
    // Not much larger than the exact sweep: within the sampled union padded by a step.
    Bounds3 swept;
    for (int i = 0; i <= 1000; ++i) swept.extend(a.at(t0 + (t1 - t0) * float(i) / 1000.f).apply(object));
    EXPECT_LT(max_component(b.diagonal() - swept.diagonal()), 0.3f);
  }
  // Pure translation is exact up to padding.
  AnimatedTransform slide({{0.f, Transform()}, {1.f, Transform::translate({4.f, 0.f, 0.f})}});
  const Bounds3 s = slide.motion_bounds(object, 0.f, 1.f);
  EXPECT_NEAR(s.lo.x, -0.5f, 0.1f);
  EXPECT_NEAR(s.hi.x, 4.5f, 0.1f);
  EXPECT_NEAR(s.hi.y, 1.f, 0.1f);
}

}  // namespace
}  // namespace tessera

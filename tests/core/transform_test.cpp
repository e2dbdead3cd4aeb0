#include "tessera/core/transform.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

void expect_near(Vec3 a, Vec3 b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

TEST(Transform, InverseOfGeneralMatrix) {
  Matrix4 m = Matrix4::from_row_major({2, 1, 0, 3, 0, 1, 4, -1, 1, 0, 3, 2, 0, 0, 0, 1});
  auto t = Transform::from_matrix(m);
  ASSERT_TRUE(t.has_value());
  Vec3 p(0.3f, -1.2f, 5.f);
  expect_near(t->inverse().apply_point(t->apply_point(p)), p, 1e-4f);
}

TEST(Transform, SingularMatrixHasNoInverse) {
  Matrix4 m = Matrix4::from_row_major({1, 2, 3, 0, 2, 4, 6, 0, 0, 0, 1, 0, 0, 0, 0, 1});
  EXPECT_FALSE(Transform::from_matrix(m).has_value());
}

TEST(Transform, RotateIsRightHanded) {
  // 90 degrees about z takes +x to +y.
  expect_near(Transform::rotate(Vec3(0, 0, 1), 90.f).apply_vector(Vec3(1, 0, 0)), Vec3(0, 1, 0));
  expect_near(Transform::rotate(Vec3(1, 0, 0), 90.f).apply_vector(Vec3(0, 1, 0)), Vec3(0, 0, 1));
}

TEST(Transform, NormalsStayPerpendicularUnderNonUniformScale) {
  Transform t = Transform::scale(Vec3(4.f, 1.f, 1.f)) * Transform::rotate(Vec3(0, 0, 1), 30.f);
  Vec3 tangent = normalize(Vec3(1, -1, 0));
  Vec3 normal = normalize(Vec3(1, 1, 0));
  Vec3 tt = t.apply_vector(tangent);
  Vec3 nn = normalize(t.apply_normal(normal));
  EXPECT_NEAR(dot(tt, nn), 0.f, 1e-5f);
}

TEST(Transform, LookAtMatchesMitsuba) {
  // Mitsuba: the camera looks down +z of its to_world; lookat puts +z towards the target.
  auto t = Transform::look_at(Vec3(0, 0, 5), Vec3(0, 0, 0), Vec3(0, 1, 0));
  ASSERT_TRUE(t.has_value());
  expect_near(t->apply_point(Vec3(0, 0, 0)), Vec3(0, 0, 5));
  expect_near(t->apply_vector(Vec3(0, 0, 1)), Vec3(0, 0, -1));
  expect_near(t->apply_vector(Vec3(0, 1, 0)), Vec3(0, 1, 0));
  // left = up x dir: camera +x is world -x here.
  expect_near(t->apply_vector(Vec3(1, 0, 0)), Vec3(-1, 0, 0));
  EXPECT_FALSE(Transform::look_at(Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(0, 1, 0)).has_value());
}

TEST(Transform, CompositionAppliesRightFirst) {
  Transform t = Transform::translate(Vec3(1, 0, 0)) * Transform::scale(Vec3(2.f));
  expect_near(t.apply_point(Vec3(1, 1, 1)), Vec3(3, 2, 2));
  EXPECT_FALSE(t.swaps_handedness());
  EXPECT_TRUE(Transform::scale(Vec3(-1, 1, 1)).swaps_handedness());
}

}  // namespace
}  // namespace tessera

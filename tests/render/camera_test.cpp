#include "tessera/core/transform.h"
#include "tessera/render/camera.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

TEST(PerspectiveCamera, CentreAndEdgesIdentity) {
  // fov_x 90 on a 200x100 film: half-width tan 45 = 1, half-height 1/2.
  auto cam = make_perspective_camera(Transform(), 90.f, 200, 100, 0.01f, 1000.f);
  Ray c = cam->generate_ray({100.f, 50.f}, {0.5f, 0.5f});
  EXPECT_NEAR(c.d.x, 0.f, 1e-6f);
  EXPECT_NEAR(c.d.y, 0.f, 1e-6f);
  EXPECT_NEAR(c.d.z, 1.f, 1e-6f);
  EXPECT_EQ(c.o, Vec3(0.f));

  // Mitsuba mirrors x: camera +x is on the LEFT of the image; +y is up.
  Ray left = cam->generate_ray({0.f, 50.f}, {});
  EXPECT_NEAR(left.d.x / left.d.z, 1.f, 1e-5f);
  Ray right = cam->generate_ray({200.f, 50.f}, {});
  EXPECT_NEAR(right.d.x / right.d.z, -1.f, 1e-5f);
  Ray top = cam->generate_ray({100.f, 0.f}, {});
  EXPECT_NEAR(top.d.y / top.d.z, 0.5f, 1e-5f);
  Ray bottom = cam->generate_ray({100.f, 100.f}, {});
  EXPECT_NEAR(bottom.d.y / bottom.d.z, -0.5f, 1e-5f);

  // Unit directions, starting on the near plane, ending on the far plane.
  for (Ray r : {c, left, right, top, bottom}) {
    EXPECT_NEAR(length(r.d), 1.f, 1e-6f);
    EXPECT_NEAR(r.tmin * r.d.z, 0.01f, 1e-6f);
    EXPECT_NEAR(r.tmax * r.d.z, 1000.f, 1e-2f);
  }
}

// The Cornell box's sensor: to_world = diag(-1, 1, -1) + (0, 1, 6.8), fov 19.5. The red wall is at
// world x = -1 and must appear on the LEFT of the image (as in the reference render).
TEST(PerspectiveCamera, CornellBoxLeftIsWorldMinusX) {
  auto m = Matrix4::from_row_major({-1, 0, 0, 0, 0, 1, 0, 1, 0, 0, -1, 6.8, 0, 0, 0, 1});
  auto xf = Transform::from_matrix(m);
  ASSERT_TRUE(xf.has_value());
  auto cam = make_perspective_camera(*xf, 19.5f, 1024, 1024, 0.01f, 1e4f);
  Ray left = cam->generate_ray({1.f, 512.f}, {});
  Ray right = cam->generate_ray({1023.f, 512.f}, {});
  Ray top = cam->generate_ray({512.f, 1.f}, {});
  EXPECT_NEAR(left.o.z, 6.8f, 1e-6f);
  EXPECT_LT(left.d.z, 0.f);  // looking into the box
  // Where the rays cross the plane of the back wall (z = -1):
  auto x_at_back = [](const Ray& r) { return r.o.x + r.d.x * (-1.f - r.o.z) / r.d.z; };
  EXPECT_LT(x_at_back(left), -1.f + 0.2f);
  EXPECT_LT(x_at_back(left), 0.f);
  EXPECT_GT(x_at_back(right), 0.f);
  float y_top = top.o.y + top.d.y * (-1.f - top.o.z) / top.d.z;
  EXPECT_GT(y_top, 1.5f);
  // Horizontal fov 19.5 deg: at the image edge, the angle to the axis is 9.75 deg.
  EXPECT_NEAR(std::atan2(right.d.x, -right.d.z) * 180.0 / M_PI, 9.75 * (1023.0 - 512.0) / 512.0, 0.2);
}

}  // namespace
}  // namespace tessera

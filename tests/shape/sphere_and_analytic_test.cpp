#include "shape_test_util.h"

#include "tessera/core/hash.h"
#include "tessera/render/shape.h"

#include <cmath>

namespace tessera {
namespace {

Vec3 face_normal(const MeshData& m, size_t t) {
  Vec3 p0 = m.positions[m.indices[3 * t]], p1 = m.positions[m.indices[3 * t + 1]],
       p2 = m.positions[m.indices[3 * t + 2]];
  return normalize(cross(p1 - p0, p2 - p0));
}

TEST(AnalyticMeshes, RectangleMatchesMitsuba) {
  MeshData m = make_rectangle_mesh();
  EXPECT_NEAR(test::mesh_area(m), 4.0, 1e-6);
  for (size_t t = 0; t < m.num_triangles(); ++t) EXPECT_EQ(face_normal(m, t), Vec3(0, 0, 1));
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i) {
    EXPECT_EQ(m.positions[i].z, 0.f);
    EXPECT_EQ(m.uvs[i].x, 0.5f * (m.positions[i].x + 1.f));
    EXPECT_EQ(m.uvs[i].y, 0.5f * (m.positions[i].y + 1.f));
  }
  EXPECT_NO_THROW(validate_mesh(m, FileLoc{"rectangle", 0}));
}

TEST(AnalyticMeshes, CubeHas24VerticesAndOutwardFaces) {
  MeshData m = make_cube_mesh();
  EXPECT_EQ(m.positions.size(), 24u);
  EXPECT_EQ(m.num_triangles(), 12u);
  EXPECT_NEAR(test::mesh_area(m), 24.0, 1e-6);
  for (size_t t = 0; t < m.num_triangles(); ++t) {
    Vec3 n = face_normal(m, t);
    Vec3 c = (m.positions[m.indices[3 * t]] + m.positions[m.indices[3 * t + 1]] +
              m.positions[m.indices[3 * t + 2]]) / 3.f;
    EXPECT_GT(dot(n, c), 0.f) << "triangle " << t << " faces inwards";
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.normals[m.indices[3 * t + k]], n);
  }
  for (const Vec2& uv : m.uvs) {
    EXPECT_TRUE(uv.x == 0.f || uv.x == 1.f);
    EXPECT_TRUE(uv.y == 0.f || uv.y == 1.f);
  }
  EXPECT_NO_THROW(validate_mesh(m, FileLoc{"cube", 0}));
}

TEST(AnalyticMeshes, DiskHasAreaPiAndFacesUp) {
  MeshData m = make_disk_mesh();
  EXPECT_EQ(m.num_triangles(), size_t(kDiskSegments));
  EXPECT_NEAR(test::mesh_area(m), 3.14159265358979, 1e-5);
  float max_r = 0;
  for (const Vec3& p : m.positions) max_r = std::max(max_r, length(p));
  EXPECT_LT(max_r, 1.001f);
  EXPECT_GT(max_r, 1.f);
  for (size_t t = 0; t < m.num_triangles(); ++t) EXPECT_NEAR(face_normal(m, t).z, 1.f, 1e-6f);
  for (const Vec2& uv : m.uvs) {
    EXPECT_GE(uv.y, 0.f);
    EXPECT_LE(uv.y, 1.f);
  }
  EXPECT_NEAR(test::mesh_area(make_disk_mesh(8)), 3.14159265358979, 1e-5);
}

TEST(SphereShape, FillInteractionReprojectsAndFacesOutward) {
  SphereShape sphere(Vec3(1, 2, 3), 2.f, false);
  // A ray along -x hitting the +x pole at t = 7.
  Ray ray{Vec3(10, 2, 3), Vec3(-1, 0, 0)};
  Hit hit{7.f + 1e-4f, 0, 0, 0};  // slightly off: reprojection puts p back on the surface
  SurfaceInteraction si;
  sphere.fill_interaction(ray, hit, 0, si);
  EXPECT_NEAR(length(si.p - sphere.center()), 2.f, 1e-6f);
  EXPECT_NEAR(si.p.x, 3.f, 1e-6f);
  EXPECT_EQ(si.ng, Vec3(1, 0, 0));
  EXPECT_EQ(si.shading.n, si.ng);
  EXPECT_NEAR(si.uv.x, 0.f, 1e-6f);   // phi = 0
  EXPECT_NEAR(si.uv.y, 0.5f, 1e-6f);  // theta = pi/2
  EXPECT_EQ(si.wo, Vec3(1, 0, 0));
  EXPECT_EQ(si.shape, &sphere);

  SphereShape inside_out(Vec3(1, 2, 3), 2.f, true);
  inside_out.fill_interaction(ray, hit, 0, si);
  EXPECT_EQ(si.ng, Vec3(-1, 0, 0));

  // Top pole: theta = 0.
  Ray down{Vec3(1, 2, 10), Vec3(0, 0, -3)};
  sphere.fill_interaction(down, Hit{5.f / 3.f, 0, 0, 0}, 0, si);
  EXPECT_NEAR(si.uv.y, 0.f, 1e-3f);
  EXPECT_NEAR(si.ng.z, 1.f, 1e-6f);
  EXPECT_NEAR(length(si.wo), 1.f, 1e-6f);
}

TEST(SphereShape, SampleAreaIsOnTheSurfaceWithAreaPdf) {
  SphereShape sphere(Vec3(-1, 0, 2), 0.5f, false);
  EXPECT_FLOAT_EQ(sphere.area(), kPi);
  Bounds3 b = sphere.bounds();
  EXPECT_EQ(b.lo, Vec3(-1.5f, -0.5f, 1.5f));
  EXPECT_EQ(b.hi, Vec3(-0.5f, 0.5f, 2.5f));
  Pcg32 rng(5);
  Vec3 mean(0.f);
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    Vec3 p, nrm;
    float pdf;
    sphere.sample_area({rng.next_float(), rng.next_float()}, p, nrm, pdf);
    ASSERT_NEAR(length(p - sphere.center()), 0.5f, 1e-5f);
    ASSERT_NEAR(dot(nrm, (p - sphere.center()) * 2.f), 1.f, 1e-5f);
    ASSERT_FLOAT_EQ(pdf, 1.f / kPi);
    mean += nrm;
  }
  // Uniform directions average to zero (sd of each component: sqrt(1/3n)).
  EXPECT_LT(length(mean / float(n)), 5.f * std::sqrt(1.f / (3.f * n)) * std::sqrt(3.f));
}

}  // namespace
}  // namespace tessera

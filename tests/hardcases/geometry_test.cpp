// Degenerate geometry: coplanar overlapping triangles, slivers, zero-area triangles, NaN and huge
// vertices, zero-length and back-facing vertex normals.
//
// The analytic yardstick: a one-sided diffuse plane of albedo a facing the camera under a constant
// environment of radiance 1 has radiance exactly a (irradiance pi, times a / pi), and every pixel
// that misses it sees 1. Degenerate triangles must neither poison the BVH (a NaN bound would hide
// the plane) nor shade it (self-hits on a coplanar twin darken it: acne).
#include "hardcases/hardcase_support.h"
#include "render/scene_builders.h"
#include "tessera/light/constant.h"
#include "tessera/shape/mesh_io.h"
#include "test_support.h"

#include <limits>

namespace tessera {
namespace {

constexpr int kSize = 16, kSpp = 64;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

/// Appends the quad [-h, h]^2 at depth z, wound to face the camera at the origin (-z).
void add_quad(MeshData& m, float h, float z) {
  const uint32_t b = uint32_t(m.positions.size());
  m.positions.insert(m.positions.end(), {{-h, -h, z}, {-h, h, z}, {h, h, z}, {h, -h, z}});
  m.indices.insert(m.indices.end(), {b, b + 1, b + 2, b, b + 2, b + 3});
}
void add_triangle(MeshData& m, Vec3 a, Vec3 b, Vec3 c) {
  const uint32_t i = uint32_t(m.positions.size());
  m.positions.insert(m.positions.end(), {a, b, c});
  m.indices.insert(m.indices.end(), {i, i + 1, i + 2});
}

/// Renders `mesh` (albedo 0.5) in a constant environment of 1 from the origin looking along +z;
/// every pixel is expected at 0.5 (the plane covers the view; tan(22.5) * 3 < 2).
void expect_plane_at_half(std::shared_ptr<MeshData> mesh, const std::string& what) {
  Scene scene;
  const Bsdf* grey = test::add_diffuse(scene, Rgb(0.5f));
  scene.shapes.push_back(std::make_unique<TriangleMeshShape>(mesh, false, false));
  scene.shapes.back()->bsdf = grey;
  scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(1.f)));
  test::set_camera(scene, Vec3(0.f), 45.f, kSize, kSize);
  scene.finalize();
  const Film film = test::render_checked(scene, test::hard_settings(kSpp), what);
  double sum = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float v = film.mean({x, y}).g;
      // 64 cosine-weighted NEE+BSDF samples of a constant sky: per-pixel noise well below 0.05.
      EXPECT_NEAR(v, 0.5f, 0.05f) << what << " pixel " << x << "," << y;
      sum += v;
    }
  // Acne would darken the mean by the fraction of self-shadowed rays; leaks are impossible here.
  EXPECT_NEAR(sum / (kSize * kSize), 0.5, 0.005) << what;
}

// Expected: 0.5 everywhere. The control for the cases below.
TEST(HardGeometry, PlaneInConstantSkyIsItsAlbedo) {
  auto m = std::make_shared<MeshData>();
  add_quad(*m, 2.f, 3.f);
  expect_plane_at_half(m, "plane");
}

// Two coplanar copies of the plane, plus a third copy shifted by 1 ulp, plus one overlapping half of
// it (different triangulation). Expected: 0.5 everywhere, no acne (spawned rays start on the lit
// side of all copies at once).
TEST(HardGeometry, CoplanarOverlappingTrianglesShowNoAcne) {
  auto m = std::make_shared<MeshData>();
  add_quad(*m, 2.f, 3.f);
  add_quad(*m, 2.f, 3.f);
  add_quad(*m, 2.f, std::nextafter(3.f, 4.f));
  add_triangle(*m, {-2.f, -2.f, 3.f}, {0.f, 2.f, 3.f}, {2.f, -2.f, 3.f});
  expect_plane_at_half(m, "coplanar");
}

// In front of the plane: a zero-area triangle (repeated vertex), a collinear one, and slivers of
// width 1e-7 and 1e-30 (the last one's normal underflows). Expected: 0.5 everywhere (the slivers
// cover almost no pixel area), all finite.
TEST(HardGeometry, SliverAndZeroAreaTrianglesAreHarmless) {
  auto m = std::make_shared<MeshData>();
  add_quad(*m, 2.f, 3.f);
  add_triangle(*m, {0.f, 0.f, 2.f}, {0.f, 0.f, 2.f}, {0.5f, 0.5f, 2.f});
  add_triangle(*m, {-1.f, 0.f, 2.f}, {0.f, 0.f, 2.f}, {1.f, 0.f, 2.f});
  add_triangle(*m, {-1.f, 0.3f, 2.f}, {1.f, 0.3f, 2.f}, {0.f, 0.3f + 1e-7f, 2.f});
  add_triangle(*m, {-1.f, -0.3f, 2.f}, {1.f, -0.3f, 2.f}, {0.f, -0.3f + 1e-30f, 2.f});
  expect_plane_at_half(m, "slivers");
  // Through a loader the degenerate ones are dropped (and the factory warns about them).
  MeshData loaded = *m;
  MeshLoadStats stats;
  finish_mesh(loaded, true, FileLoc{"mem", 1}, &stats);
  EXPECT_GE(stats.degenerate_dropped, 2u);
}

// Built in code (a loader would refuse them, see below): triangles with a NaN vertex, an infinite
// one, and huge (1e30, finite) coordinates whose edge cross product overflows. Expected: the BVH
// skips the non-finite ones and the image is still the plane at 0.5: no NaN bound hides it, no
// NaN reaches a pixel.
TEST(HardGeometry, NaNAndHugeVerticesDoNotPoisonTheBvh) {
  auto m = std::make_shared<MeshData>();
  add_triangle(*m, {kNaN, 0.f, 2.f}, {1.f, 0.f, 2.f}, {0.f, 1.f, 2.f});
  add_quad(*m, 2.f, 3.f);
  add_triangle(*m, {0.f, 0.f, 2.f}, {std::numeric_limits<float>::infinity(), 0.f, 2.f}, {0.f, 1.f, 2.f});
  add_triangle(*m, {1e30f, 1e30f, 1e30f}, {-1e30f, 1e30f, 1e30f}, {0.f, -1e30f, 1e30f});
  add_triangle(*m, {kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN}, {kNaN, kNaN, kNaN});
  expect_plane_at_half(m, "nan vertices");
}

// Through the loaders: a NaN position is refused with a SceneError naming the file; a triangle with
// 1e30 coordinates (its normal overflows) is dropped and counted, the rest of the mesh kept.
TEST(HardGeometry, LoadersRejectNaNAndDropOverflowingTriangles) {
  test::TempDir dir;
  const std::string nan_obj = dir.write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
  const std::string msg = test::scene_error_of([&] { (void)load_obj(nan_obj, ObjOptions{}); });
  EXPECT_NE(msg.find("nan.obj"), std::string::npos) << msg;
  const std::string huge_obj = dir.write(
      "huge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e30 1e30 0\nv -1e30 1e30 0\nv 0 -1e30 0\nf 1 2 3\nf 4 5 6\n");
  MeshLoadStats stats;
  const MeshData mesh = load_obj(huge_obj, ObjOptions{}, &stats);
  EXPECT_EQ(mesh.num_triangles(), 1u);
  EXPECT_EQ(stats.degenerate_dropped, 1u);
  for (const Vec3& n : mesh.normals) EXPECT_TRUE(is_finite(n));
}

// Vertex normals of zero length, NaN, and pointing against the face (|n| = 1 but -ng), on the
// plane. Expected: the mesh keeps rendering at 0.5 (an unusable interpolated normal falls back to
// ng; a back-facing one is turned to ng's side, shape.h's contract), finite everywhere.
TEST(HardGeometry, ZeroAndBackFacingNormalsShadeLikeTheFace) {
  for (int variant = 0; variant < 3; ++variant) {
    auto m = std::make_shared<MeshData>();
    add_quad(*m, 2.f, 3.f);
    const Vec3 n = variant == 0 ? Vec3(0.f) : variant == 1 ? Vec3(kNaN, 0.f, 0.f) : Vec3(0.f, 0.f, 1.f);
    m->normals.assign(m->positions.size(), n);
    expect_plane_at_half(m, variant == 0 ? "zero normals" : variant == 1 ? "nan normals" : "back-facing normals");
  }
}

}  // namespace
}  // namespace tessera

#include "shape_test_util.h"
#include "test_support.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace tessera {
namespace {

using test::expect_scene_error;
using test::write_scratch;

void expect_unit_normals(const MeshData& m) {
  for (const Vec3& n : m.normals) ASSERT_NEAR(length(n), 1.f, 1e-4f);
}

TEST(ObjLoader, BathroomAllFilesMatchTheRayFileTriangleCount) {
  std::string dir = test::shared_path("scenes/bathroom/models");
  TESSERA_REQUIRE_FILE(dir);
  // rays/README.md: the 855 OBJ files hold 592,186 triangles in total.
  size_t files = 0, triangles = 0, dropped = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".obj") continue;
    MeshLoadStats stats;
    MeshData m = load_obj(e.path().string(), {}, &stats);
    ++files;
    triangles += m.num_triangles();
    dropped += stats.degenerate_dropped;
    ASSERT_EQ(m.normals.size(), m.positions.size()) << e.path();
  }
  EXPECT_EQ(files, 855u);
  EXPECT_EQ(triangles + dropped, 592186u);
}

TEST(ObjLoader, BathroomMeshWithoutNormalsGetsSmoothNormals) {
  // Mesh263.obj is the only bathroom file without `vn` lines.
  std::string path = test::shared_path("scenes/bathroom/models/Mesh263.obj");
  TESSERA_REQUIRE_FILE(path);
  MeshData m = load_obj(path, {});
  EXPECT_EQ(m.num_triangles(), 20480u);
  ASSERT_EQ(m.normals.size(), m.positions.size());
  expect_unit_normals(m);
  EXPECT_EQ(m.uvs.size(), m.positions.size());
  MeshData flat = load_obj(path, {.face_normals = true});
  EXPECT_TRUE(flat.normals.empty());
  EXPECT_EQ(flat.num_triangles(), m.num_triangles());
}

TEST(ObjLoader, VeachBidirModels) {
  std::string dir = test::shared_path("scenes/veach-bidir/models");
  TESSERA_REQUIRE_FILE(dir);
  // Face counts from `grep -c '^f'`: all faces are triangles.
  const std::pair<const char*, size_t> expected[] = {{"Mesh000.obj", 12}, {"Mesh001.obj", 1024},
                                                     {"Mesh002.obj", 7936}, {"Mesh010.obj", 10}};
  for (const auto& [name, faces] : expected) {
    MeshLoadStats stats;
    MeshData m = load_obj(dir + "/" + name, {}, &stats);
    EXPECT_EQ(m.num_triangles() + stats.degenerate_dropped, faces) << name;
    expect_unit_normals(m);
  }
  // Mesh000 is a 2.64 x 0.1 x 5.114 box: 24 distinct (position, normal) vertices, area known.
  MeshData box = load_obj(dir + "/Mesh000.obj", {});
  EXPECT_EQ(box.positions.size(), 24u);
  double w = 3.706875 - 1.066875, h = 0.1, d = 1.378570 + 3.735601;
  EXPECT_NEAR(test::mesh_area(box), 2 * (w * h + h * d + w * d), 1e-4);
}

TEST(ObjLoader, QuadsAndPolygonsAreFanTriangulatedAndVerticesUnified) {
  std::string path = write_scratch("poly.obj",
                                   "# a unit square and a pentagon sharing an edge\n"
                                   "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                                   "f 1 2 3 4\n"
                                   "g other\n"
                                   "v 1.5 1.5 0\n"
                                   "f 2 5 6 -1 3\n");  // -1 = the vertex just defined
  MeshData m = load_obj(path, {});
  ASSERT_EQ(m.num_triangles(), 5u);  // 2 + 3, both groups in one mesh
  EXPECT_EQ(m.positions.size(), 7u);  // shared positions merged
  EXPECT_NEAR(test::mesh_area(m), 1.0 + 1.0 + 0.25, 1e-6);
  // Fan of the quad: (0,1,2), (0,2,3).
  EXPECT_EQ(m.positions[m.indices[0]], Vec3(0, 0, 0));
  EXPECT_EQ(m.positions[m.indices[3]], Vec3(0, 0, 0));
  EXPECT_EQ(m.positions[m.indices[5]], Vec3(0, 1, 0));
  // Smooth normals of a flat +z mesh.
  for (const Vec3& n : m.normals) EXPECT_NEAR(n.z, 1.f, 1e-6f);
}

TEST(ObjLoader, DistinctUvsSplitVerticesAndFlipTexCoords) {
  std::string path = write_scratch("uv.obj",
                                   "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                   "vt 0 0.25\nvt 1 0.25\nvt 0 1\nvt 0.5 0.5\n"
                                   "vn 0 0 1\n"
                                   "f 1/1/1 2/2/1 3/3/1\n"
                                   "f 1/4/1 3/3/1 2/2/1\n");
  MeshData m = load_obj(path, {});
  EXPECT_EQ(m.positions.size(), 4u);  // vertex 1 appears with two uvs
  ASSERT_EQ(m.uvs.size(), 4u);
  EXPECT_FLOAT_EQ(m.uvs[m.indices[0]].y, 0.75f);  // default flip: v -> 1 - v (Mitsuba 0.6)
  MeshData raw = load_obj(path, {.flip_tex_coords = false});
  EXPECT_FLOAT_EQ(raw.uvs[raw.indices[0]].y, 0.25f);
}

TEST(ObjLoader, SmoothNormalsAreAngleWeighted) {
  // At the origin: two +z triangles with 45 degree corners and one +x triangle with a 90 degree
  // corner. Angle weighting gives both planes equal weight; face or area weighting would not (2:1).
  std::string path = write_scratch("fold.obj",
                                   "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                                   "f 1 2 3\nf 1 3 4\nf 1 4 5\n");
  MeshData m = load_obj(path, {});
  Vec3 n0 = m.normals[m.indices[0]];
  EXPECT_NEAR(n0.x, std::sqrt(0.5f), 1e-5f);
  EXPECT_NEAR(n0.z, std::sqrt(0.5f), 1e-5f);
  EXPECT_NEAR(n0.y, 0.f, 1e-6f);
}

TEST(ObjLoader, ZeroAreaTrianglesAreDroppedAndCounted) {
  std::string path = write_scratch("degenerate.obj",
                                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
                                   "f 1 2 3\nf 1 2 4\nf 1 1 3\n");
  MeshLoadStats stats;
  MeshData m = load_obj(path, {}, &stats);
  EXPECT_EQ(m.num_triangles(), 1u);
  EXPECT_EQ(stats.degenerate_dropped, 2u);
}

TEST(ObjLoader, MalformedInputsAreSceneErrorsNamingTheFile) {
  struct Case {
    const char* name;
    const char* text;
    const char* needle;
  };
  const Case cases[] = {
      {"nan_vertex.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", ":2:"},
      {"inf_vertex.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n", ":2:"},
      {"bad_number.obj", "v 0 0 0\nv 1,5 0 0\nv 0 1 0\nf 1 2 3\n", "invalid number"},
      {"short_vertex.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", ":2:"},
      {"index_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "out of range"},
      {"index_zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", ":4:"},
      {"relative_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", ":4:"},
      {"normal_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n", "normal"},
      {"truncated.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2", ":4:"},
      {"bad_face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "malformed"},
      {"no_faces.obj", "v 0 0 0\n", "no faces"},
      {"garbage.obj", "\x01\x02\x00\xff garbage", "not a text file"},
  };
  for (const Case& c : cases) {
    std::string text = c.text;
    if (std::string(c.name) == "garbage.obj") text.assign(c.text, 12);
    std::string path = write_scratch(c.name, text);
    SCOPED_TRACE(c.name);
    expect_scene_error([&] { load_obj(path, {}); }, path, c.needle);
  }
  std::string missing = (test::scratch_dir() / "does_not_exist.obj").string();
  expect_scene_error([&] { load_obj(missing, {}); }, missing, "cannot open");
}

TEST(ObjLoader, NanNormalIsRepairedNotFatal) {
  std::string path = write_scratch("nan_normal.obj",
                                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn nan nan nan\nvn 0 0 1\n"
                                   "f 1//1 2//2 3//2\n");
  MeshData m = load_obj(path, {});
  ASSERT_EQ(m.normals.size(), 3u);
  for (const Vec3& n : m.normals) EXPECT_NEAR(n.z, 1.f, 1e-6f);
}

}  // namespace
}  // namespace tessera

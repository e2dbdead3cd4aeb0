#include "shape_test_util.h"
#include "test_support.h"

#include <zlib.h>

#include <cstring>

namespace tessera {
namespace {

using test::expect_scene_error;
using test::write_scratch;

const char* kKitchen = "scenes/kitchenette/meshes/kitchen.serialized";

template <typename T>
void put(std::string& s, T v) {  // little endian (the test machine is x86-64)
  s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

struct TestMesh {
  std::vector<double> pos, nrm, uv;  // flat
  std::vector<uint32_t> idx;
};

std::string deflate(const std::string& raw) {
  uLongf n = compressBound(uLong(raw.size()));
  std::string out(n, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &n,
                      reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()), 6),
            Z_OK);
  out.resize(n);
  return out;
}

/// Writes meshes in Mitsuba's layout, version 3 or 4, single or double precision.
std::string write_serialized(const std::vector<TestMesh>& meshes, int version, bool dbl) {
  std::string file;
  std::vector<uint64_t> offsets;
  for (const TestMesh& m : meshes) {
    offsets.push_back(file.size());
    put<uint16_t>(file, 0x041C);
    put<uint16_t>(file, uint16_t(version));
    std::string raw;
    uint32_t flags = (dbl ? 0x2000 : 0x1000) | (m.nrm.empty() ? 0 : 1) | (m.uv.empty() ? 0 : 2);
    put(raw, flags);
    if (version == 4) raw += std::string("test mesh") + '\0';
    put<uint64_t>(raw, m.pos.size() / 3);
    put<uint64_t>(raw, m.idx.size() / 3);
    for (const auto* arr : {&m.pos, &m.nrm, &m.uv})
      for (double v : *arr) dbl ? put(raw, v) : put(raw, float(v));
    for (uint32_t i : m.idx) put(raw, i);
    file += deflate(raw);
  }
  for (uint64_t o : offsets) version == 4 ? put(file, o) : put(file, uint32_t(o));
  put(file, uint32_t(meshes.size()));
  return file;
}

TestMesh triangle_mesh(double scale) {
  TestMesh m;
  m.pos = {0, 0, 0, scale, 0, 0, 0, scale, 0};
  m.nrm = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  m.uv = {0, 0, 1, 0, 0, 1};
  m.idx = {0, 1, 2};
  return m;
}

TEST(SerializedLoader, KitchenetteHas88ShapesWithTheDocumentedTriangleCount) {
  std::string path = test::shared_path(kKitchen);
  TESSERA_REQUIRE_FILE(path);
  ASSERT_EQ(serialized_shape_count(path), 88);
  // PROVENANCE.md: 177,640 vertices and 253,435 triangles over the 88 shapes; normals and uvs.
  size_t vertices = 0, triangles = 0;
  for (int i = 0; i < 88; ++i) {
    MeshLoadStats stats;
    MeshData m = load_serialized(path, i, false, &stats);
    vertices += m.positions.size();
    triangles += m.num_triangles() + stats.degenerate_dropped;
    ASSERT_EQ(m.normals.size(), m.positions.size()) << "shape " << i;
    ASSERT_EQ(m.uvs.size(), m.positions.size()) << "shape " << i;
    for (const Vec3& n : m.normals) ASSERT_NEAR(length(n), 1.f, 1e-4f) << "shape " << i;
  }
  EXPECT_EQ(vertices, 177640u);
  EXPECT_EQ(triangles, 253435u);
}

TEST(SerializedLoader, KitchenetteShapeIndexOutOfRangeIsAnError) {
  std::string path = test::shared_path(kKitchen);
  TESSERA_REQUIRE_FILE(path);
  expect_scene_error([&] { load_serialized(path, 88, false); }, path, "0..87");
  expect_scene_error([&] { load_serialized(path, -1, false); }, path, "out of range");
  MeshData last = load_serialized(path, 87, true);
  EXPECT_TRUE(last.normals.empty());
  EXPECT_GT(last.num_triangles(), 0u);
}

TEST(SerializedLoader, SyntheticVersionsAndPrecisions) {
  for (int version : {3, 4}) {
    for (bool dbl : {false, true}) {
      SCOPED_TRACE(::testing::Message() << "version " << version << (dbl ? " double" : " single"));
      TestMesh plain = triangle_mesh(3.0);
      plain.nrm.clear();
      plain.uv.clear();
      std::string path = write_scratch("synthetic.serialized",
                                       write_serialized({triangle_mesh(1.0), plain}, version, dbl));
      ASSERT_EQ(serialized_shape_count(path), 2);
      MeshData a = load_serialized(path, 0, false);
      EXPECT_EQ(a.positions[1], Vec3(1, 0, 0));
      EXPECT_EQ(a.uvs[2].y, 1.f);
      MeshData b = load_serialized(path, 1, false);
      EXPECT_EQ(b.positions[2], Vec3(0, 3, 0));
      EXPECT_TRUE(b.uvs.empty());
      ASSERT_EQ(b.normals.size(), 3u);  // computed
      EXPECT_NEAR(b.normals[0].z, 1.f, 1e-6f);
    }
  }
}

TEST(SerializedLoader, ZeroAreaTrianglesAreDroppedAndCounted) {
  TestMesh m = triangle_mesh(1.0);
  m.idx = {0, 1, 2, 0, 0, 1, 2, 2, 2};
  std::string path = write_scratch("degenerate.serialized", write_serialized({m}, 4, false));
  MeshLoadStats stats;
  EXPECT_EQ(load_serialized(path, 0, false, &stats).num_triangles(), 1u);
  EXPECT_EQ(stats.degenerate_dropped, 2u);
}

TEST(SerializedLoader, MalformedInputsAreSceneErrorsNamingTheFile) {
  std::string good = write_serialized({triangle_mesh(1.0), triangle_mesh(2.0)}, 4, false);
  TestMesh nan_mesh = triangle_mesh(1.0);
  nan_mesh.pos[4] = std::nan("");
  TestMesh bad_index = triangle_mesh(1.0);
  bad_index.idx[2] = 3;
  // The second mesh's compressed stream, cut short, with an intact dictionary pointing at it.
  std::string one = write_serialized({triangle_mesh(1.0)}, 4, false);
  size_t first_len = one.size() - 12;
  std::string cut = good.substr(0, first_len + 20);
  put<uint64_t>(cut, 0);
  put<uint64_t>(cut, first_len);
  put<uint32_t>(cut, 2);

  struct Case {
    const char* name;
    std::string bytes;
    int index;
    const char* needle;
  };
  std::string garbage_stream = good;
  garbage_stream[4] = garbage_stream[5] = char(0x55);  // breaks the zlib header
  const Case cases[] = {
      {"truncated.serialized", good.substr(0, 30), 0, "truncated"},
      {"truncated_second.serialized", cut, 1, "truncated"},
      {"nan.serialized", write_serialized({nan_mesh}, 4, false), 0, "NaN"},
      {"index.serialized", write_serialized({bad_index}, 3, true), 0, "references vertex 3"},
      {"bad_magic.serialized", std::string("\x1d\x04\x04\x00", 4) + "garbage-garbage", 0,
       "format identifier"},
      {"bad_version.serialized", std::string("\x1c\x04\x07\x00", 4) + "garbage-garbage", 0, "version"},
      {"garbage_stream.serialized", garbage_stream, 0, "corrupt"},
      {"tiny.serialized", "\x1c", 0, "end of file"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::string path = write_scratch(c.name, c.bytes);
    expect_scene_error([&] { load_serialized(path, c.index, false); }, path, c.needle);
  }
  std::string missing = (test::scratch_dir() / "missing.serialized").string();
  expect_scene_error([&] { load_serialized(missing, 0, false); }, missing, "cannot open");
}

}  // namespace
}  // namespace tessera

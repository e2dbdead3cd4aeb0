#include "shape_test_util.h"

#include <bit>
#include <cstring>

namespace tessera {
namespace {

using test::expect_scene_error;
using test::write_scratch;

enum class Enc { Ascii, LE, BE };

/// Writes scalars in a PLY body in one of the three encodings.
class BodyWriter {
 public:
  explicit BodyWriter(Enc enc) : enc_(enc) {}
  template <typename T>
  void put(T v) {
    if (enc_ == Enc::Ascii) {
      if constexpr (sizeof(T) == 1)
        out_ += std::to_string(int(v));
      else
        out_ += std::to_string(v);
      out_ += ' ';
      return;
    }
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    bool big = enc_ == Enc::BE;
    if (big != (std::endian::native == std::endian::big))
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    out_.append(reinterpret_cast<const char*>(b), sizeof(T));
  }
  void end_line() {
    if (enc_ == Enc::Ascii) out_ += '\n';
  }
  const std::string& str() const { return out_; }

 private:
  Enc enc_;
  std::string out_;
};

const char* format_name(Enc e) {
  return e == Enc::Ascii ? "ascii" : e == Enc::LE ? "binary_little_endian" : "binary_big_endian";
}

/// A unit square (one quad) plus a triangle, with normals, uvs, an unknown per-vertex property,
/// an unknown element with a list before the faces, and an extra face property after the list.
std::string square_ply(Enc enc) {
  std::string h = std::string("ply\nformat ") + format_name(enc) + " 1.0\n" +
                  "comment written by ply_loader_test\n"
                  "element vertex 5\n"
                  "property float x\nproperty float y\nproperty double z\n"
                  "property uchar red\n"
                  "property float nx\nproperty float ny\nproperty float nz\n"
                  "property float s\nproperty float t\n"
                  "element material 2\n"
                  "property list uchar int ids\nproperty short flags\n"
                  "element face 2\n"
                  "property list uchar uint vertex_indices\n"
                  "property ushort tag\n"
                  "end_header\n";
  BodyWriter w(enc);
  const float pos[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}};
  for (int i = 0; i < 5; ++i) {
    w.put(pos[i][0]);
    w.put(pos[i][1]);
    w.put(double(pos[i][2]));
    w.put(uint8_t(200));
    w.put(0.f);
    w.put(0.f);
    w.put(2.f);  // not unit: the loader normalizes
    w.put(pos[i][0] * 0.5f);
    w.put(pos[i][1]);
    w.end_line();
  }
  for (int m = 0; m < 2; ++m) {
    w.put(uint8_t(3));
    for (int k = 0; k < 3; ++k) w.put(int32_t(k + m));
    w.put(int16_t(-7));
    w.end_line();
  }
  w.put(uint8_t(4));
  for (uint32_t i : {0u, 1u, 2u, 3u}) w.put(i);
  w.put(uint16_t(1));
  w.end_line();
  w.put(uint8_t(3));
  for (uint32_t i : {1u, 4u, 2u}) w.put(i);
  w.put(uint16_t(2));
  w.end_line();
  return h + w.str();
}

class PlyEncodings : public ::testing::TestWithParam<Enc> {};

TEST_P(PlyEncodings, ReadsPositionsNormalsUvsAndSkipsUnknownData) {
  std::string path = write_scratch(std::string("square_") + format_name(GetParam()) + ".ply",
                                   square_ply(GetParam()));
  MeshData m = load_ply(path, false);
  ASSERT_EQ(m.positions.size(), 5u);
  ASSERT_EQ(m.num_triangles(), 3u);  // quad fan (0,1,2),(0,2,3) + triangle
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 1, 4, 2}));
  EXPECT_EQ(m.positions[4], Vec3(2, 0, 0));
  ASSERT_EQ(m.normals.size(), 5u);
  EXPECT_EQ(m.normals[3], Vec3(0, 0, 1));
  ASSERT_EQ(m.uvs.size(), 5u);
  EXPECT_FLOAT_EQ(m.uvs[2].x, 0.5f);
  EXPECT_FLOAT_EQ(m.uvs[2].y, 1.f);
  EXPECT_NEAR(test::mesh_area(m), 1.5, 1e-6);
  EXPECT_TRUE(load_ply(path, true).normals.empty());
}

INSTANTIATE_TEST_SUITE_P(AllEncodings, PlyEncodings, ::testing::Values(Enc::Ascii, Enc::LE, Enc::BE));

TEST(PlyLoader, VertexIndexNameAndSignedIndexTypesWithoutNormals) {
  std::string text =
      "ply\r\nformat binary_big_endian 1.0\r\nelement vertex 3\r\nproperty float32 x\r\n"
      "property float32 y\r\nproperty float32 z\r\nproperty float32 u\r\nproperty float32 v\r\n"
      "element face 1\r\nproperty list int8 int16 vertex_index\r\nend_header\r\n";
  BodyWriter w(Enc::BE);
  const float p[3][5] = {{0, 0, 0, 0, 0}, {0, 2, 0, 1, 0}, {0, 0, 2, 0, 1}};
  for (const auto& v : p)
    for (float c : v) w.put(c);
  w.put(int8_t(3));
  for (int16_t i : {0, 1, 2}) w.put(i);
  std::string path = write_scratch("signed.ply", text + w.str());
  MeshData m = load_ply(path, false);
  ASSERT_EQ(m.num_triangles(), 1u);
  ASSERT_EQ(m.normals.size(), 3u);  // computed: the triangle faces +x
  EXPECT_NEAR(m.normals[0].x, 1.f, 1e-6f);
  EXPECT_NEAR(test::mesh_area(m), 2.0, 1e-6);
}

TEST(PlyLoader, ZeroAreaFacesAreDroppedAndCounted) {
  std::string text =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 3\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n2 0 0\n3 0 1 2\n3 0 1 3\n3 2 2 1\n";
  MeshLoadStats stats;
  MeshData m = load_ply(write_scratch("degenerate.ply", text), false, &stats);
  EXPECT_EQ(m.num_triangles(), 1u);
  EXPECT_EQ(stats.degenerate_dropped, 2u);
}

TEST(PlyLoader, MalformedInputsAreSceneErrorsNamingTheFile) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  struct Case {
    const char* name;
    std::string text;
    const char* needle;
  };
  std::string bin = square_ply(Enc::LE);
  const Case cases[] = {
      {"truncated_ascii.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1", "end of file"},
      {"truncated_binary.ply", bin.substr(0, bin.size() - 9), "end of file"},
      {"nan_vertex.ply", header + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", "NaN"},
      {"inf_vertex.ply", header + "0 0 0\n1e999 0 0\n0 1 0\n3 0 1 2\n", "NaN"},
      {"bad_number.ply", header + "0 0 0\n1x 0 0\n0 1 0\n3 0 1 2\n", "invalid number"},
      {"index_range.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "references vertex"},
      {"negative_index.ply", header + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "references vertex"},
      {"two_vertex_face.ply", header + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "fewer than 3"},
      {"huge_count.ply",
       "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
       "property float y\nproperty float z\nend_header\n\x01\x02",
       "too short"},
      {"bad_format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown PLY format"},
      {"no_header_end.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "incomplete"},
      {"not_ply.ply", "PK\x03\x04 garbage", "not a PLY"},
      {"no_faces.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                       "property float z\nend_header\n0 0 0\n", "no faces"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    std::string path = write_scratch(c.name, c.text);
    expect_scene_error([&] { load_ply(path, false); }, path, c.needle);
  }
  std::string missing = (test::scratch_dir() / "missing.ply").string();
  expect_scene_error([&] { load_ply(missing, false); }, missing, "cannot open");
}

}  // namespace
}  // namespace tessera

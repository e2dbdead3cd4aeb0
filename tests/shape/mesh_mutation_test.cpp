// Deterministic mutation fuzzing of the three loaders: every corrupted file must either load into a
// valid mesh or raise SceneError; anything else (another exception, a crash, a sanitizer report in
// the TESSERA_SANITIZE build) is a bug.
#include "shape_test_util.h"

#include "tessera/core/hash.h"

#include <zlib.h>

namespace tessera {
namespace {

using test::write_scratch;

std::string mutate(const std::string& src, Pcg32& rng) {
  std::string s = src;
  switch (rng.next_u32() % 4) {
    case 0:  // truncate
      s.resize(rng.next_u32() % (s.size() + 1));
      break;
    case 1:  // flip a few bytes
      for (int k = 0, n = 1 + int(rng.next_u32() % 4); k < n && !s.empty(); ++k)
        s[rng.next_u32() % s.size()] = char(rng.next_u32());
      break;
    case 2: {  // overwrite a byte with a digit or separator (keeps text files textual)
      static const char kChars[] = "0123456789-./ \nnaef";
      if (!s.empty()) s[rng.next_u32() % s.size()] = kChars[rng.next_u32() % (sizeof(kChars) - 1)];
      break;
    }
    default: {  // duplicate or delete a slice
      if (s.empty()) break;
      size_t a = rng.next_u32() % s.size(), len = 1 + rng.next_u32() % 16;
      if (rng.next_u32() % 2)
        s.insert(a, s.substr(a, len));
      else
        s.erase(a, len);
    }
  }
  return s;
}

void fuzz(const std::string& name, const std::string& valid,
          const std::function<MeshData(const std::string&)>& load, int iterations) {
  Pcg32 rng(1234);
  size_t loaded = 0, rejected = 0;
  for (int i = 0; i < iterations; ++i) {
    std::string path = write_scratch(name, mutate(valid, rng));
    try {
      MeshData m = load(path);
      EXPECT_NO_THROW(validate_mesh(m, FileLoc{path, 0})) << "iteration " << i;
      for (const Vec3& n : m.normals) ASSERT_NEAR(length(n), 1.f, 1e-3f) << "iteration " << i;
      ++loaded;
    } catch (const SceneError&) {
      ++rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << name << " iteration " << i << ": non-SceneError exception: " << e.what();
    }
  }
  // Both outcomes must occur, or the mutations are not exercising anything.
  EXPECT_GT(loaded, 0u) << name;
  EXPECT_GT(rejected, 0u) << name;
}

TEST(MeshMutation, Obj) {
  std::string obj =
      "# cube-ish\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 1 0\n"
      "f 1/1/1 2/2/1 3/3/1 4/1/1\ng side\nf 1//2 2//2 6//2 5//2\nf -6 -5 -4\n";
  fuzz("fuzz.obj", obj, [](const std::string& p) { return load_obj(p, {}); }, 600);
}

TEST(MeshMutation, PlyAscii) {
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n4 0 1 2 3\n";
  fuzz("fuzz_ascii.ply", ply, [](const std::string& p) { return load_ply(p, false); }, 600);
}

TEST(MeshMutation, PlyBinary) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nelement face 2\n"
      "property list uchar uint vertex_indices\nend_header\n";
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  ply.append(reinterpret_cast<const char*>(v), sizeof(v));
  const uint32_t f[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (const auto& t : f) {
    ply += char(3);
    ply.append(reinterpret_cast<const char*>(t), sizeof(t));
  }
  fuzz("fuzz_binary.ply", ply, [](const std::string& p) { return load_ply(p, false); }, 600);
}

TEST(MeshMutation, Serialized) {
  // Two meshes, version 4, with an end-of-file dictionary; mutations hit headers, the zlib
  // streams and the dictionary alike.
  std::string file;
  std::vector<uint64_t> offsets;
  for (int k = 0; k < 2; ++k) {
    offsets.push_back(file.size());
    file += std::string("\x1c\x04\x04\x00", 4);
    std::string raw;
    uint32_t flags = 0x1000 | 0x1;
    raw.append(reinterpret_cast<const char*>(&flags), 4);
    raw += std::string("m") + '\0';
    uint64_t nv = 3, nt = 1;
    raw.append(reinterpret_cast<const char*>(&nv), 8);
    raw.append(reinterpret_cast<const char*>(&nt), 8);
    const float pn[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    raw.append(reinterpret_cast<const char*>(pn), sizeof(pn));
    const uint32_t idx[3] = {0, 1, 2};
    raw.append(reinterpret_cast<const char*>(idx), sizeof(idx));
    uLongf n = compressBound(uLong(raw.size()));
    std::string z(n, '\0');
    ASSERT_EQ(compress2(reinterpret_cast<Bytef*>(z.data()), &n,
                        reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()), 6), Z_OK);
    file += z.substr(0, n);
  }
  for (uint64_t o : offsets) file.append(reinterpret_cast<const char*>(&o), 8);
  uint32_t count = 2;
  file.append(reinterpret_cast<const char*>(&count), 4);
  ASSERT_EQ(load_serialized(write_scratch("ok.serialized", file), 1, false).num_triangles(), 1u);
  fuzz("fuzz.serialized", file, [](const std::string& p) { return load_serialized(p, 1, false); }, 600);
}

}  // namespace
}  // namespace tessera

// Mitsuba's `.serialized` meshes -> MeshData.
//
// Layout (little endian; Mitsuba's serialized.cpp documents it): per mesh an uncompressed header
// `u16 0x041C, u16 version (3 or 4)`, then a zlib stream holding `u32 flags`, (v4 only) a
// NUL-terminated name, `u64 vertex_count`, `u64 triangle_count`, positions, [normals], [uvs],
// [colors] as float32 or float64 per the flags, and u32 triangle indices. Several meshes are
// concatenated; the file ends with the start offset of each mesh (u64 in v4, u32 in v3) and a u32
// mesh count. The file's own "face normals" flag is ignored, as in Mitsuba 0.6 and 3: the
// `faceNormals` parameter decides.
#include "tessera/shape/mesh_io.h"

#include "tessera/scene/error.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>

namespace tessera {

namespace {

constexpr uint16_t kFormatId = 0x041C;
constexpr uint32_t kHasNormals = 0x0001, kHasUvs = 0x0002, kHasColors = 0x0008;
constexpr uint32_t kDoublePrecision = 0x2000;
// zlib cannot expand data by more than about 1032:1; larger claimed sizes are corrupt counts.
constexpr uint64_t kMaxZlibRatio = 1100;

template <typename T>
T from_le(const unsigned char* b) {
  T v;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(&v, b, sizeof(T));
  } else {
    unsigned char r[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) r[i] = b[sizeof(T) - 1 - i];
    std::memcpy(&v, r, sizeof(T));
  }
  return v;
}

class SerializedFile {
 public:
  explicit SerializedFile(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) fail("cannot open .serialized file");
    in_.seekg(0, std::ios::end);
    size_ = uint64_t(in_.tellg());
    unsigned char h[4];
    read_at(0, h, 4);
    version_ = check_header(h);
    read_dictionary();
  }

  [[noreturn]] void fail(const std::string& msg) const { throw SceneError(FileLoc{path_, 0}, msg); }
  int count() const { return int(offsets_.size()); }
  int version() const { return version_; }
  uint64_t size() const { return size_; }
  /// Byte range [begin, end) of mesh `i`, header included.
  std::pair<uint64_t, uint64_t> range(int i) const {
    return {offsets_[size_t(i)], size_t(i) + 1 < offsets_.size() ? offsets_[size_t(i) + 1] : data_end_};
  }

  void read_at(uint64_t pos, void* dst, uint64_t n) {
    if (pos > size_ || n > size_ - pos) fail("unexpected end of file (truncated)");
    in_.clear();
    in_.seekg(std::streamoff(pos));
    in_.read(static_cast<char*>(dst), std::streamsize(n));
    if (!in_) fail("error while reading");
  }

  int check_header(const unsigned char* h) const {
    uint16_t format = from_le<uint16_t>(h), version = from_le<uint16_t>(h + 2);
    if (format == 0x1C04) fail("geometry file from an old Mitsuba version (re-export it)");
    if (format != kFormatId) fail("not a Mitsuba .serialized file (bad format identifier)");
    if (version != 3 && version != 4)
      fail("unsupported .serialized version " + std::to_string(version) + " (3 or 4 expected)");
    return version;
  }

 private:
  void read_dictionary() {
    // Without a usable dictionary the file holds a single mesh (Mitsuba makes the same assumption).
    offsets_.assign(1, 0);
    data_end_ = size_;
    if (size_ < 8) return;
    unsigned char b[8];
    read_at(size_ - 4, b, 4);
    uint64_t count = from_le<uint32_t>(b);
    uint64_t entry = version_ == 4 ? 8 : 4;
    if (count == 0 || count > (size_ - 4) / entry) return;
    uint64_t dict_start = size_ - 4 - count * entry;
    std::vector<unsigned char> raw(count * entry);
    read_at(dict_start, raw.data(), raw.size());
    std::vector<uint64_t> offsets(count);
    for (uint64_t i = 0; i < count; ++i)
      offsets[i] = entry == 8 ? from_le<uint64_t>(&raw[i * 8]) : from_le<uint32_t>(&raw[i * 4]);
    bool valid = offsets[0] == 0;
    for (uint64_t i = 0; valid && i < count; ++i)
      valid = offsets[i] < dict_start && dict_start - offsets[i] > 4 &&
              (i == 0 || offsets[i] > offsets[i - 1]);
    if (!valid) return;
    offsets_ = std::move(offsets);
    data_end_ = dict_start;
  }

  std::string path_;
  std::ifstream in_;
  uint64_t size_ = 0;
  int version_ = 0;
  std::vector<uint64_t> offsets_;
  uint64_t data_end_ = 0;
};

/// Pulls exactly the requested number of bytes out of one zlib stream.
class Inflater {
 public:
  Inflater(const std::vector<unsigned char>& src, const SerializedFile& file) : file_(file) {
    std::memset(&zs_, 0, sizeof(zs_));
    if (inflateInit(&zs_) != Z_OK) file_.fail("cannot initialise zlib");
    zs_.next_in = const_cast<unsigned char*>(src.data());
    zs_.avail_in = uInt(src.size());
  }
  ~Inflater() { inflateEnd(&zs_); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;

  void read(void* dst, uint64_t n) {
    auto* out = static_cast<unsigned char*>(dst);
    while (n > 0) {
      uInt chunk = uInt(std::min<uint64_t>(n, 1u << 30));
      zs_.next_out = out;
      zs_.avail_out = chunk;
      uInt in_before = zs_.avail_in;
      int ret = inflate(&zs_, Z_NO_FLUSH);
      if (ret == Z_NEED_DICT || ret == Z_DATA_ERROR || ret == Z_MEM_ERROR || ret == Z_STREAM_ERROR)
        file_.fail(std::string("corrupt compressed data (zlib: ") + (zs_.msg ? zs_.msg : "error") + ")");
      uint64_t got = chunk - zs_.avail_out;
      out += got;
      n -= got;
      if (n > 0 && (ret == Z_STREAM_END || (got == 0 && zs_.avail_in == in_before)))
        file_.fail("unexpected end of compressed data (truncated mesh)");
    }
  }
  template <typename T>
  T get() {
    unsigned char b[sizeof(T)];
    read(b, sizeof(T));
    return from_le<T>(b);
  }

 private:
  z_stream zs_;
  const SerializedFile& file_;
};

/// Reads `n` reals (float32 or float64 per `dbl`), converted to float.
/// Storage grows with the data actually decompressed, so a corrupt count fails on truncation
/// before it can cause a large allocation.
std::vector<float> read_reals(Inflater& z, bool dbl, uint64_t n) {
  std::vector<float> out;
  std::vector<unsigned char> buf;
  const uint64_t batch = 1 << 16;
  for (uint64_t i = 0; i < n; i += batch) {
    uint64_t m = std::min(batch, n - i);
    buf.resize(m * (dbl ? 8 : 4));
    z.read(buf.data(), buf.size());
    for (uint64_t k = 0; k < m; ++k)
      out.push_back(dbl ? float(from_le<double>(&buf[k * 8])) : from_le<float>(&buf[k * 4]));
  }
  return out;
}

std::vector<Vec3> to_vec3(const std::vector<float>& f) {
  std::vector<Vec3> v(f.size() / 3);
  for (size_t i = 0; i < v.size(); ++i) v[i] = Vec3(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
  return v;
}

}  // namespace

int serialized_shape_count(const std::string& path) { return SerializedFile(path).count(); }

MeshData load_serialized(const std::string& path, int shape_index, bool face_normals,
                         MeshLoadStats* stats) {
  SerializedFile file(path);
  if (shape_index < 0 || shape_index >= file.count())
    file.fail("shape index " + std::to_string(shape_index) + " is out of range: the file holds " +
              std::to_string(file.count()) + " shape(s), 0.." + std::to_string(file.count() - 1));
  auto [begin, end] = file.range(shape_index);
  if (end - begin <= 4) file.fail("mesh " + std::to_string(shape_index) + " is empty");
  unsigned char h[4];
  file.read_at(begin, h, 4);
  if (file.check_header(h) != file.version()) file.fail("mixed .serialized versions in one file");
  if (end - begin - 4 > 0xFFFFFFFFull)
    file.fail("mesh " + std::to_string(shape_index) + " is too large");
  std::vector<unsigned char> compressed(end - begin - 4);
  file.read_at(begin + 4, compressed.data(), compressed.size());

  Inflater z(compressed, file);
  uint32_t flags = z.get<uint32_t>();
  if (file.version() == 4) {
    // The shape's name: skipped, but bounded so garbage cannot make it unbounded.
    for (int i = 0;; ++i) {
      if (i > 65536) file.fail("corrupt mesh name");
      if (z.get<uint8_t>() == 0) break;
    }
  }
  uint64_t nv = z.get<uint64_t>(), nt = z.get<uint64_t>();
  bool dbl = flags & kDoublePrecision;
  uint64_t per_vertex = 3 + ((flags & kHasNormals) ? 3 : 0) + ((flags & kHasUvs) ? 2 : 0) +
                        ((flags & kHasColors) ? 3 : 0);
  if (nv > 0xFFFFFFFFull || nt > 0xFFFFFFFFull / 3)
    file.fail("mesh " + std::to_string(shape_index) + " is too large or corrupt");
  uint64_t claimed = nv * per_vertex * (dbl ? 8 : 4) + nt * 12;
  if (claimed > (compressed.size() + 64) * kMaxZlibRatio)
    file.fail("mesh " + std::to_string(shape_index) + " claims more data than the file can hold");

  MeshData mesh;
  mesh.positions = to_vec3(read_reals(z, dbl, nv * 3));
  if (flags & kHasNormals) mesh.normals = to_vec3(read_reals(z, dbl, nv * 3));
  if (flags & kHasUvs) {
    std::vector<float> uv = read_reals(z, dbl, nv * 2);
    mesh.uvs.resize(nv);
    for (size_t i = 0; i < nv; ++i) mesh.uvs[i] = Vec2(uv[2 * i], uv[2 * i + 1]);
  }
  if (flags & kHasColors) read_reals(z, dbl, nv * 3);  // vertex colours are not used
  std::vector<unsigned char> buf;
  const uint64_t batch = 1 << 16;
  for (uint64_t i = 0; i < nt * 3; i += batch) {
    uint64_t m = std::min(batch, nt * 3 - i);
    buf.resize(m * 4);
    z.read(buf.data(), buf.size());
    for (uint64_t k = 0; k < m; ++k) mesh.indices.push_back(from_le<uint32_t>(&buf[k * 4]));
  }
  finish_mesh(mesh, face_normals, FileLoc{path, 0}, stats);
  return mesh;
}

}  // namespace tessera

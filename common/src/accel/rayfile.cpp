#include "tessera/accel/rayfile.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

namespace tessera {
namespace {

constexpr char kRaysMagic[8] = {'R', 'B', 'R', 'A', 'Y', 'S', '0', '1'};
constexpr char kHitsMagic[8] = {'R', 'B', 'H', 'I', 'T', 'S', '0', '1'};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kRayRecordSize = 32;
constexpr uint32_t kHitRecordSize = 8;
constexpr size_t kNameSize = 16;

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RayFileError(path + ": cannot open");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw RayFileError(path + ": read error");
  return data;
}

/// Bounds-checked little-endian reader over a file image.
class Reader {
 public:
  Reader(const std::string& path, const std::string& data) : path_(path), data_(data) {}
  size_t remaining() const { return data_.size() - pos_; }
  void need(size_t n, const std::string& what) const {
    if (remaining() < n)
      throw RayFileError(path_ + ": truncated " + what + " at byte " + std::to_string(pos_) + " (need " +
                         std::to_string(n) + " bytes, " + std::to_string(remaining()) + " left)");
  }
  uint32_t u32() {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= uint32_t(uint8_t(data_[pos_ + i])) << (8 * i);
    pos_ += 4;
    return v;
  }
  uint64_t u64() {
    uint64_t lo = u32();
    return lo | (uint64_t(u32()) << 32);
  }
  float f32() { return std::bit_cast<float>(u32()); }
  std::string bytes(size_t n) {
    std::string s = data_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  size_t pos() const { return pos_; }

 private:
  const std::string& path_;
  const std::string& data_;
  size_t pos_ = 0;
};

class Writer {
 public:
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) buf_.push_back(char((v >> (8 * i)) & 0xFF));
  }
  void u64(uint64_t v) {
    u32(uint32_t(v));
    u32(uint32_t(v >> 32));
  }
  void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
  void bytes(const void* p, size_t n) { buf_.append(static_cast<const char*>(p), n); }
  std::string& buf() { return buf_; }

 private:
  std::string buf_;
};

struct SetHeader {
  std::string name;
  RayQuery query;
  uint64_t count;
};

/// Reads the file header; returns info text and number of sets.
uint32_t read_file_header(Reader& r, const std::string& path, const char (&magic)[8], std::string& info) {
  r.need(24, "file header");
  const std::string m = r.bytes(8);
  if (std::memcmp(m.data(), magic, 8) != 0)
    throw RayFileError(path + ": bad magic '" + m + "' (expected '" + std::string(magic, 8) + "')");
  const uint32_t version = r.u32();
  if (version != kVersion)
    throw RayFileError(path + ": unsupported version " + std::to_string(version) + " (expected 1)");
  const uint32_t num_sets = r.u32();
  const uint32_t info_len = r.u32();
  r.u32();  // reserved
  r.need(info_len, "info text");
  info = r.bytes(info_len);
  return num_sets;
}

SetHeader read_set_header(Reader& r, const std::string& path, uint32_t index, uint32_t record_size) {
  r.need(kNameSize + 16, "header of set " + std::to_string(index));
  std::string name = r.bytes(kNameSize);
  name.resize(std::strlen(name.c_str()));  // NUL-padded; a full 16-byte name has no NUL
  const uint32_t query = r.u32();
  const uint32_t size = r.u32();
  const uint64_t count = r.u64();
  const std::string where = path + ": set " + std::to_string(index) + " '" + name + "'";
  if (query > 1) throw RayFileError(where + ": unknown query " + std::to_string(query));
  if (size != record_size)
    throw RayFileError(where + ": record size " + std::to_string(size) + ", expected " +
                       std::to_string(record_size));
  if (count > r.remaining() / record_size)
    throw RayFileError(where + ": truncated: declares " + std::to_string(count) + " records but only " +
                       std::to_string(r.remaining() / record_size) + " remain in the file");
  return {name, RayQuery(query), count};
}

void check_trailing(const Reader& r, const std::string& path) {
  if (r.remaining() != 0)
    throw RayFileError(path + ": " + std::to_string(r.remaining()) + " unexpected bytes after the last set");
}

void write_file_header(Writer& w, const char (&magic)[8], const std::string& info, size_t num_sets) {
  w.bytes(magic, 8);
  w.u32(kVersion);
  w.u32(uint32_t(num_sets));
  w.u32(uint32_t(info.size()));
  w.u32(0);
  w.bytes(info.data(), info.size());
}

void write_set_header(Writer& w, const std::string& path, const std::string& name, RayQuery query,
                      uint32_t record_size, uint64_t count) {
  if (name.size() > kNameSize) throw RayFileError(path + ": set name '" + name + "' longer than 16 bytes");
  char padded[kNameSize] = {};
  std::memcpy(padded, name.data(), name.size());
  w.bytes(padded, kNameSize);
  w.u32(uint32_t(query));
  w.u32(record_size);
  w.u64(count);
}

void write_all(const std::string& path, const std::string& data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw RayFileError(path + ": cannot open for writing");
  out.write(data.data(), std::streamsize(data.size()));
  if (!out) throw RayFileError(path + ": write error");
}

}  // namespace

RayFile read_ray_file(const std::string& path) {
  const std::string data = read_all(path);
  Reader r(path, data);
  RayFile file;
  const uint32_t num_sets = read_file_header(r, path, kRaysMagic, file.info);
  for (uint32_t s = 0; s < num_sets; ++s) {
    const SetHeader h = read_set_header(r, path, s, kRayRecordSize);
    RaySet set{h.name, h.query, {}};
    set.rays.resize(h.count);
    for (Ray& ray : set.rays) {
      ray.o.x = r.f32(), ray.o.y = r.f32(), ray.o.z = r.f32();
      ray.tmin = r.f32();
      ray.d.x = r.f32(), ray.d.y = r.f32(), ray.d.z = r.f32();
      ray.tmax = r.f32();
    }
    file.sets.push_back(std::move(set));
  }
  check_trailing(r, path);
  return file;
}

HitFile read_hit_file(const std::string& path) {
  const std::string data = read_all(path);
  Reader r(path, data);
  HitFile file;
  const uint32_t num_sets = read_file_header(r, path, kHitsMagic, file.info);
  for (uint32_t s = 0; s < num_sets; ++s) {
    const SetHeader h = read_set_header(r, path, s, kHitRecordSize);
    HitSet set{h.name, h.query, {}};
    set.hits.resize(h.count);
    for (HitRecord& hit : set.hits) {
      hit.t = r.f32();
      hit.prim = r.u32();
    }
    file.sets.push_back(std::move(set));
  }
  check_trailing(r, path);
  return file;
}

void write_ray_file(const std::string& path, const RayFile& file) {
  Writer w;
  write_file_header(w, kRaysMagic, file.info, file.sets.size());
  for (const RaySet& set : file.sets) {
    write_set_header(w, path, set.name, set.query, kRayRecordSize, set.rays.size());
    for (const Ray& ray : set.rays) {
      w.f32(ray.o.x), w.f32(ray.o.y), w.f32(ray.o.z), w.f32(ray.tmin);
      w.f32(ray.d.x), w.f32(ray.d.y), w.f32(ray.d.z), w.f32(ray.tmax);
    }
  }
  write_all(path, w.buf());
}

void write_hit_file(const std::string& path, const HitFile& file) {
  Writer w;
  write_file_header(w, kHitsMagic, file.info, file.sets.size());
  for (const HitSet& set : file.sets) {
    write_set_header(w, path, set.name, set.query, kHitRecordSize, set.hits.size());
    for (const HitRecord& hit : set.hits) {
      w.f32(hit.t);
      w.u32(hit.prim);
    }
  }
  write_all(path, w.buf());
}

bool hits_agree(const HitRecord& a, const HitRecord& b) {
  if (a.is_hit() != b.is_hit()) return false;
  if (!a.is_hit()) return true;
  return std::abs(a.t - b.t) <= 1e-4f * std::max(a.t, b.t);
}

std::vector<SetAgreement> compare_hit_files(const HitFile& a, const HitFile& b) {
  if (a.sets.size() != b.sets.size())
    throw RayFileError("hit files have " + std::to_string(a.sets.size()) + " and " +
                       std::to_string(b.sets.size()) + " sets");
  std::vector<SetAgreement> result;
  for (size_t s = 0; s < a.sets.size(); ++s) {
    const HitSet &x = a.sets[s], &y = b.sets[s];
    if (x.name != y.name || x.query != y.query || x.hits.size() != y.hits.size())
      throw RayFileError("hit files differ in set " + std::to_string(s) + ": '" + x.name + "' (" +
                         std::to_string(x.hits.size()) + " records) vs '" + y.name + "' (" +
                         std::to_string(y.hits.size()) + " records)");
    SetAgreement agreement{x.name, x.hits.size(), 0};
    for (size_t i = 0; i < x.hits.size(); ++i)
      if (!hits_agree(x.hits[i], y.hits[i])) ++agreement.disagree;
    result.push_back(agreement);
  }
  return result;
}

void check_hits_match_rays(const RayFile& rays, const HitFile& hits, const std::string& what) {
  if (rays.sets.size() != hits.sets.size())
    throw RayFileError(what + ": " + std::to_string(hits.sets.size()) + " sets, the ray file has " +
                       std::to_string(rays.sets.size()));
  for (size_t s = 0; s < rays.sets.size(); ++s) {
    const RaySet& r = rays.sets[s];
    const HitSet& h = hits.sets[s];
    if (r.name != h.name || r.query != h.query || r.rays.size() != h.hits.size())
      throw RayFileError(what + ": set " + std::to_string(s) + " is '" + h.name + "' with " +
                         std::to_string(h.hits.size()) + " records, the ray file's is '" + r.name +
                         "' with " + std::to_string(r.rays.size()));
  }
}

}  // namespace tessera

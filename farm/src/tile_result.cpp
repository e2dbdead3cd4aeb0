#include "tessera/farm/tile_result.h"

#include "tessera/farm/sha256.h"

#include <zstd.h>

#include <bit>
#include <cstring>

namespace tessera {
namespace {

static_assert(std::endian::native == std::endian::little, "the tile format is little-endian");
constexpr char kMagic[4] = {'T', 'S', 'T', 'R'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeaderBytes = 4 + 4 + 8 + 4 + 4 + 16 + 8 + 5 * 8 + 8;
constexpr size_t kPixelBytes = 7 * 8;

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

struct Reader {
  std::string_view in;
  size_t pos = 0;
  template <class T>
  T get() {
    T v;
    std::memcpy(&v, in.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
};

}  // namespace

std::string encode_tile_result(const TileResult& r, int level) {
  const TileRect& rect = r.film.rect();
  const RenderCounters& c = r.film.counters;
  std::string raw;
  raw.reserve(kHeaderBytes + size_t(rect.area()) * kPixelBytes + 32);
  raw.append(kMagic, 4);
  put(raw, kVersion);
  put(raw, r.job_id);
  put(raw, r.tile);
  put(raw, r.pass);
  for (int v : {rect.x0, rect.y0, rect.x1, rect.y1}) put(raw, int32_t(v));
  put(raw, r.sample_begin);
  put(raw, r.sample_end);
  for (uint64_t v : {c.samples, c.camera_rays, c.bounce_rays, c.shadow_rays, c.nonfinite}) put(raw, v);
  put(raw, r.seconds);
  for (const PixelSums& px : r.film.pixels()) {
    for (double v : px.sum) put(raw, v);
    for (double v : px.sum_sq) put(raw, v);
    put(raw, uint64_t(px.count));
  }
  Sha256Digest digest = sha256(raw);
  raw.append(reinterpret_cast<const char*>(digest.data()), digest.size());
  if (level == kUncompressed) return raw;

  std::string out(ZSTD_compressBound(raw.size()), '\0');
  size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), level);
  out.resize(ZSTD_isError(n) ? 0 : n);  // compressBound makes an error impossible
  return out;
}

namespace {

// The uncompressed size of concatenated zstd frames (they decode as one: an encoder may compress
// the parts separately), or an error if a frame is malformed, does not state its size, or the total
// exceeds what `max_pixels` allows.
bool decompressed_size(std::string_view bytes, unsigned long long& size, std::string& error, int64_t max_pixels) {
  const unsigned long long max_size = kHeaderBytes + 32 + (unsigned long long)max_pixels * kPixelBytes;
  size = 0;
  for (size_t pos = 0; pos < bytes.size();) {
    const unsigned long long n = ZSTD_getFrameContentSize(bytes.data() + pos, bytes.size() - pos);
    const size_t frame = ZSTD_findFrameCompressedSize(bytes.data() + pos, bytes.size() - pos);
    if (n == ZSTD_CONTENTSIZE_ERROR || n == ZSTD_CONTENTSIZE_UNKNOWN || ZSTD_isError(frame)) {
      error = "tile result: not zstd frames with known sizes";
      return false;
    }
    size += n;
    if (size > max_size) break;
    pos += frame;
  }
  if (size < kHeaderBytes + 32 || size > max_size) {
    error = "tile result: implausible size " + std::to_string(size) + " bytes";
    return false;
  }
  return true;
}

// The uncompressed bytes of a compressed result, into `raw`.
bool decompress(std::string_view bytes, std::string& raw, std::string& error, int64_t max_pixels) {
  unsigned long long size = 0;
  if (!decompressed_size(bytes, size, error, max_pixels)) return false;
  raw.resize(size_t(size));
  size_t n = ZSTD_decompress(raw.data(), raw.size(), bytes.data(), bytes.size());
  if (ZSTD_isError(n) || n != raw.size()) {
    error = std::string("tile result: corrupt or truncated: ") + (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short");
    return false;
  }
  return true;
}

}  // namespace

bool decode_tile_result(std::string_view bytes, TileResult& out, std::string& error, int64_t max_pixels) {
  std::string decompressed;
  const bool stored = bytes.size() >= 4 && std::memcmp(bytes.data(), kMagic, 4) == 0;
  if (!stored && !decompress(bytes, decompressed, error, max_pixels)) return false;
  const std::string_view raw = stored ? bytes : std::string_view(decompressed);
  if (raw.size() < kHeaderBytes + 32) {
    error = "tile result: implausible size " + std::to_string(raw.size()) + " bytes";
    return false;
  }
  Sha256Digest digest = sha256(raw.data(), raw.size() - 32);
  if (std::memcmp(digest.data(), raw.data() + raw.size() - 32, 32) != 0) {
    error = "tile result: checksum mismatch";
    return false;
  }
  Reader rd{raw};
  if (std::memcmp(raw.data(), kMagic, 4) != 0) {
    error = "tile result: bad magic";
    return false;
  }
  rd.pos = 4;
  if (uint32_t v = rd.get<uint32_t>(); v != kVersion) {
    error = "tile result: format version " + std::to_string(v) + ", expected " + std::to_string(kVersion);
    return false;
  }
  out.job_id = rd.get<uint64_t>();
  out.tile = rd.get<uint32_t>();
  out.pass = rd.get<uint32_t>();
  TileRect rect;
  rect.x0 = rd.get<int32_t>();
  rect.y0 = rd.get<int32_t>();
  rect.x1 = rd.get<int32_t>();
  rect.y1 = rd.get<int32_t>();
  if (rect.empty() || rect.x0 < 0 || rect.y0 < 0 || rect.area() > max_pixels ||
      raw.size() != kHeaderBytes + 32 + size_t(rect.area()) * kPixelBytes) {
    error = "tile result: pixel data does not match the tile's rectangle";
    return false;
  }
  out.sample_begin = rd.get<uint32_t>();
  out.sample_end = rd.get<uint32_t>();
  out.film.reset(rect);
  RenderCounters& c = out.film.counters;
  for (uint64_t* v : {&c.samples, &c.camera_rays, &c.bounce_rays, &c.shadow_rays, &c.nonfinite}) *v = rd.get<uint64_t>();
  out.seconds = rd.get<double>();
  for (PixelSums& px : out.film.mutable_pixels()) {
    for (double& v : px.sum) v = rd.get<double>();
    for (double& v : px.sum_sq) v = rd.get<double>();
    px.count = rd.get<uint64_t>();
  }
  return true;
}

}  // namespace tessera

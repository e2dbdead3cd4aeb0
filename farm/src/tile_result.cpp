#include "tessera/farm/tile_result.h"

#include "tessera/farm/sha256.h"

#include "result_bytes.h"


#include <array>
#include <bit>
#include <cstring>
#include <type_traits>

namespace tessera {
namespace {

using result_bytes::checksum;
using result_bytes::put;
using result_bytes::Reader;

static_assert(std::endian::native == std::endian::little, "the tile format is little-endian");
constexpr char kMagic[4] = {'T', 'S', 'T', 'R'};
// Version 5 adds the per-pixel state; version 4 the AOV sums; version 3 training records; version 2
// ends in an XXH3-128 checksum; version 1 (results and checkpoints stored by earlier versions) in a
// SHA-256. The checksum guards against corruption in transit and on disk, not against an adversary
// (tokens do that), and SHA-256 was a tenth of the coordinator's time per unit.
constexpr uint32_t kVersion = 5;
constexpr uint32_t kVersionNoState = 4;
constexpr uint32_t kVersionNoAovs = 3;
constexpr uint32_t kVersionNoTraining = 2;
constexpr uint32_t kVersionSha256 = 1;
constexpr size_t kHeaderBytes = 4 + 4 + 8 + 4 + 4 + 16 + 8 + 5 * 8 + 8;
constexpr size_t kPixelBytes = 7 * 8;
constexpr size_t kMaxDigestBytes = sizeof(Sha256Digest);
constexpr size_t kAovBytes = 11 * 8;
static_assert(sizeof(PixelSums) == kPixelBytes && std::is_trivially_copyable_v<PixelSums>,
              "pixel sums are copied to and from the format as they lie in memory");
static_assert(sizeof(AovSums) == kAovBytes && std::is_trivially_copyable_v<AovSums>,
              "AOV sums are copied to and from the format as they lie in memory");

size_t digest_bytes(uint32_t version) { return version == kVersionSha256 ? sizeof(Sha256Digest) : kTileResultDigestBytes; }

}  // namespace

uint64_t max_tile_result_bytes(const TileRect& rect, bool aovs, bool training, bool state) {
  const uint64_t per_pixel = kPixelBytes + (aovs ? kAovBytes : 0) + (state ? kMaxStateBytesPerPixel : 0);
  const uint64_t raw = kHeaderBytes + uint64_t(rect.area()) * per_pixel + 24 + (training ? kMaxTrainingBytes : 0) + kMaxDigestBytes;
  return result_bytes::max_compressed_bytes(raw);
}

std::string encode_tile_result(const TileResult& r, int level) {
  const TileRect& rect = r.film.rect();
  const RenderCounters& c = r.film.counters;
  std::string raw;
  raw.reserve(kHeaderBytes + size_t(rect.area()) * kPixelBytes + kTileResultDigestBytes);
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
  raw.append(reinterpret_cast<const char*>(r.film.pixels().data()), r.film.pixels().size() * kPixelBytes);
  put(raw, uint64_t(r.training.size()));
  raw.append(r.training);
  put(raw, uint64_t(r.film.aovs().size()));
  raw.append(reinterpret_cast<const char*>(r.film.aovs().data()), r.film.aovs().size() * kAovBytes);
  put(raw, uint64_t(r.tile_state.size()));
  raw.append(r.tile_state);
  const auto digest = checksum(raw);
  raw.append(digest.data(), digest.size());
  return result_bytes::compress(std::move(raw), level);
}

namespace {

// The uncompressed bytes of a compressed result, into `raw`, within what `max_pixels` allows.
bool decompress(std::string_view bytes, std::string& raw, std::string& error, int64_t max_pixels) {
  const uint64_t max_size = kHeaderBytes + kMaxDigestBytes +
                            uint64_t(max_pixels) * (kPixelBytes + kAovBytes + kMaxStateBytesPerPixel) + 24 + kMaxTrainingBytes;
  return result_bytes::decompress(bytes, max_size, raw, error, "tile result");
}

// Whether the bytes' trailing checksum (of the version's kind) matches what precedes it.
bool checksum_matches(std::string_view raw, uint32_t version) {
  const size_t n = digest_bytes(version);
  if (raw.size() < kHeaderBytes + n) return false;
  const std::string_view body = raw.substr(0, raw.size() - n), stored = raw.substr(raw.size() - n);
  if (version == kVersionSha256) return std::memcmp(sha256(body).data(), stored.data(), n) == 0;
  return std::memcmp(checksum(body).data(), stored.data(), n) == 0;
}

// Where the sections after the pixel sums lie (each a u64 count and its bytes): training records
// (version 3 on), AOV sums (4 on: none, or one per pixel), per-pixel state (5 on: at most
// kMaxStateBytesPerPixel a pixel). `fit`: they end exactly at `body`, each within its bound.
struct Sections {
  uint64_t training = 0, aov_pixels = 0, state = 0;
  size_t training_at = 0, aovs_at = 0, state_at = 0;
  bool fit = false;
};

Sections sections(std::string_view raw, uint32_t version, size_t pixel_end, size_t body, uint64_t pixels) {
  Sections s;
  size_t at = pixel_end;
  // A section's count, or false when it does not fit before `body` or exceeds `max` units.
  auto count = [&](uint32_t since, uint64_t& n, uint64_t max, size_t unit, size_t& data_at) {
    if (version < since) {
      data_at = at;
      return true;
    }
    if (body < at + 8) return false;
    std::memcpy(&n, raw.data() + at, 8);
    if (n > max || body - (at + 8) < n * unit) return false;
    data_at = at + 8;
    at = data_at + size_t(n * unit);
    return true;
  };
  s.fit = count(kVersionNoAovs, s.training, kMaxTrainingBytes, 1, s.training_at) &&
          count(kVersionNoState, s.aov_pixels, pixels, kAovBytes, s.aovs_at) &&
          count(kVersion, s.state, pixels * kMaxStateBytesPerPixel, 1, s.state_at) &&
          (s.aov_pixels == 0 || s.aov_pixels == pixels) && at == body;
  return s;
}

}  // namespace

bool decode_tile_result(std::string_view bytes, TileResult& out, std::string& error, int64_t max_pixels) {
  // Reused by the thread (a coordinator's HTTP threads decode one result after another), so a
  // result's decompressed bytes are not a fresh allocation each time.
  thread_local std::string decompressed;
  struct KeepSmall {  // (a huge tile's buffer is not kept by every thread)
    std::string& buffer;
    ~KeepSmall() {
      if (buffer.capacity() > (size_t(4) << 20)) std::string().swap(buffer);
    }
  } keep_small{decompressed};
  const bool stored = bytes.size() >= 4 && std::memcmp(bytes.data(), kMagic, 4) == 0;
  if (!stored && !decompress(bytes, decompressed, error, max_pixels)) return false;
  const std::string_view raw = stored ? bytes : std::string_view(decompressed);
  if (raw.size() < kHeaderBytes + kTileResultDigestBytes) {
    error = "tile result: implausible size " + std::to_string(raw.size()) + " bytes";
    return false;
  }
  Reader rd{raw};
  if (std::memcmp(raw.data(), kMagic, 4) != 0) {
    error = "tile result: bad magic";
    return false;
  }
  rd.pos = 4;
  const uint32_t version = rd.get<uint32_t>();
  if (version != kVersion && version != kVersionNoState && version != kVersionNoAovs && version != kVersionNoTraining &&
      version != kVersionSha256) {
    error = "tile result: format version " + std::to_string(version) + ", expected " + std::to_string(kVersion);
    return false;
  }
  if (!checksum_matches(raw, version)) {
    error = "tile result: checksum mismatch";
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
  if (rect.area() > max_pixels) {
    error = "tile result: " + std::to_string(rect.area()) + " pixels, over the limit of " + std::to_string(max_pixels);
    return false;
  }
  const size_t pixel_end = kHeaderBytes + size_t(rect.area()) * kPixelBytes;
  const size_t body = raw.size() - digest_bytes(version);
  const Sections sec = sections(raw, version, pixel_end, body, uint64_t(rect.area()));
  if (rect.empty() || rect.x0 < 0 || rect.y0 < 0 || !sec.fit) {
    error = "tile result: pixel data does not match the tile's rectangle";
    return false;
  }
  out.sample_begin = rd.get<uint32_t>();
  out.sample_end = rd.get<uint32_t>();
  out.film.reset(rect, sec.aov_pixels > 0);
  RenderCounters& c = out.film.counters;
  for (uint64_t* v : {&c.samples, &c.camera_rays, &c.bounce_rays, &c.shadow_rays, &c.nonfinite}) *v = rd.get<uint64_t>();
  out.seconds = rd.get<double>();
  std::memcpy(out.film.mutable_pixels().data(), raw.data() + rd.pos, out.film.pixels().size() * kPixelBytes);
  out.training.assign(raw.data() + sec.training_at, size_t(sec.training));
  if (sec.aov_pixels > 0)
    std::memcpy(out.film.mutable_aovs().data(), raw.data() + sec.aovs_at, size_t(sec.aov_pixels) * kAovBytes);
  out.tile_state.assign(raw.data() + sec.state_at, size_t(sec.state));
  return true;
}

}  // namespace tessera

#include "synthetic_results.h"

#include "tessera/farm/job_scene.h"

#include <zstd.h>

#include <algorithm>

namespace tessera::bench {

namespace {

uint64_t xorshift(uint64_t& rng) {
  rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
  return rng;
}

constexpr size_t kDigestBytes = kTileResultDigestBytes;
constexpr size_t kPixelBytes = 7 * 8;  // tile_result.h: sum[3], sum_sq[3], count

// Where the pixel sums start in a result's uncompressed bytes (after the header, before the digest).
size_t pixels_offset(const std::string& raw, size_t pixels) { return raw.size() - kDigestBytes - pixels * kPixelBytes; }

}  // namespace

std::string SyntheticResults::compress(std::string_view raw) {
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const size_t n = ZSTD_compressCCtx(cctx_.get(), out.data(), out.size(), raw.data(), raw.size(), 1);
  out.resize(ZSTD_isError(n) ? 0 : n);
  return out;
}

const SyntheticResults::Variant& SyntheticResults::variant(const Lease& lease, uint64_t& rng) {
  const uint32_t n = lease.sample_end - lease.sample_begin;
  std::vector<Variant>& pool = variants_[{lease.rect.area(), n}];
  const size_t pick = size_t(xorshift(rng) % kVariants);
  while (pool.size() <= pick) {
    Variant v;
    v.pixels.resize(size_t(lease.rect.area()));
    for (PixelSums& p : v.pixels) {
      for (int c = 0; c < 3; ++c) {
        const double x = double(xorshift(rng) >> 11) * 0x1p-53;
        p.sum[c] = x * n;
        p.sum_sq[c] = x * x * n;
      }
      p.count = n;
    }
    // The pixels' bytes as the real encoder lays them out.
    begin_tile_result(lease, scratch_);
    std::copy(v.pixels.begin(), v.pixels.end(), scratch_.film.mutable_pixels().begin());
    const std::string raw = encode_tile_result(scratch_, kUncompressed);
    v.frame = compress(std::string_view(raw).substr(pixels_offset(raw, v.pixels.size()), v.pixels.size() * kPixelBytes));
    pool.push_back(std::move(v));
  }
  return pool[pick];
}

std::string SyntheticResults::encode(const Lease& lease, uint64_t& rng) {
  const Variant& v = variant(lease, rng);
  begin_tile_result(lease, scratch_);
  scratch_.seconds = 0.001;
  std::copy(v.pixels.begin(), v.pixels.end(), scratch_.film.mutable_pixels().begin());
  const uint64_t samples = uint64_t(lease.rect.area()) * (lease.sample_end - lease.sample_begin);
  scratch_.film.counters.samples = samples;
  scratch_.film.counters.camera_rays = samples;
  // The real format's bytes (and digest), uncompressed; then its header and digest are compressed
  // around the variant's ready frame of pixels.
  const std::string raw = encode_tile_result(scratch_, kUncompressed);
  const size_t header = pixels_offset(raw, v.pixels.size());
  std::string out = compress(std::string_view(raw).substr(0, header));
  out.reserve(out.size() + v.frame.size() + 64);
  out += v.frame;
  out += compress(std::string_view(raw).substr(raw.size() - kDigestBytes));
  return out;
}

}  // namespace tessera::bench

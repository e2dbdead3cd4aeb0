// The farm's work result on the wire: the pixel sums of one tile x sample pass.
//
// Layout (little-endian; the whole of it zstd-compressed, as one frame or several concatenated, or
// stored as it is: see kUncompressed):
//   "TSTR" magic, u32 format version,
//   u64 job id, u32 tile index, u32 pass index, i32 x0 y0 x1 y1, u32 sample_begin, sample_end,
//   u64 samples, camera_rays, bounce_rays, shadow_rays, nonfinite, f64 render seconds,
//   per pixel (row-major over the rect): f64 sum[3], f64 sum_sq[3], u64 count,
//   u64 n, n bytes of training records (guiding/tree_io.h; n = 0 unless the unit trains a guide),
//   u64 m, m per-pixel AOV sums (render/aov.h: f64 albedo[3], normal[3], depth, half_sum[3], u64
//   half_count; m is 0, or the rect's area for a job that is denoised),
//   u64 s, s bytes of per-pixel state (PassSpec::tile_state: an sppm gather's SppmPixels; else 0),
//   16-byte XXH3-128 checksum of everything above (big-endian canonical form). Format version 4,
//   still read, has no state; version 3 no AOV sums; version 2 no training records either; version 1 also ended in a
//   32-byte SHA-256 instead.
// The coordinator adds decoded tiles to its Film exactly as render() does, so the stitched image is
// bit-identical to a local render (render/renderer.h).
#pragma once

#include "tessera/render/film.h"

#include <cstdint>
#include <string>
#include <string_view>

namespace tessera {

struct TileResult {
  uint64_t job_id = 0;
  uint32_t tile = 0, pass = 0;
  uint32_t sample_begin = 0, sample_end = 0;
  double seconds = 0;  // time the worker spent rendering it
  FilmTile film;       // rect, sums and counters
  std::string training;  // a guide-training unit's records (guiding/tree_io.h); else empty
  std::string tile_state;  // the per-pixel state the tile's next pass starts from; else empty
};

/// Per-pixel state larger than this per pixel is refused (sppm's is 32 bytes).
inline constexpr size_t kMaxStateBytesPerPixel = 64;

/// Training records larger than this are refused (a unit's records are far smaller than its guide).
inline constexpr size_t kMaxTrainingBytes = size_t(64) << 20;

/// Bytes of the checksum that ends a result's uncompressed bytes.
inline constexpr size_t kTileResultDigestBytes = 16;

/// The `level` that stores a result uncompressed (it starts with the magic, not a zstd frame): for
/// bytes written locally and often (the coordinator's checkpoints), where compressing would cost
/// more than the bytes it saves.
inline constexpr int kUncompressed = -1000;

/// The most bytes a result of a unit over `rect` can take as sent (compressed or not): its sums,
/// the AOV sums with `aovs`, training records with `training` (at most kMaxTrainingBytes) and
/// per-pixel state with `state`. What the coordinator reads of an upload for that unit.
uint64_t max_tile_result_bytes(const TileRect& rect, bool aovs, bool training, bool state = false);

/// Encodes (and compresses) a result; `level` is zstd's compression level, or kUncompressed. Pixel
/// sums are noise in their low bits: level 1 makes them as small as level 3 does (within 0.2%) in a
/// third of the time.
std::string encode_tile_result(const TileResult& result, int level = 1);

/// Decodes and verifies bytes (compressed or not). False with `error` set on anything malformed:
/// bad compression, wrong magic or version, a size that does not match the rect, a checksum
/// mismatch, a rect larger than `max_pixels`.
[[nodiscard]] bool decode_tile_result(std::string_view bytes, TileResult& out, std::string& error,
                                      int64_t max_pixels = int64_t(1) << 24);

}  // namespace tessera

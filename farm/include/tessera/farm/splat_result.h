// A Paths unit's result on the wire (sequence/pass_program.h): what its range of light paths added
// to which pixels of the window, sparse (sequence/splat_sums.h), with the records it feeds an
// artifact with. Tile units' results are tile_result.h's; the first four bytes (compressed or not)
// tell which a body is.
//
// Layout (little-endian; the whole of it zstd-compressed, as one frame or several concatenated,
// or stored as it is):
//   "TSPL" magic, u32 format version 1,
//   u64 job id, u32 pass, u32 unit (its index in the pass), u64 path_begin, path_end,
//   i32 window x0 y0 x1 y1, u64 samples, camera_rays, bounce_rays, shadow_rays, nonfinite,
//   f64 render seconds,
//   u64 n, n splats of (u32 pixel, row-major in the window; f64 r, g, b),
//   u64 m, m bytes of records,
//   16-byte XXH3-128 checksum of everything above (big-endian canonical form).
#pragma once

#include "tessera/sequence/splat_sums.h"

#include <cstdint>
#include <string>
#include <string_view>

namespace tessera {

struct SplatResult {
  uint64_t job_id = 0;
  uint32_t pass = 0, unit = 0;
  uint64_t path_begin = 0, path_end = 0;
  double seconds = 0;
  SplatSums splats;     // window, splats, counters
  std::string records;  // for the artifact the unit feeds (empty if it feeds none)
};

/// A light path adds at most this many splats (one per vertex a camera connection starts from),
/// or a result sums its paths' splats per pixel (a light tracer's: one splat per window pixel at
/// most): what bounds an upload of a range of paths over a window.
inline constexpr uint64_t kMaxSplatsPerPath = 64;
inline uint64_t max_splats(uint64_t paths, uint64_t window_pixels) {
  if (paths == 0) return 0;
  return paths * kMaxSplatsPerPath > window_pixels ? paths * kMaxSplatsPerPath : window_pixels;
}

/// The most bytes a result of `paths` light paths over a window of `window_pixels` can take as
/// sent, with records of at most `max_record_bytes`.
uint64_t max_splat_result_bytes(uint64_t paths, uint64_t max_record_bytes, uint64_t window_pixels = 0);

/// Whether `bytes` (compressed or not) are a splat result rather than a tile result.
bool is_splat_result(std::string_view bytes);

/// Encodes (and compresses, zstd `level`; kUncompressed of tile_result.h stores) a result.
std::string encode_splat_result(const SplatResult& result, int level = 1);

/// Decodes and verifies bytes. False with `error` set on anything malformed: bad compression,
/// magic, version or checksum, a size that does not match its counts, a pixel outside the window,
/// more splats than max_splats(), a window of more than `max_pixels`.
[[nodiscard]] bool decode_splat_result(std::string_view bytes, SplatResult& out, std::string& error,
                                       int64_t max_pixels = int64_t(1) << 28);

}  // namespace tessera

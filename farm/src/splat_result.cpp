#include "tessera/farm/splat_result.h"

#include "tessera/farm/tile_result.h"

#include "result_bytes.h"

#include <zstd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace tessera {
namespace {

using result_bytes::checksum;
using result_bytes::put;
using result_bytes::Reader;

constexpr char kMagic[4] = {'T', 'S', 'P', 'L'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeaderBytes = 4 + 4 + 8 + 4 + 4 + 8 + 8 + 16 + 5 * 8 + 8;
constexpr size_t kSplatBytes = 4 + 3 * 8;
constexpr size_t kDigestBytes = result_bytes::kChecksumBytes;

// The uncompressed bytes of `bytes` (into `raw`, or a view of `bytes` when stored as they are),
// within `max_size`.
bool uncompressed(std::string_view bytes, std::string& raw, std::string_view& view, uint64_t max_size, std::string& error) {
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kMagic, 4) == 0) {
    view = bytes;
    return true;
  }
  if (!result_bytes::decompress(bytes, max_size, raw, error, "splat result")) return false;
  view = raw;
  return true;
}

}  // namespace

uint64_t max_splat_result_bytes(uint64_t paths, uint64_t max_record_bytes, uint64_t window_pixels) {
  const uint64_t raw = kHeaderBytes + 8 + max_splats(paths, window_pixels) * kSplatBytes + 8 + max_record_bytes + kDigestBytes;
  return result_bytes::max_compressed_bytes(raw);
}

bool is_splat_result(std::string_view bytes) {
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kMagic, 4) == 0) return true;
  // Compressed: the first four bytes it decompresses to (a stream stops once they are out). They
  // come out with the frame's first block, which can take up to a block's size (128 KiB) of input.
  char head[4];
  ZSTD_DCtx* d = ZSTD_createDCtx();
  ZSTD_inBuffer in{bytes.data(), std::min<size_t>(bytes.size(), ZSTD_BLOCKSIZE_MAX + 4096), 0};
  ZSTD_outBuffer out{head, sizeof(head), 0};
  for (int step = 0; step < 64 && out.pos < out.size && in.pos < in.size; ++step)
    if (ZSTD_isError(ZSTD_decompressStream(d, &out, &in))) break;
  ZSTD_freeDCtx(d);
  return out.pos == sizeof(head) && std::memcmp(head, kMagic, 4) == 0;
}

std::string encode_splat_result(const SplatResult& r, int level) {
  const SplatSums& s = r.splats;
  const RenderCounters& c = s.counters;
  std::string raw;
  raw.reserve(kHeaderBytes + 16 + s.size() * kSplatBytes + r.records.size() + kDigestBytes);
  raw.append(kMagic, 4);
  put(raw, kVersion);
  put(raw, r.job_id);
  put(raw, r.pass);
  put(raw, r.unit);
  put(raw, r.path_begin);
  put(raw, r.path_end);
  for (int v : {s.window.x0, s.window.y0, s.window.x1, s.window.y1}) put(raw, int32_t(v));
  for (uint64_t v : {c.samples, c.camera_rays, c.bounce_rays, c.shadow_rays, c.nonfinite}) put(raw, v);
  put(raw, r.seconds);
  put(raw, uint64_t(s.size()));
  for (size_t i = 0; i < s.size(); ++i) {
    put(raw, s.pixel[i]);
    for (double v : s.value[i]) put(raw, v);
  }
  put(raw, uint64_t(r.records.size()));
  raw.append(r.records);
  const auto digest = checksum(raw);
  raw.append(digest.data(), digest.size());
  return result_bytes::compress(std::move(raw), level);
}

namespace {

// The header fields, checked against the bytes' size; false with `error` set.
bool read_header(Reader& rd, SplatResult& out, std::string& error, int64_t max_pixels) {
  rd.pos = 4;
  if (const uint32_t version = rd.get<uint32_t>(); version != kVersion) {
    error = "splat result: format version " + std::to_string(version) + ", expected " + std::to_string(kVersion);
    return false;
  }
  out.job_id = rd.get<uint64_t>();
  out.pass = rd.get<uint32_t>();
  out.unit = rd.get<uint32_t>();
  out.path_begin = rd.get<uint64_t>();
  out.path_end = rd.get<uint64_t>();
  TileRect w;
  w.x0 = rd.get<int32_t>();
  w.y0 = rd.get<int32_t>();
  w.x1 = rd.get<int32_t>();
  w.y1 = rd.get<int32_t>();
  if (w.empty() || w.x0 < 0 || w.y0 < 0 || w.area() > max_pixels || out.path_end < out.path_begin) {
    error = "splat result: a window of " + std::to_string(w.area()) + " pixels or a range of paths out of bounds";
    return false;
  }
  out.splats.reset(w);
  RenderCounters& c = out.splats.counters;
  for (uint64_t* v : {&c.samples, &c.camera_rays, &c.bounce_rays, &c.shadow_rays, &c.nonfinite}) *v = rd.get<uint64_t>();
  out.seconds = rd.get<double>();
  return true;
}

}  // namespace

bool decode_splat_result(std::string_view bytes, SplatResult& out, std::string& error, int64_t max_pixels) {
  std::string buffer;
  std::string_view raw;
  // (The range of paths is not known before the header: the size is bounded by the largest range.)
  if (!uncompressed(bytes, buffer, raw, max_splat_result_bytes(uint64_t(1) << 24, uint64_t(64) << 20, uint64_t(max_pixels)), error))
    return false;
  if (raw.size() < kHeaderBytes + 16 + kDigestBytes || std::memcmp(raw.data(), kMagic, 4) != 0) {
    error = "splat result: bad magic or implausible size";
    return false;
  }
  const std::string_view body = raw.substr(0, raw.size() - kDigestBytes);
  if (std::memcmp(checksum(body).data(), raw.data() + body.size(), kDigestBytes) != 0) {
    error = "splat result: checksum mismatch";
    return false;
  }
  Reader rd{raw};
  if (!read_header(rd, out, error, max_pixels)) return false;
  const uint64_t n = rd.get<uint64_t>(), area = uint64_t(out.splats.window.area());
  if (n > max_splats(out.path_end - out.path_begin, area) || body.size() < rd.pos + n * kSplatBytes + 8) {
    error = "splat result: " + std::to_string(n) + " splats do not fit its paths or its size";
    return false;
  }
  out.splats.pixel.resize(size_t(n));
  out.splats.value.resize(size_t(n));
  for (uint64_t i = 0; i < n; ++i) {
    out.splats.pixel[i] = rd.get<uint32_t>();
    for (double& v : out.splats.value[i]) v = rd.get<double>();
    if (out.splats.pixel[i] >= area || !std::isfinite(out.splats.value[i][0] + out.splats.value[i][1] + out.splats.value[i][2])) {
      error = "splat result: splat " + std::to_string(i) + " outside the window or not finite";
      return false;
    }
  }
  const uint64_t m = rd.get<uint64_t>();
  if (m > uint64_t(64) << 20 || body.size() != rd.pos + m) {
    error = "splat result: its records do not match its size";
    return false;
  }
  out.records.assign(body.data() + rd.pos, size_t(m));
  return true;
}

}  // namespace tessera

#include "tessera/farm/sample_counts.h"

#include <zstd.h>

#include <bit>
#include <cstring>
#include <stdexcept>

namespace tessera {

static_assert(std::endian::native == std::endian::little, "sample counts are stored little-endian");

std::string encode_sample_counts(const std::vector<uint32_t>& counts) {
  std::vector<uint16_t> raw(counts.size());
  for (size_t i = 0; i < counts.size(); ++i) {
    if (counts[i] > UINT16_MAX) throw std::invalid_argument("sample count " + std::to_string(counts[i]) + " above 65535");
    raw[i] = uint16_t(counts[i]);
  }
  const size_t bytes = raw.size() * sizeof(uint16_t);
  std::string out(ZSTD_compressBound(bytes), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), bytes, 3);
  out.resize(ZSTD_isError(n) ? 0 : n);  // (compressBound makes an error impossible)
  return out;
}

bool decode_sample_counts(std::string_view bytes, size_t pixels, std::vector<uint32_t>& out, std::string& error) {
  const size_t expected = pixels * sizeof(uint16_t);
  if (ZSTD_getFrameContentSize(bytes.data(), bytes.size()) != expected) {
    error = "sample counts: not a zstd frame of " + std::to_string(pixels) + " counts";
    return false;
  }
  std::vector<uint16_t> raw(pixels);
  const size_t n = ZSTD_decompress(raw.data(), expected, bytes.data(), bytes.size());
  if (ZSTD_isError(n) || n != expected) {
    error = "sample counts: corrupt or truncated";
    return false;
  }
  out.assign(raw.begin(), raw.end());
  return true;
}

}  // namespace tessera

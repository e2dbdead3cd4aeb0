#include "result_bytes.h"

#include "tessera/farm/tile_result.h"

#include <xxhash.h>
#include <zstd.h>

namespace tessera::result_bytes {

std::array<char, kChecksumBytes> checksum(std::string_view bytes) {
  XXH128_canonical_t c;
  XXH128_canonicalFromHash(&c, XXH3_128bits(bytes.data(), bytes.size()));
  std::array<char, kChecksumBytes> out;
  std::memcpy(out.data(), c.digest, out.size());
  return out;
}

uint64_t max_compressed_bytes(uint64_t raw_bytes) {
  return ZSTD_compressBound(size_t(raw_bytes)) + raw_bytes / 64 + (uint64_t(64) << 10);
}

std::string compress(std::string raw, int level) {
  if (level == kUncompressed) return raw;
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), level);
  out.resize(ZSTD_isError(n) ? 0 : n);  // compressBound makes an error impossible
  return out;
}

bool decompress(std::string_view bytes, uint64_t max_size, std::string& raw, std::string& error, const char* what) {
  uint64_t size = 0;
  for (size_t pos = 0; pos < bytes.size();) {
    const unsigned long long n = ZSTD_getFrameContentSize(bytes.data() + pos, bytes.size() - pos);
    const size_t frame = ZSTD_findFrameCompressedSize(bytes.data() + pos, bytes.size() - pos);
    if (n == ZSTD_CONTENTSIZE_ERROR || n == ZSTD_CONTENTSIZE_UNKNOWN || ZSTD_isError(frame)) {
      error = std::string(what) + ": not zstd frames of known sizes";
      return false;
    }
    if ((size += n) > max_size) {
      error = std::string(what) + ": more than " + std::to_string(max_size) + " bytes once decompressed";
      return false;
    }
    pos += frame;
  }
  raw.resize(size_t(size));
  const size_t n = ZSTD_decompress(raw.data(), raw.size(), bytes.data(), bytes.size());
  if (ZSTD_isError(n) || n != raw.size()) {
    error = std::string(what) + ": corrupt or truncated: " + (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short");
    return false;
  }
  return true;
}

}  // namespace tessera::result_bytes

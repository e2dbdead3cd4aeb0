#include "tessera/sequence/guide_artifact.h"

#include "tessera/guiding/tree_io.h"

#include <zstd.h>

namespace tessera {

std::string encode_guide(const SpatialTree& tree) {
  const std::string raw = write_tree(tree);
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 1);
  out.resize(ZSTD_isError(n) ? 0 : n);  // (compressBound makes an error impossible)
  return out;
}

bool decode_guide(std::string_view bytes, SpatialTree& out, std::string& error, size_t max_bytes) {
  const unsigned long long size = ZSTD_getFrameContentSize(bytes.data(), bytes.size());
  if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN || size > max_bytes) {
    error = "guide: not a zstd frame of a known size up to " + std::to_string(max_bytes) + " bytes";
    return false;
  }
  std::string raw(size_t(size), '\0');
  const size_t n = ZSTD_decompress(raw.data(), raw.size(), bytes.data(), bytes.size());
  if (ZSTD_isError(n) || n != raw.size()) {
    error = "guide: corrupt or truncated";
    return false;
  }
  return read_tree(raw, out, error);
}

}  // namespace tessera

// A guided job's learned SD-tree as the farm hands it out: the coordinator makes one after every
// training pass (from the tree before it and every tile's training records, guiding/tree_io.h),
// stores it under its SHA-256 like a bundle, and names it in the leases that render with it;
// workers fetch it once (GET /api/v1/guides/HASH), check the hash and keep it cached.
#pragma once

#include "tessera/guiding/spatial_tree.h"

#include <string>
#include <string_view>

namespace tessera {

/// The tree's bytes (write_tree, zstd-compressed).
std::string encode_guide(const SpatialTree& tree);
/// False with `error` set on anything malformed, or a tree above `max_bytes` uncompressed.
[[nodiscard]] bool decode_guide(std::string_view bytes, SpatialTree& out, std::string& error,
                                size_t max_bytes = size_t(1) << 30);

}  // namespace tessera

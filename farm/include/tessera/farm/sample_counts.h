// An adaptive pass's per-pixel sample counts as the coordinator stores them: u16 little-endian per
// pixel, row-major over the film window, zstd-compressed (a pass that is uniform, or nearly so,
// shrinks to a few bytes). A pixel takes at most AdaptiveSettings::max_factor times a pass's 64
// samples, well within 16 bits.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tessera {

/// Throws std::invalid_argument for a count above 65535.
std::string encode_sample_counts(const std::vector<uint32_t>& counts);
/// False with `error` set when the bytes are not `pixels` counts so encoded.
[[nodiscard]] bool decode_sample_counts(std::string_view bytes, size_t pixels, std::vector<uint32_t>& out,
                                        std::string& error);

}  // namespace tessera

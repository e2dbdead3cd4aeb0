// The simulated workers' tile results: bytes of a real pass's size and entropy, in the real format
// (zstd level 1, as tessera-worker sends), made for a fraction of what compressing each would cost,
// so the load generator measures the coordinator rather than itself.
#pragma once

#include "tessera/farm/protocol.h"
#include "tessera/farm/tile_result.h"

#include <zstd.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace tessera::bench {

class SyntheticResults {
 public:
  /// The encoded result for exactly the leased unit: its own header and digest, pixel sums from one
  /// of a few variants per tile shape and sample count, each variant compressed once. The three
  /// parts are separate zstd frames, which decode as one.
  std::string encode(const Lease& lease, uint64_t& rng);

 private:
  struct Variant {
    std::vector<PixelSums> pixels;
    std::string frame;  // the pixels' bytes, compressed
  };
  const Variant& variant(const Lease& lease, uint64_t& rng);
  std::string compress(std::string_view raw);

  static constexpr size_t kVariants = 8;
  std::map<std::pair<int64_t, uint32_t>, std::vector<Variant>> variants_;  // by (pixels, samples)
  TileResult scratch_;
  // One compression context for every frame (ZSTD_compress would set up a new one each call).
  std::unique_ptr<ZSTD_CCtx, size_t (*)(ZSTD_CCtx*)> cctx_{ZSTD_createCCtx(), ZSTD_freeCCtx};
};

}  // namespace tessera::bench

// An adaptive job's sample plans on the coordinator (render/adaptive.h).
//
// The passes from the first that may adapt (one beginning at AdaptiveSettings::uniform_fraction of
// the budget or later) open one at a time. At each one's barrier every tile has every earlier pass
// and none has a later one, so the film is exactly the one render() plans that pass from, and the
// pass's per-pixel counts are decided from it as render() decides them. They are stored before any
// unit of the pass is leased: a restarted coordinator reads them back instead of deciding again,
// since its film, rebuilt from checkpoints, may already hold later passes.
//
// Memory: the per-pixel first index and count of the latest decided pass (8 bytes a pixel), and
// each decided pass's samples per tile.
#pragma once

#include "tessera/render/adaptive.h"
#include "tessera/render/film.h"

#include <cstdint>
#include <string>
#include <vector>

namespace tessera::server {

class PassPlans {
 public:
  /// `passes`/`pass_begin`: the job's pass schedule; `tiles`: its tiles, row-major.
  PassPlans(const TileRect& window, std::vector<TileRect> tiles, std::vector<uint32_t> passes,
            std::vector<uint32_t> pass_begin, uint32_t spp, AdaptiveSettings settings = {});

  /// Whether pass `pass` opens only at its barrier, with its counts decided there.
  bool at_barrier(uint32_t pass) const { return pass >= first_barrier_ && pass < passes_.size(); }
  /// The first such pass (the number of passes when none is).
  uint32_t first_barrier() const { return first_barrier_; }
  /// Whether the pass's counts are known (always, for a pass before the first barrier).
  bool decided(uint32_t pass) const { return pass < first_barrier_ + decided_passes(); }

  /// Decides the next barrier pass (`pass` must be it) from `film`, the passes before it.
  void decide(uint32_t pass, const Film& film);
  /// Restores the next barrier pass's stored counts (row-major over the window). False with
  /// `error` when they cannot be that pass's: wrong size, total, or a count above the cap.
  [[nodiscard]] bool restore(uint32_t pass, std::vector<uint32_t> counts, std::string& error);
  /// Counts of the latest decided pass (row-major over the window): what is stored.
  const std::vector<uint32_t>& latest_counts() const { return count_; }

  /// The samples of tile `tile` in decided barrier pass `pass` (only the latest decided pass: the
  /// earlier ones are complete before it is decided).
  PassSamples tile_samples(uint32_t tile, uint32_t pass) const;
  /// Samples (over the tile's pixels) of tile `tile` in decided barrier pass `pass`.
  uint64_t samples(uint32_t tile, uint32_t pass) const { return tile_totals_[pass - first_barrier_][tile]; }
  /// Whether `film`'s per-pixel counts are exactly what the plan gives tile `tile` in `pass`.
  bool matches(uint32_t tile, uint32_t pass, const FilmTile& film) const;
  /// Frees the per-pixel counts of a job that has ended (no pass is decided or leased again).
  void release_pixels() {
    std::vector<uint32_t>().swap(first_);
    std::vector<uint32_t>().swap(count_);
  }

 private:
  uint32_t decided_passes() const { return uint32_t(tile_totals_.size()); }
  /// Each pixel's first sample index in the next barrier pass.
  std::vector<uint32_t> next_first() const;
  void adopt(std::vector<uint32_t> counts);

  TileRect window_;
  std::vector<TileRect> tiles_;
  std::vector<uint32_t> passes_, pass_begin_;
  uint32_t spp_;
  AdaptiveSettings settings_;
  uint32_t first_barrier_;
  std::vector<uint32_t> first_, count_;           // the latest decided pass, per pixel
  std::vector<std::vector<uint64_t>> tile_totals_;  // per decided barrier pass, per tile
};

}  // namespace tessera::server

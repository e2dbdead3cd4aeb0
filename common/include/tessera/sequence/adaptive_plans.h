// An adaptive render's sample plans (render/adaptive.h), pass by pass.
//
// The adaptive passes (PassSpec::adaptive) open one at a time. At each one's barrier every tile has
// every earlier pass and none has a later one, so the film is exactly the passes before it, and
// the pass's per-pixel counts are decided from it: the same counts for a local render and on any
// farm. A coordinator stores them before any unit of the pass is leased and, restarted, reads them
// back instead of deciding again, since its film, rebuilt from checkpoints, may already hold later
// passes.
//
// Memory: the per-pixel first index and count of the latest decided pass (8 bytes a pixel), and
// each decided pass's samples per tile.
#pragma once

#include "tessera/render/adaptive.h"
#include "tessera/render/film.h"
#include "tessera/sequence/pass_program.h"

#include <cstdint>
#include <string>
#include <vector>

namespace tessera {

class AdaptivePlans {
 public:
  /// `tiles`: the window's tiles, row-major; `program`: its adaptive passes are planned here.
  AdaptivePlans(const TileRect& window, std::vector<TileRect> tiles, const PassProgram& program);

  /// Whether pass `pass` is adaptive (its counts are decided at its barrier).
  bool adaptive(uint32_t pass) const { return pass < adaptive_.size() && adaptive_[pass]; }
  /// Whether the pass's counts are known (always, for a pass that is not adaptive).
  bool decided(uint32_t pass) const;

  /// Decides the next adaptive pass (`pass` must be it) from `film`, the passes before it.
  void decide(uint32_t pass, const Film& film);
  /// Restores the next adaptive pass's stored counts (row-major over the window). False with
  /// `error` when they cannot be that pass's: wrong size, total, or a count above the cap.
  [[nodiscard]] bool restore(uint32_t pass, std::vector<uint32_t> counts, std::string& error);
  /// Counts of the latest decided pass (row-major over the window): what a coordinator stores.
  const std::vector<uint32_t>& latest_counts() const { return count_; }

  /// Whether `pass` is the latest decided pass (the only one whose per-pixel counts are kept: the
  /// earlier ones are complete before it is decided).
  bool is_latest(uint32_t pass) const { return !decided_.empty() && decided_.back() == pass && !count_.empty(); }
  /// The samples of tile `tile` in the latest decided pass `pass`.
  PassSamples tile_samples(uint32_t tile, uint32_t pass) const;
  /// Samples (over the tile's pixels) of tile `tile` in decided adaptive pass `pass`.
  uint64_t samples(uint32_t tile, uint32_t pass) const;
  /// Whether `film`'s per-pixel counts are exactly what the plan gives tile `tile` in `pass`.
  bool matches(uint32_t tile, uint32_t pass, const FilmTile& film) const;
  /// Frees the per-pixel counts of a render that has ended.
  void release_pixels() {
    std::vector<uint32_t>().swap(first_);
    std::vector<uint32_t>().swap(count_);
  }

 private:
  /// Each pixel's first sample index in the next adaptive pass.
  std::vector<uint32_t> next_first() const;
  void adopt(uint32_t pass, std::vector<uint32_t> counts);

  TileRect window_;
  std::vector<TileRect> tiles_;
  std::vector<PassSpec> passes_;
  uint32_t spp_;
  AdaptiveSettings settings_;
  std::vector<bool> adaptive_;                      // per pass
  std::vector<uint32_t> decided_;                   // adaptive passes decided, in order
  std::vector<uint32_t> first_, count_;             // the latest decided pass, per pixel
  std::vector<std::vector<uint64_t>> tile_totals_;  // per decided pass, per tile
};

}  // namespace tessera

// A toy technique for the pass sequencer's tests: no scene and no rays, every value a hash of
// (pixel or path, sample index, seed), so any schedule of its units must give the same bits. It
// has what the next techniques need: Tile units and Paths units (splatting anywhere in the
// window), an artifact made from the Paths units' records in an order-dependent way (floating-point
// sums, as a photon map's would be), per-pixel state carried from a tile's pass to its next, and
// adaptive passes.
#pragma once

#include "tessera/sequence/local_driver.h"
#include "tessera/sequence/pass_sequencer.h"

#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace tessera::test {

inline uint64_t toy_mix(uint64_t x) {  // splitmix64's finaliser
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// A heavy-tailed positive value: mostly small, now and then large (a firefly). A double with
/// every bit of its mantissa in use, so that sums of a few of them depend on their order (sums of
/// floats in doubles would be exact, and would hide an order that is not fixed).
inline double toy_value(uint64_t a, uint64_t b, uint32_t seed) {
  const double u = double(toy_mix(toy_mix(a) ^ (b * 0xD6E8FEB86659FD93ull) ^ seed) >> 11) * 0x1p-53;
  return 0.2 / std::sqrt(u + 1e-3);
}

inline constexpr size_t kToyBins = 8;

/// The toy's artifact: a weight per bin, which later units multiply their values by.
class ToyMap final : public Artifact {
 public:
  explicit ToyMap(std::vector<double> bins) : bins(std::move(bins)) {}
  std::string encode() const override {
    return std::string(reinterpret_cast<const char*>(bins.data()), bins.size() * sizeof(double));
  }
  size_t memory_bytes() const override { return bins.size() * sizeof(double); }
  std::vector<double> bins;
};

inline std::string toy_records(const std::vector<double>& sums) {
  return std::string(reinterpret_cast<const char*>(sums.data()), sums.size() * sizeof(double));
}

inline std::vector<double> toy_decode(std::string_view bytes) {
  std::vector<double> v(bytes.size() / sizeof(double));
  std::memcpy(v.data(), bytes.data(), v.size() * sizeof(double));
  return v;
}

/// Iteration 0: every bin 1. Iteration i: half the previous weights plus half the bins' share of
/// the records' sums, the records added in unit order (floating-point sums: order matters).
class ToyBuilder final : public ArtifactBuilder {
 public:
  std::shared_ptr<const Artifact> build(uint32_t iteration) override {
    std::vector<double> bins(kToyBins, 1.0);
    if (iteration > 0) {
      std::vector<double> sums(kToyBins, 0.0);
      for (const auto& [unit, r] : held_)
        for (size_t b = 0; b < kToyBins; ++b) sums[b] += r[b];
      double total = 0;
      for (double s : sums) total += s;
      for (size_t b = 0; b < kToyBins; ++b)
        bins[b] = 0.5 * latest_->bins[b] + (total > 0 ? 0.5 * sums[b] * double(kToyBins) / total : 0.5);
    }
    held_.clear();
    made_ = int64_t(iteration);
    latest_ = std::make_shared<const ToyMap>(bins);
    ++builds;
    built.push_back(latest_->encode());
    return latest_;
  }
  bool check_records(uint32_t iteration, std::string_view records, std::string& error) const override {
    if (int64_t(iteration) != made_ + 1 || records.size() != kToyBins * sizeof(double)) {
      error = "toy records that do not fit";
      return false;
    }
    return true;
  }
  void add_records(uint32_t, uint64_t unit, std::string_view records) override { held_[unit] = toy_decode(records); }
  std::shared_ptr<const Artifact> decode(std::string_view bytes, std::string& error) const override {
    if (bytes.size() != kToyBins * sizeof(double)) {
      error = "not a toy map";
      return nullptr;
    }
    return std::make_shared<const ToyMap>(toy_decode(bytes));
  }
  void restore(uint32_t iteration, std::shared_ptr<const Artifact> a) override {
    latest_ = std::static_pointer_cast<const ToyMap>(a);
    made_ = iteration;
    held_.clear();
  }
  void release() override { latest_.reset(); }
  int builds = 0;
  std::vector<std::string> built;  // each built artifact's bytes

 private:
  int64_t made_ = -1;
  std::shared_ptr<const ToyMap> latest_;
  std::map<uint64_t, std::vector<double>> held_;  // by unit
};

/// Renders the toy's units; thread-safe.
class ToyUnits final : public UnitRenderer {
 public:
  explicit ToyUnits(uint32_t seed) : seed_(seed) {}
  void render(const PassSequencer& seq, const UnitWork& work, UnitResult& result) override {
    const ToyMap* map = work.uses ? dynamic_cast<const ToyMap*>(seq.artifact(*work.uses)) : nullptr;
    if (work.uses && !map) throw std::logic_error("a unit rendered without its artifact");
    result.records.clear();
    result.tile_state.clear();
    if (work.kind == UnitKind::Paths) return paths(seq, work, map, result);
    tile(seq, work, map, result);
  }

 private:
  static size_t bin(int x, int y) { return size_t(x * 7 + y * 3) % kToyBins; }

  void tile(const PassSequencer& seq, const UnitWork& work, const ToyMap* map, UnitResult& result) const {
    const TileRect& r = work.rect;
    result.tile.reset(r);
    const PassSamples s = work.samples ? *work.samples : PassSamples::uniform(r, work.sample_begin, work.sample_end);
    std::vector<uint32_t> state(size_t(r.area()), 0);
    if (work.tile_state && !work.tile_state->empty()) std::memcpy(state.data(), work.tile_state->data(), state.size() * 4);
    const int width = seq.frame().full_width;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        const size_t i = s.index({x, y});
        const double scale = (map ? map->bins[bin(x, y)] : 1.0) * (1.0 + double(state[i]) / 16.0);
        PixelSums& px = result.tile.mutable_pixels()[size_t(y - r.y0) * size_t(r.width()) + size_t(x - r.x0)];
        for (uint32_t k = s.first[i]; k < s.first[i] + s.count[i]; ++k) {
          const double v = toy_value(uint64_t(y) * uint64_t(width) + uint64_t(x), k, seed_) * scale;
          for (int c = 0; c < 3; ++c) {
            const double vc = v * (1.0 - 0.2 * c);
            px.sum[c] += vc;
            px.sum_sq[c] += vc * vc;
          }
          ++px.count;
          ++result.tile.counters.samples;
        }
        state[i] += s.count[i];
      }
    result.tile_state.assign(reinterpret_cast<const char*>(state.data()), state.size() * 4);
  }

  void paths(const PassSequencer& seq, const UnitWork& work, const ToyMap* map, UnitResult& result) const {
    const TileRect& w = seq.frame().window;
    result.splats.reset(w);
    std::vector<double> sums(kToyBins, 0.0);
    for (uint64_t k = work.path_begin; k < work.path_end; ++k) {
      const double v = toy_value(k, 77, seed_) * (map ? map->bins[k % kToyBins] : 1.0);
      result.splats.pixel.push_back(uint32_t(toy_mix(k ^ (uint64_t(seed_) << 32)) % uint64_t(w.area())));
      result.splats.value.push_back({v, 0.5 * v, 0.25 * v});
      sums[k % kToyBins] += v;
    }
    if (work.feeds) result.records = toy_records(sums);
  }

  uint32_t seed_;
};

}  // namespace tessera::test

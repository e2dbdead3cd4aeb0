// Walker's alias method (Vose's construction): O(1) sampling of a discrete distribution, which
// power-based light selection needs for scenes with many thousands of lights (a CDF search is
// O(log n) and touches a cache line per step).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tessera {

class AliasTable {
 public:
  AliasTable() = default;
  /// Negative or non-finite weights count as 0. All-zero weights give a uniform distribution (as
  /// Distribution1D), so a sample is always an index < size().
  explicit AliasTable(const std::vector<float>& weights);

  size_t size() const { return bins_.size(); }
  /// Sum of the (sanitised) weights.
  double total() const { return total_; }
  /// Index i with probability pmf(i). `pmf` receives that probability; `u_remapped`, if given,
  /// receives a fresh uniform number in [0,1) recovered from the bits of `u` not used for i.
  uint32_t sample(float u, float* pmf = nullptr, float* u_remapped = nullptr) const;
  /// Exact probability of index i (the normalised weight, not the table's split).
  float pmf(uint32_t i) const { return i < bins_.size() ? bins_[i].p : 0.f; }

 private:
  struct Bin {
    float q = 1.f;       // probability of keeping i when bin i is drawn
    float p = 0.f;       // pmf(i)
    uint32_t alias = 0;  // index returned otherwise
  };
  std::vector<Bin> bins_;
  double total_ = 0;
};

}  // namespace tessera

// Tabulated piecewise-constant distributions, sampled by inverting their CDF (so stratified
// numbers stay stratified). Every pdf here is stated with its measure.
//
// The tables of a distribution (a CDF entry per bin, a guide slot per few bins) sit in flat arrays:
// all rows of a Distribution2D share one pair, and arrays of 2 MiB or more are backed by huge
// pages. An environment map's entries are too large for the caches, so what a sample costs is the
// cache lines (and pages) it touches: a guide slot (small enough to stay cached), then the one or
// two lines of entries of its bucket.
#pragma once

#include "tessera/core/huge_page_allocator.h"
#include "tessera/core/vec.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tessera {

/// One bin of a CDF table: cdf = the normalised sum of the weights before it, func its weight
/// (side by side, so the pmf is on the cache line the search ends on). Bin n is a sentinel, cdf 1.
struct CdfEntry {
  double cdf = 0;
  double func = 0;
};

/// A view of one distribution's tables (private to the distributions, exposed for their tests):
/// n + 1 entries and K + 1 guide slots (K = buckets(n)), guide[b] = the largest i with
/// cdf_i <= b / K. A sample u in bucket b = floor(u K) has its bin in [guide[b], guide[b + 1]], so
/// the search is a few entries long and finds exactly the bin a binary search over the whole CDF
/// finds.
struct CdfTable {
  const CdfEntry* entries = nullptr;
  const uint32_t* guide = nullptr;
  uint32_t n = 0;
  double total_norm = 1;  // the sum the weights are divided by (n for the uniform fallback)

  /// Guide buckets for n bins: one per kBinsPerBucket, so that an environment map's guide slots
  /// (a few MB) stay in cache while its entries (tens of MB) do not; a bucket of a smooth row then
  /// spans one cache line of entries.
  static constexpr uint32_t kBinsPerBucket = 8;
  static uint32_t buckets(uint32_t n) { return n == 0 ? 0 : (n + kBinsPerBucket - 1) / kBinsPerBucket; }

  /// Fills entries[0..n] and guide[0..buckets(n)] from n weights; returns the sum of the sanitised
  /// weights.
  static double fill(const float* weights, uint32_t n, CdfEntry* entries, uint32_t* guide, double& total_norm);
  uint32_t sample_discrete(float u, float* pmf, float* u_remapped) const;
  float sample_continuous(float u, float* pdf, uint32_t* index) const;
  float pdf_continuous(float x) const;
  float pmf(uint32_t i) const { return n ? float(entries[i].func / total_norm) : 0.f; }
};

/// Piecewise-constant 1D distribution over [0,1) (or over indices for discrete use).
class Distribution1D {
 public:
  Distribution1D() = default;
  /// Negative or non-finite weights count as 0. All-zero weights give a uniform distribution.
  explicit Distribution1D(const std::vector<float>& weights);
  size_t size() const { return table_.n; }
  /// Sum of the weights (the integral times size()).
  double total() const { return total_; }
  /// Discrete sample: index with probability w[i]/total; `pmf` receives it; `u_remapped` is u
  /// rescaled to [0,1) within the chosen bin, so it can be reused.
  uint32_t sample_discrete(float u, float* pmf = nullptr, float* u_remapped = nullptr) const {
    return table_.sample_discrete(u, pmf, u_remapped);
  }
  float pmf(uint32_t i) const { return table_.pmf(i); }
  /// Continuous sample in [0,1); pdf with respect to the unit interval.
  float sample_continuous(float u, float* pdf, uint32_t* index = nullptr) const {
    return table_.sample_continuous(u, pdf, index);
  }
  float pdf_continuous(float x) const { return table_.pdf_continuous(x); }
  size_t memory_bytes() const { return entries_.size() * sizeof(CdfEntry) + guide_.size() * sizeof(uint32_t); }

 private:
  HugeVector<CdfEntry> entries_;
  HugeVector<uint32_t> guide_;
  CdfTable table_;
  double total_ = 0;
};

/// Piecewise-constant 2D distribution over [0,1)^2: marginal over rows (v), conditional per row (u).
class Distribution2D {
 public:
  Distribution2D() = default;
  /// `weights` is row-major, `width` columns (u) by `height` rows (v).
  Distribution2D(const std::vector<float>& weights, int width, int height);
  /// Returns (u, v) in [0,1)^2; pdf with respect to the unit square.
  Vec2 sample(Vec2 u, float* pdf) const;
  float pdf(Vec2 uv) const;
  size_t memory_bytes() const {
    return marginal_.memory_bytes() + entries_.size() * sizeof(CdfEntry) + guide_.size() * sizeof(uint32_t) +
           row_norm_.size() * sizeof(double);
  }

 private:
  CdfTable row(size_t y) const;

  HugeVector<CdfEntry> entries_;  // (width + 1) per row
  HugeVector<uint32_t> guide_;    // CdfTable::buckets(width) + 1 per row
  std::vector<double> row_norm_;
  Distribution1D marginal_;
  int width_ = 0, height_ = 0;
};

}  // namespace tessera

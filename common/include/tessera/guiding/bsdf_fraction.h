// The learned probability of sampling the BSDF rather than the guide (Müller 2019, "Practical Path
// Guiding in Production", §"Learning the selection probability"), made exact and order-free.
//
// Müller minimises the KL divergence between the product f * cos * Li and the one-sample mixture
//   p(alpha) = alpha * bsdf_pdf + (1 - alpha) * guide_pdf
// by stochastic gradient descent after every sample, whose result depends on the order of the
// samples. Here each record instead adds its share of the loss at every candidate alpha:
//   loss(alpha) = sum over samples of  w * -log p(alpha),  w = f * cos * Li / pdf_sampled,
// a Monte Carlo estimate of -integral(f * cos * Li * log p(alpha)), which is convex in alpha; at
// the pass barrier the candidate with the lowest loss is taken. Sums are 64-bit fixed point, so
// they do not depend on the order of records (the farm's tiles, threads).
#pragma once

#include <array>
#include <cstdint>

namespace tessera {

class BsdfFractionLoss {
 public:
  static constexpr int kCandidates = 10;
  /// Candidate i is 0.1 * (i + 1): from mostly guided to the BSDF alone.
  static float candidate(int i) { return 0.1f * float(i + 1); }

  /// One sampled direction whose contribution f * cos * Li over its sampling pdf is `weight`, with
  /// the BSDF's and the guide's pdfs there (solid angle). Thread-safe against other records.
  void record(float weight, float bsdf_pdf, float guide_pdf);
  /// Adds the sums of another (exact).
  void merge(const BsdfFractionLoss& other);
  /// The candidate (at least `lowest_allowed`) with the lowest loss, or `current` when nothing was
  /// recorded.
  float best(float current, float lowest_allowed = 0.f) const;
  bool operator==(const BsdfFractionLoss& other) const = default;

 private:
  friend struct TreeIo;  // tree_io.h
  std::array<int64_t, kCandidates> loss_{};
  uint64_t records_ = 0;  // records with weight > 0
};

}  // namespace tessera

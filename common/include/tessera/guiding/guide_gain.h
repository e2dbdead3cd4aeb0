// Whether guiding pays: a guided iteration's own paths predict how much larger the second moment
// of a pixel sample would be had every vertex sampled its BSDF alone (plain path tracing).
//
// A guided vertex k draws wi from the mixture, density p_k, where the BSDF alone has b_k. The
// same path drawn by BSDF sampling has probability prod(b_k / p_k) times the guided one's, and a
// contribution c_d the path found after its vertices 0..d-1 would have carried the weight
// r_d = prod_{k<d} p_k / b_k. For a guided path of n guided vertices, then,
//   guided second moment:  (sum_d c_d)^2
//   plain second moment:   (sum_d c_d r_d)^2 / r_n     (importance-reweighted, unbiased)
// and the ratio of their sums over an iteration's paths is the predicted gain. Both take the
// guided path's Russian roulette and MIS weights as they were, an approximation: where guiding
// pays through its roulette rather than its directions (a gain of time) the prediction does not
// see it. Sums are 64-bit fixed point (DirectionalTree::fixed_point), so the prediction, and the
// decision it makes, are the same bits for any order of paths.
#pragma once

#include <cstdint>

namespace tessera {

/// One path's side: what its guided vertices did to its weight under BSDF sampling.
class PathGain {
 public:
  /// A vertex sampled with mixture density `mixture_pdf` where the BSDF alone has `bsdf_pdf`
  /// (both > 0), when the path's estimate (luminance) was `estimate`.
  void scattered(float estimate, float mixture_pdf, float bsdf_pdf) {
    plain_ += double(estimate - last_) * ratio_;
    last_ = estimate;
    ratio_ *= double(mixture_pdf) / double(bsdf_pdf);
  }
  /// The finished path's second moment under BSDF sampling, its estimate being `estimate`.
  double plain_moment(float estimate) const {
    const double plain = plain_ + double(estimate - last_) * ratio_;
    return plain * plain / ratio_;
  }
  /// Its second moment as it was sampled.
  static double guided_moment(float estimate) { return double(estimate) * double(estimate); }

 private:
  double plain_ = 0.0;  // sum of c_d r_d so far
  double ratio_ = 1.0;  // r after the last guided vertex
  float last_ = 0.f;    // the estimate when it was reached
};

/// An iteration's sums of both second moments, and how many paths they are of.
struct GuideGain {
  uint64_t plain = 0, guided = 0;  // fixed point, as DirectionalTree's
  uint64_t paths = 0;

  /// Adds one path's moments (each clamped and rounded by `dither`, DirectionalTree::fixed_point).
  /// Thread-safe against other records.
  void record(double plain_moment, double guided_moment, float dither);
  void merge(const GuideGain& other) {
    plain += other.plain;
    guided += other.guided;
    paths += other.paths;
  }
  /// Plain's second moment over guided's; 0 when no guided path was recorded.
  double ratio() const { return guided > 0 ? double(plain) / double(guided) : 0.0; }
  bool operator==(const GuideGain&) const = default;
};

}  // namespace tessera

#include "tessera/guiding/bsdf_fraction.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace tessera {
namespace {

// Fixed point: a term w * -log p is added as round(term * 2^10), clamped to 2^30 in magnitude, so
// 2^33 records fit in 64 bits. (The argmin needs only relative precision; a clamped sun hit still
// counts as the largest term there is.)
constexpr double kScale = 1024.0;
constexpr double kMaxTerm = double(int64_t(1) << 30);
constexpr float kMaxWeight = float(1 << 20);
// A candidate whose pdf is zero at a direction that carried light could never have sampled it.
constexpr double kUnreachable = kMaxTerm;

}  // namespace

void BsdfFractionLoss::record(float weight, float bsdf_pdf, float guide_pdf) {
  if (!(weight > 0.f)) return;
  const double w = std::min(weight, kMaxWeight);
  for (int i = 0; i < kCandidates; ++i) {
    // (In float: the argmin needs a few digits, and a record is ten logarithms.)
    const float alpha = candidate(i);
    const float p = alpha * bsdf_pdf + (1.f - alpha) * guide_pdf;
    const double term = p > 0.f ? std::clamp(-w * double(std::log(p)) * kScale, -kMaxTerm, kMaxTerm) : kUnreachable;
    const int64_t rounded = int64_t(term < 0.0 ? term - 0.5 : term + 0.5);  // (to nearest, as llround)
    std::atomic_ref<int64_t>(loss_[size_t(i)]).fetch_add(rounded, std::memory_order_relaxed);
  }
  std::atomic_ref<uint64_t>(records_).fetch_add(1, std::memory_order_relaxed);
}

void BsdfFractionLoss::merge(const BsdfFractionLoss& other) {
  for (size_t i = 0; i < loss_.size(); ++i) loss_[i] += other.loss_[i];
  records_ += other.records_;
}

float BsdfFractionLoss::best(float current, float lowest_allowed) const {
  int first_candidate = 0;
  while (first_candidate + 1 < kCandidates && candidate(first_candidate) < lowest_allowed - 1e-6f) ++first_candidate;
  if (records_ == 0) return current;
  const auto lowest = std::min_element(loss_.begin() + first_candidate, loss_.end());
  return candidate(int(lowest - loss_.begin()));
}

}  // namespace tessera

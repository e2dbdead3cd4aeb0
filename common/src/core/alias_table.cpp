// Vose's construction in double: each bin's weight is n * w_i / total; bins below 1 ("small") are
// topped up by one bin above 1 ("large"), whose excess moves on. Rounding leaves a few bins a hair
// off 1 at the end; they keep themselves (q = 1), which is what the exact arithmetic would do.
#include "tessera/core/alias_table.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <cmath>

namespace tessera {

AliasTable::AliasTable(const std::vector<float>& weights) {
  const size_t n = weights.size();
  bins_.resize(n);
  if (n == 0) return;
  std::vector<double> w(n);
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    float x = weights[i];
    w[i] = (std::isfinite(x) && x > 0.f) ? double(x) : 0.0;
    sum += w[i];
  }
  total_ = sum;
  if (!(sum > 0)) {
    std::fill(w.begin(), w.end(), 1.0);
    sum = double(n);
  }
  std::vector<double> scaled(n);
  std::vector<uint32_t> small, large;
  small.reserve(n);
  large.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    bins_[i].p = float(w[i] / sum);
    scaled[i] = w[i] * double(n) / sum;
    (scaled[i] < 1.0 ? small : large).push_back(uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    uint32_t s = small.back(), l = large.back();
    small.pop_back();
    large.pop_back();
    bins_[s].q = float(scaled[s]);
    bins_[s].alias = l;
    scaled[l] -= 1.0 - scaled[s];
    (scaled[l] < 1.0 ? small : large).push_back(l);
  }
  // A weightless bin must never keep itself, however the rounding went.
  const uint32_t heaviest = uint32_t(std::max_element(w.begin(), w.end()) - w.begin());
  for (auto* rest : {&small, &large})
    for (uint32_t i : *rest) {
      const bool empty = w[i] == 0.0;
      bins_[i].q = empty ? 0.f : 1.f;
      bins_[i].alias = empty ? heaviest : i;
    }
}

uint32_t AliasTable::sample(float u, float* pmf_out, float* u_remapped) const {
  const size_t n = bins_.size();
  if (n == 0) {
    if (pmf_out) *pmf_out = 0.f;
    if (u_remapped) *u_remapped = 0.f;
    return 0;
  }
  // One number picks the bin (integer part of u n) and the side of its split (fraction).
  const double x = double(u) * double(n);
  const uint32_t bin = uint32_t(std::min(x, double(n - 1)));
  const double frac = std::min(x - double(bin), 1.0);
  const Bin& b = bins_[bin];
  const bool keep = frac < double(b.q);
  const uint32_t i = keep ? bin : b.alias;
  if (pmf_out) *pmf_out = bins_[i].p;
  if (u_remapped) {
    double r = keep ? frac / double(b.q) : (frac - double(b.q)) / (1.0 - double(b.q));
    *u_remapped = std::min(float(std::clamp(r, 0.0, 1.0)), 0x1.fffffep-1f);
  }
  TESSERA_DCHECK(i < n);
  return i;
}

}  // namespace tessera

// Pearson's chi-square test of a discrete sampler (light selection, alias tables) against its
// probabilities: categories expected to get fewer than `min_expected` samples are pooled into one
// (Mitsuba's rule), and the p-value comes from support/chi2.h. A sample in a category of
// probability 0 fails the test outright.
#pragma once

#include "support/chi2.h"

#include <cstdint>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace tessera::test {

struct DiscreteChi2Result {
  bool passed = false;
  double statistic = 0, p_value = 0;
  int dof = 0;
  std::string message;
};

/// `counts[i]` samples fell in category i (N in total, including `misses`, samples the sampler
/// returned nothing for); `probs[i]` is the claimed probability, `p_miss` that of returning nothing.
inline DiscreteChi2Result discrete_chi2(const std::vector<uint64_t>& counts, const std::vector<double>& probs,
                                        uint64_t misses = 0, double p_miss = 0.0, double significance = 0.01,
                                        int test_count = 1, double min_expected = 5.0) {
  DiscreteChi2Result r;
  uint64_t n = misses;
  for (uint64_t c : counts) n += c;
  std::vector<std::pair<double, double>> cells;  // (observed, expected)
  double pooled_obs = 0, pooled_exp = 0;
  auto add = [&](double obs, double p, size_t index) {
    const double e = p * double(n);
    if (p <= 0.0) {
      if (obs > 0) {
        std::ostringstream s;
        s << obs << " samples in category " << index << " of probability 0";
        r.message = s.str();
        return false;
      }
      return true;
    }
    if (e < min_expected) pooled_obs += obs, pooled_exp += e;
    else cells.push_back({obs, e});
    return true;
  };
  for (size_t i = 0; i < counts.size(); ++i)
    if (!add(double(counts[i]), probs[i], i)) return r;
  if (!add(double(misses), p_miss, size_t(-1))) return r;
  if (pooled_exp > 0) cells.push_back({pooled_obs, pooled_exp});
  double stat = 0;
  for (auto [o, e] : cells) stat += (o - e) * (o - e) / e;
  r.statistic = stat;
  r.dof = int(cells.size()) - 1;
  r.p_value = r.dof > 0 ? chi2_p_value(stat, r.dof) : 1.0;
  const double alpha = 1.0 - std::pow(1.0 - significance, 1.0 / double(test_count));
  r.passed = r.p_value >= alpha;
  std::ostringstream s;
  s << "chi2 = " << stat << ", dof = " << r.dof << ", p = " << r.p_value << " (alpha " << alpha << ", "
    << cells.size() << " cells, " << n << " samples)";
  r.message = s.str();
  return r;
}

}  // namespace tessera::test

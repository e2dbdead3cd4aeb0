// Chi-square goodness-of-fit test for direction samplers (BSDFs, lights), after Mitsuba 3's
// ChiSquareTest with a SphericalDomain.
//
// The sphere is binned in (cos theta, phi) about +z, which makes equal-sized bins equal in solid
// angle and makes the expected count of a bin the plain integral of the solid-angle pdf over
// d(cos theta) d(phi) (no Jacobian). N samples are histogrammed; the expected counts are N times the
// pdf integrated over each bin by composite Simpson's rule on a sub-grid. Bins expected to get fewer
// than `min_expected` samples are pooled into one; Pearson's statistic is compared with the
// chi-square distribution (p-value from the regularised incomplete gamma function). The null
// hypothesis "samples follow pdf" is rejected when p < alpha, with alpha Sidak-corrected when a
// test runs several chi-square tests: alpha = 1 - (1 - significance)^(1 / test_count).
//
// Also checked: every sample is a unit vector with a finite direction, the pdf integrates to at
// most 1 + pdf_integral_tolerance, the pdf is never negative, a sample never lands in a bin whose
// expected count is zero, and (if the sampler reports one) the sampler's pdf agrees with pdf().
//
// Usage:
//   auto r = tessera::test::chi2_test(
//       [](Vec2 u) { return Chi2Sample{square_to_cosine_hemisphere(u), 0.f}; },
//       [](Vec3 w) { return double(cosine_hemisphere_pdf(w.z)); });
//   EXPECT_TRUE(r.passed) << r.message;
#pragma once

#include "tessera/core/hash.h"
#include "tessera/core/ray.h"
#include "tessera/core/vec.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

namespace tessera::test {

inline constexpr double kChi2Pi = 3.14159265358979323846;

/// One sampled direction. `valid = false` for a failed sample (it is simply not counted, as in
/// Mitsuba). `pdf`: the sampler's own solid-angle pdf, or 0 when it reports none.
struct Chi2Sample {
  Vec3 wi;
  float pdf = 0.f;
  bool valid = true;
};

/// Samplers take two uniform numbers, or two plus a third (e.g. for picking a lobe).
using Chi2Sampler = std::function<Chi2Sample(Vec2 u)>;
using Chi2Sampler3 = std::function<Chi2Sample(Vec2 u, float u_extra)>;
/// Solid-angle density of the sampler at a unit direction.
using Chi2Pdf = std::function<double(Vec3 w)>;

struct Chi2Options {
  int cos_theta_bins = 50;          // bins along cos(theta) in [-1, 1]
  int phi_bins = 100;               // bins along phi in [0, 2 pi)
  size_t sample_count = 1000000;
  int integration_resolution = 8;   // Simpson intervals per bin and axis (made even)
  double significance = 0.01;
  int test_count = 1;               // number of chi-square tests the caller runs (Sidak)
  double min_expected = 5.0;
  double pdf_integral_tolerance = 1e-2;
  double reported_pdf_rel_tolerance = 1e-3;  // |pdf_s - pdf(w)| <= tol * max(pdf(w), 1e-4)
  // Samplers with piecewise densities (tabulated lights) may report the pdf of the cell they drew
  // from while the float direction rounds into the neighbouring cell; tolerate that rarely.
  double max_pdf_mismatch_fraction = 1e-4;
  uint64_t seed = 1;
  std::string name = "sampler";     // for messages
};

struct Chi2Result {
  bool passed = false;
  double statistic = 0;     // Pearson's chi^2
  int dof = 0;
  double p_value = 0;
  double alpha = 0;         // after the Sidak correction
  double pdf_integral = 0;  // numeric integral of pdf over the sphere
  size_t valid_samples = 0;
  int pooled_bins = 0;      // bins merged because of a low expected count
  std::string message;      // why it failed, with the worst bins; a summary when it passed
};

namespace chi2_detail {

/// Regularised lower incomplete gamma P(a, x), Numerical Recipes style: series for x < a + 1,
/// Lentz's continued fraction for Q = 1 - P otherwise. Iteration limits are generous because
/// chi-square tests with thousands of degrees of freedom have large a.
inline double gamma_p_series(double a, double x) {
  double ap = a, del = 1.0 / a, sum = del;
  for (int n = 0; n < 100000; ++n) {
    ap += 1.0;
    del *= x / ap;
    sum += del;
    if (std::abs(del) < std::abs(sum) * 1e-15) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

inline double gamma_q_continued_fraction(double a, double x) {
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

}  // namespace chi2_detail

/// Regularised lower incomplete gamma function P(a, x) = gamma(a, x) / Gamma(a).
inline double regularized_gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  if (x < a + 1.0) return chi2_detail::gamma_p_series(a, x);
  return 1.0 - chi2_detail::gamma_q_continued_fraction(a, x);
}
/// Q(a, x) = 1 - P(a, x), computed without cancellation.
inline double regularized_gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  if (x < a + 1.0) return 1.0 - chi2_detail::gamma_p_series(a, x);
  return chi2_detail::gamma_q_continued_fraction(a, x);
}
/// P(X >= statistic) for X ~ chi^2(dof).
inline double chi2_p_value(double statistic, int dof) {
  return regularized_gamma_q(0.5 * dof, 0.5 * statistic);
}

/// Expected fraction of samples per bin (row-major: cos theta bin, then phi bin).
inline std::vector<double> chi2_integrate_pdf(const Chi2Pdf& pdf, const Chi2Options& o) {
  int res = std::max(2, o.integration_resolution + (o.integration_resolution & 1));
  double dc = 2.0 / o.cos_theta_bins, dphi = 2.0 * kChi2Pi / o.phi_bins;
  std::vector<double> out(size_t(o.cos_theta_bins) * size_t(o.phi_bins));
  std::vector<double> wc(size_t(res + 1));
  for (int k = 0; k <= res; ++k) wc[size_t(k)] = (k == 0 || k == res) ? 1.0 : ((k & 1) ? 4.0 : 2.0);
  // Nodes on a bin's edges are nudged inside it: a pdf with a step exactly on a bin edge (a
  // hemisphere's rim) must not leak into the neighbouring bin through rounding.
  auto node = [res](int k) { return k == 0 ? 1e-7 : (k == res ? 1.0 - 1e-7 : double(k) / res); };
  for (int i = 0; i < o.cos_theta_bins; ++i) {
    for (int j = 0; j < o.phi_bins; ++j) {
      double c0 = -1.0 + i * dc, p0 = j * dphi, sum = 0;  // bin [c0, c0 + dc) x [p0, p0 + dphi)
      for (int a = 0; a <= res; ++a) {
        double c = std::clamp(c0 + dc * node(a), -1.0, 1.0);
        double s = std::sqrt(std::max(0.0, 1.0 - c * c));
        for (int b = 0; b <= res; ++b) {
          double phi = p0 + dphi * node(b);
          Vec3 w(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c));
          double p = pdf(w);
          if (!(p >= 0.0) || !std::isfinite(p)) p = -1e300;  // flagged below as invalid
          sum += wc[size_t(a)] * wc[size_t(b)] * p;
        }
      }
      out[size_t(i) * size_t(o.phi_bins) + size_t(j)] = sum * (dc / (3.0 * res)) * (dphi / (3.0 * res));
    }
  }
  return out;
}

inline Chi2Result chi2_test(const Chi2Sampler3& sample, const Chi2Pdf& pdf, const Chi2Options& o = {}) {
  Chi2Result r;
  std::ostringstream msg;
  msg.precision(6);
  const int nc = o.cos_theta_bins, np = o.phi_bins;
  const size_t nbins = size_t(nc) * size_t(np);
  std::vector<double> observed(nbins, 0.0);

  // 1. Histogram, and check what the sampler reports.
  Pcg32 rng(o.seed, 0x7a1b3c5d);
  size_t bad_dirs = 0, pdf_mismatches = 0;
  double worst_pdf_err = 0;
  Vec3 worst_pdf_dir;
  float worst_pdf_reported = 0;
  double worst_pdf_expected = 0;
  for (size_t n = 0; n < o.sample_count; ++n) {
    Vec2 u(rng.next_float(), rng.next_float());
    float u3 = rng.next_float();
    Chi2Sample s = sample(u, u3);
    if (!s.valid) continue;
    Vec3 w = s.wi;
    if (!is_finite(w) || std::abs(length(w) - 1.f) > 1e-3f) {
      ++bad_dirs;
      continue;
    }
    ++r.valid_samples;
    double c = std::clamp(double(w.z), -1.0, 1.0);
    double phi = std::atan2(double(w.y), double(w.x));
    if (phi < 0) phi += 2.0 * kChi2Pi;
    int i = std::min(int((c + 1.0) * 0.5 * nc), nc - 1);
    int j = std::min(int(phi / (2.0 * kChi2Pi) * np), np - 1);
    observed[size_t(i) * size_t(np) + size_t(j)] += 1.0;
    if (s.pdf > 0.f) {
      double expected = pdf(w);
      double err = std::abs(double(s.pdf) - expected) / std::max(expected, 1e-4);
      if (err > o.reported_pdf_rel_tolerance) {
        ++pdf_mismatches;
        if (err > worst_pdf_err) {
          worst_pdf_err = err;
          worst_pdf_dir = w;
          worst_pdf_reported = s.pdf;
          worst_pdf_expected = expected;
        }
      }
    }
  }

  // 2. Expected counts.
  std::vector<double> expected = chi2_integrate_pdf(pdf, o);
  bool negative_pdf = false;
  for (double& e : expected) {
    if (e < 0) negative_pdf = true;
    r.pdf_integral += std::max(e, 0.0);
    e = std::max(e, 0.0) * double(o.sample_count);
  }

  std::vector<std::string> failures;
  if (bad_dirs)
    failures.push_back(std::to_string(bad_dirs) + " samples were not finite unit vectors");
  if (negative_pdf) failures.push_back("pdf() returned a negative or non-finite value");
  if (r.pdf_integral > 1.0 + o.pdf_integral_tolerance) {
    std::ostringstream s;
    s << "pdf integrates to " << r.pdf_integral << " > 1 over the sphere";
    failures.push_back(s.str());
  }
  if (double(pdf_mismatches) > o.max_pdf_mismatch_fraction * double(o.sample_count)) {
    std::ostringstream s;
    s << pdf_mismatches << " samples report a pdf that differs from pdf(); worst: reported "
      << worst_pdf_reported << ", pdf() " << worst_pdf_expected << " at (" << worst_pdf_dir.x << ", "
      << worst_pdf_dir.y << ", " << worst_pdf_dir.z << ")";
    failures.push_back(s.str());
  }

  auto bin_label = [&](size_t k) {
    int i = int(k / size_t(np)), j = int(k % size_t(np));
    std::ostringstream s;
    s.precision(4);
    s << "cos_theta [" << -1.0 + 2.0 * i / nc << ", " << -1.0 + 2.0 * (i + 1) / nc << "), phi ["
      << 360.0 * j / np << ", " << 360.0 * (j + 1) / np << ") deg";
    return s.str();
  };

  // 3. Pool low-expectation bins and compute Pearson's statistic.
  size_t zero_hits = 0, worst_zero = 0;
  double pooled_obs = 0, pooled_exp = 0, stat = 0;
  int kept = 0;
  std::vector<std::pair<double, size_t>> contrib;
  for (size_t k = 0; k < nbins; ++k) {
    if (expected[k] == 0.0) {
      if (observed[k] > 0) {
        if (observed[k] > observed[worst_zero] || zero_hits == 0) worst_zero = k;
        zero_hits += size_t(observed[k]);
      }
      continue;
    }
    if (expected[k] < o.min_expected) {
      pooled_obs += observed[k];
      pooled_exp += expected[k];
      ++r.pooled_bins;
      continue;
    }
    double d = observed[k] - expected[k];
    double t = d * d / expected[k];
    stat += t;
    contrib.push_back({t, k});
    ++kept;
  }
  if (zero_hits) {
    std::ostringstream s;
    s << zero_hits << " samples fell in bins where pdf() integrates to 0, e.g. " << observed[worst_zero]
      << " in " << bin_label(worst_zero);
    failures.push_back(s.str());
  }
  if (pooled_exp >= o.min_expected) {
    double d = pooled_obs - pooled_exp;
    stat += d * d / pooled_exp;
    ++kept;
  } else if (pooled_exp > 0 && kept > 0) {
    // Too little to stand alone: fold it into the smallest kept bin, as Mitsuba does.
    auto it = std::min_element(contrib.begin(), contrib.end(), [&](const auto& a, const auto& b) {
      return expected[a.second] < expected[b.second];
    });
    size_t k = it->second;
    double e = expected[k] + pooled_exp, ob = observed[k] + pooled_obs;
    stat -= it->first;
    it->first = (ob - e) * (ob - e) / e;
    stat += it->first;
  }
  r.statistic = stat;
  r.dof = kept - 1;
  r.alpha = 1.0 - std::pow(1.0 - o.significance, 1.0 / std::max(1, o.test_count));
  if (r.dof < 1) {
    failures.push_back("fewer than two usable bins (pdf() is zero almost everywhere?)");
    r.p_value = 0;
  } else {
    r.p_value = chi2_p_value(stat, r.dof);
    if (r.p_value < r.alpha) {
      std::ostringstream s;
      s << "chi-square test rejects the sampler: statistic " << stat << " with " << r.dof
        << " degrees of freedom, p = " << r.p_value << " < alpha " << r.alpha;
      failures.push_back(s.str());
    }
  }

  std::sort(contrib.begin(), contrib.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  msg << "[chi2 " << o.name << "] " << (failures.empty() ? "passed" : "FAILED") << ": " << r.valid_samples
      << "/" << o.sample_count << " valid samples, " << nc << "x" << np << " bins (" << r.pooled_bins
      << " pooled), pdf integral " << r.pdf_integral << ", statistic " << stat << ", dof " << r.dof
      << ", p = " << r.p_value << "\n";
  for (const auto& f : failures) msg << "  - " << f << "\n";
  if (pdf_mismatches && failures.empty())
    msg << "  (" << pdf_mismatches << " samples reported a pdf differing from pdf(), within the tolerated fraction)\n";
  if (!failures.empty()) {
    msg << "  worst bins (observed vs expected):\n";
    for (size_t n = 0; n < std::min<size_t>(8, contrib.size()); ++n) {
      size_t k = contrib[n].second;
      msg << "    " << bin_label(k) << ": " << observed[k] << " vs " << expected[k] << " (chi2 term "
          << contrib[n].first << ")\n";
    }
  }
  r.passed = failures.empty();
  r.message = msg.str();
  return r;
}

inline Chi2Result chi2_test(const Chi2Sampler& sample, const Chi2Pdf& pdf, const Chi2Options& o = {}) {
  return chi2_test(Chi2Sampler3([&sample](Vec2 u, float) { return sample(u); }), pdf, o);
}

}  // namespace tessera::test

// Error metrics, time to a target error and the CSV of `tessera bench convergence` (convergence.h).
#include "tessera/cli/convergence.h"

#include "tessera/image/image_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace tessera::cli {

ErrorMetrics measure_error(const Image& image, const Image& ref, double trim_fraction) {
  if (image.width() != ref.width() || image.height() != ref.height() || image.channels() != ref.channels())
    throw std::invalid_argument("image is " + describe_size(image) + " but the reference is " + describe_size(ref));
  ErrorMetrics m;
  m.rel_mse = rel_mse(image, ref);
  m.mse = mse(image, ref);

  const size_t n = image.num_pixels();
  const size_t c = size_t(image.channels());
  const float* a = image.data();
  const float* r = ref.data();
  std::vector<double> per_pixel(n);
  double sum_a = 0, sum_r = 0;
  for (size_t p = 0; p < n; ++p) {
    double e = 0;
    for (size_t ch = 0; ch < c; ++ch) {
      double x = a[p * c + ch], y = r[p * c + ch];
      e += (x - y) * (x - y) / (y * y + 1e-2);
      sum_a += x;
      sum_r += y;
    }
    per_pixel[p] = e / double(c);
  }
  m.mean_ratio = sum_r != 0 ? sum_a / sum_r : (sum_a == 0 ? 1.0 : HUGE_VAL);

  // Drop the k largest per-pixel errors: nth_element puts the n - k smallest first.
  const size_t k = std::min(n, size_t(std::floor(double(n) * std::max(trim_fraction, 0.0))));
  if (n > k) {
    std::nth_element(per_pixel.begin(), per_pixel.begin() + std::ptrdiff_t(n - k), per_pixel.end());
    double sum = 0;
    for (size_t p = 0; p < n - k; ++p) sum += per_pixel[p];
    m.rel_mse_trim = sum / double(n - k);
  }
  return m;
}

TimeToTarget time_to_target(const std::vector<ConvergencePoint>& points, double target) {
  TimeToTarget t;
  for (size_t i = 0; i < points.size(); ++i) {
    const double e1 = points[i].error.rel_mse;
    if (!(e1 <= target)) continue;
    t.reached = true;
    t.seconds = points[i].seconds;
    if (i == 0) {
      t.at_first_budget = true;
      return t;
    }
    const double e0 = points[i - 1].error.rel_mse;
    const double s0 = points[i - 1].seconds, s1 = points[i].seconds;
    // A zero error or time has no logarithm: the budget that reached the target is the answer.
    if (!(e1 > 0) || !(s0 > 0) || !(s1 > 0) || !std::isfinite(e0) || !(e0 > e1)) return t;
    const double f = (std::log(target) - std::log(e0)) / (std::log(e1) - std::log(e0));
    t.seconds = std::exp(std::log(s0) + f * (std::log(s1) - std::log(s0)));
    return t;
  }
  return t;
}

void write_convergence_csv(std::ostream& out, const std::vector<ConvergencePoint>& points) {
  out << "strategy,spp,seconds,relmse,relmse_trim,mse,mean_ratio,noise_estimate\n";
  char line[512];
  for (const auto& p : points) {
    std::snprintf(line, sizeof line, "%s,%d,%.6f,%.6g,%.6g,%.6g,%.6g,%.6g\n", p.strategy.c_str(), p.spp, p.seconds,
                  p.error.rel_mse, p.error.rel_mse_trim, p.error.mse, p.error.mean_ratio, p.noise_estimate);
    out << line;
  }
}

}  // namespace tessera::cli

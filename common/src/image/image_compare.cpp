#include "tessera/image/image_compare.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tessera {

namespace {

void require_same_shape(const Image& a, const Image& b, const char* what) {
  if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels())
    throw std::invalid_argument(std::string(what) + ": image sizes differ (" + describe_size(a) + " vs " +
                                describe_size(b) + ")");
}

template <typename F>
double mean_over_values(const Image& a, const Image& b, const char* what, F&& term) {
  require_same_shape(a, b, what);
  const auto& va = a.values();
  const auto& vb = b.values();
  if (va.empty()) return 0.0;
  double sum = 0;
  for (size_t i = 0; i < va.size(); ++i) sum += term(double(va[i]), double(vb[i]));
  return sum / double(va.size());
}

}  // namespace

std::string describe_size(const Image& image) {
  return std::to_string(image.width()) + "x" + std::to_string(image.height()) + "x" +
         std::to_string(image.channels());
}

std::vector<double> channel_means(const Image& image) {
  std::vector<double> sums(size_t(image.channels()), 0.0);
  if (image.empty()) return sums;
  const auto& v = image.values();
  for (size_t i = 0; i < v.size(); ++i) sums[i % sums.size()] += v[i];
  for (double& s : sums) s /= double(image.num_pixels());
  return sums;
}

size_t count_non_finite(const Image& image) {
  size_t n = 0;
  for (float v : image.values()) n += std::isfinite(v) ? 0 : 1;
  return n;
}

double rel_mse(const Image& a, const Image& ref, double epsilon) {
  return mean_over_values(a, ref, "rel_mse", [epsilon](double x, double r) {
    double d = x - r;
    return d * d / (r * r + epsilon);
  });
}

double rel_mse_floor(const Image& ref, const Image& ref_variance, double epsilon) {
  return mean_over_values(ref_variance, ref, "rel_mse_floor", [epsilon](double v, double r) { return v / (r * r + epsilon); });
}

double mse(const Image& a, const Image& b) {
  return mean_over_values(a, b, "mse", [](double x, double y) { return (x - y) * (x - y); });
}

double mean_abs_error(const Image& a, const Image& b) {
  return mean_over_values(a, b, "mean_abs_error", [](double x, double y) { return std::abs(x - y); });
}

ZScoreStats z_score_stats(const Image& a, const Image& ref, const Image& ref_variance, const Image* a_variance,
                          double variance_floor) {
  require_same_shape(a, ref, "z_score_stats");
  require_same_shape(ref, ref_variance, "z_score_stats (reference variance)");
  if (a_variance) require_same_shape(a, *a_variance, "z_score_stats (variance)");
  ZScoreStats s;
  const auto& va = a.values();
  double sum = 0, sum2 = 0;
  size_t above = 0;
  for (size_t i = 0; i < va.size(); ++i) {
    double var = double(ref_variance.values()[i]) + (a_variance ? double(a_variance->values()[i]) : 0.0);
    double z = (double(va[i]) - double(ref.values()[i])) / std::sqrt(std::max(var, 0.0) + variance_floor);
    sum += z;
    sum2 += z * z;
    above += std::abs(z) > 4.0 ? 1 : 0;
  }
  s.count = va.size();
  if (s.count) {
    s.mean_z = sum / double(s.count);
    s.mean_z2 = sum2 / double(s.count);
    s.frac_above_4 = double(above) / double(s.count);
  }
  return s;
}

namespace {

Image box_reduce(const Image& image, int factor, bool variance) {
  if (factor < 1) throw std::invalid_argument("downsample: factor must be >= 1");
  int w = (image.width() + factor - 1) / factor, h = (image.height() + factor - 1) / factor;
  Image out(w, h, image.channels());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int x0 = x * factor, y0 = y * factor;
      int x1 = std::min(x0 + factor, image.width()), y1 = std::min(y0 + factor, image.height());
      double k = double(x1 - x0) * double(y1 - y0);
      for (int c = 0; c < image.channels(); ++c) {
        double sum = 0;
        for (int yy = y0; yy < y1; ++yy)
          for (int xx = x0; xx < x1; ++xx) sum += image.at(xx, yy, c);
        out.at(x, y, c) = float(variance ? sum / (k * k) : sum / k);
      }
    }
  return out;
}

}  // namespace

Image downsample(const Image& image, int factor) { return box_reduce(image, factor, false); }
Image downsample_variance(const Image& variance, int factor) { return box_reduce(variance, factor, true); }

}  // namespace tessera

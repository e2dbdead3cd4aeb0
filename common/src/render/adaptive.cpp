#include "tessera/render/adaptive.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace tessera {

PassSamples PassSamples::uniform(const TileRect& rect, uint32_t begin, uint32_t end) {
  PassSamples s;
  s.rect = rect;
  s.first.assign(size_t(rect.area()), begin);
  s.count.assign(size_t(rect.area()), end - begin);
  return s;
}

bool adaptive_pass(uint32_t begin, uint32_t spp, uint64_t fewest_film_samples, const AdaptiveSettings& s) {
  return fewest_film_samples >= s.min_samples && double(begin) >= s.uniform_fraction * double(spp);
}

uint64_t fewest_samples(const Film& film) {
  uint64_t fewest = std::numeric_limits<uint64_t>::max();
  const TileRect& w = film.window();
  for (int y = w.y0; y < w.y1; ++y)
    for (int x = w.x0; x < w.x1; ++x) fewest = std::min(fewest, film.pixel({x, y}).count);
  return fewest;
}

namespace {

/// Per pixel, row-major: the per-sample relative variance s^2 / (mean^2 + 0.01), over channels.
std::vector<double> relative_variance(const Film& film) {
  const TileRect& w = film.window();
  std::vector<double> v;
  v.reserve(size_t(w.area()));
  for (int y = w.y0; y < w.y1; ++y)
    for (int x = w.x0; x < w.x1; ++x) {
      const Rgb mean = film.mean({x, y}), var = film.sample_variance({x, y});
      double sum = 0;
      for (int c = 0; c < 3; ++c) sum += double(var[c]) / (double(mean[c]) * mean[c] + 0.01);
      v.push_back(sum / 3);
    }
  return v;
}

/// Per pixel: sqrt of the mean of v over its four edge neighbours, which are the other colour of
/// the checkerboard (a film of one pixel: its own).
std::vector<double> neighbour_weights(const std::vector<double>& v, int width, int height) {
  std::vector<double> s(v.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double sum = 0;
      int n = 0;
      for (const auto& [dx, dy] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}})
        if (x + dx >= 0 && x + dx < width && y + dy >= 0 && y + dy < height) {
          sum += v[size_t(y + dy) * width + x + dx];
          ++n;
        }
      s[size_t(y) * width + x] = std::sqrt(n ? sum / n : v[size_t(y) * width + x]);
    }
  return s;
}

/// Gives `budget` samples to the pixels `which`: each is filled up to c * weight, at most `cap`
/// more, c found by bisection in a fixed number of steps; the last few samples go in pixel order
/// so the total is exact.
void fill_pixels(const std::vector<size_t>& which, const std::vector<double>& weight, const std::vector<uint64_t>& have,
                 uint64_t cap, uint64_t budget, std::vector<uint32_t>& count) {
  // A pixel without variance (so far) still takes samples once every other pixel has its share.
  double raw_sum = 0;
  for (size_t i : which) raw_sum += weight[i];
  const double least = raw_sum > 0 ? 1e-3 * raw_sum / double(which.size()) : 1.0;
  const auto weight_of = [&](size_t i) { return std::max(weight[i], least); };
  double weight_sum = 0, have_sum = 0;
  for (size_t i : which) {
    weight_sum += weight_of(i);
    have_sum += double(have[i]);
  }
  const auto fill = [&](double c, std::vector<uint32_t>* out) {
    uint64_t total = 0;
    for (size_t i : which) {
      const double target = std::floor(c * weight_of(i));
      const double more = target > double(have[i]) ? std::min(target - double(have[i]), double(cap)) : 0.0;
      if (out) (*out)[i] = uint32_t(more);
      total += uint64_t(more);
    }
    return total;
  };
  double lo = 0, hi = (have_sum + double(budget)) / weight_sum;
  while (fill(hi, nullptr) < budget) hi *= 2;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (fill(mid, nullptr) >= budget ? hi : lo) = mid;
  }
  std::vector<uint32_t> more(count.size());
  uint64_t left = budget - fill(lo, &count);
  fill(hi, &more);
  // Between two adjacent levels only a few pixels differ.
  for (size_t i : which) {
    if (left == 0) break;
    const uint64_t extra = std::min<uint64_t>(more[i] - count[i], left);
    count[i] += uint32_t(extra);
    left -= extra;
  }
  TESSERA_CHECK(left == 0);
}

}  // namespace

std::vector<uint32_t> allocate_samples(const Film& film, uint32_t pass_spp, const AdaptiveSettings& settings) {
  const TileRect& w = film.window();
  const size_t n = size_t(w.area());
  const std::vector<double> weight = neighbour_weights(relative_variance(film), w.width(), w.height());
  std::vector<uint64_t> have;
  have.reserve(n);
  for (int y = w.y0; y < w.y1; ++y)
    for (int x = w.x0; x < w.x1; ++x) have.push_back(film.pixel({x, y}).count);
  // Each colour of the checkerboard takes its own share of the budget, so a pixel's count depends on
  // the other colour's samples alone (see adaptive.h).
  std::vector<uint32_t> count(n, 0);
  for (int colour = 0; colour < 2; ++colour) {
    std::vector<size_t> which;
    for (size_t i = 0; i < n; ++i)
      if (int((i % size_t(w.width())) + (i / size_t(w.width()))) % 2 == colour) which.push_back(i);
    if (!which.empty())
      fill_pixels(which, weight, have, uint64_t(std::max(1u, settings.max_factor)) * pass_spp,
                  uint64_t(pass_spp) * which.size(), count);
  }
  return count;
}

PassSamples plan_pass(const Film& film, const std::vector<uint32_t>& taken, uint32_t begin, uint32_t pass_spp,
                      uint32_t spp, const AdaptiveSettings* adaptive) {
  const size_t n = size_t(film.window().area());
  TESSERA_CHECK(taken.size() == n);
  PassSamples s;
  s.rect = film.window();
  s.first = taken;
  if (adaptive && adaptive_pass(begin, spp, fewest_samples(film), *adaptive))
    s.count = allocate_samples(film, pass_spp, *adaptive);
  else
    s.count.assign(n, pass_spp);
  return s;
}

}  // namespace tessera

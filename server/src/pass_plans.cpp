#include "pass_plans.h"

#include "tessera/core/check.h"

#include <limits>
#include <numeric>

namespace tessera::server {

PassPlans::PassPlans(const TileRect& window, std::vector<TileRect> tiles, std::vector<uint32_t> passes,
                     std::vector<uint32_t> pass_begin, uint32_t spp, AdaptiveSettings settings)
    : window_(window), tiles_(std::move(tiles)), passes_(std::move(passes)), pass_begin_(std::move(pass_begin)),
      spp_(spp), settings_(settings) {
  // (Pass 0 never adapts: there is no film to plan it from.)
  first_barrier_ = uint32_t(passes_.size());
  for (uint32_t p = 1; p < passes_.size(); ++p)
    if (adaptive_pass(pass_begin_[p], spp_, std::numeric_limits<uint64_t>::max(), settings_)) {
      first_barrier_ = p;
      break;
    }
}

namespace {

size_t window_index(const TileRect& window, int x, int y) {
  return size_t(y - window.y0) * size_t(window.width()) + size_t(x - window.x0);
}

}  // namespace

std::vector<uint32_t> PassPlans::next_first() const {
  std::vector<uint32_t> first(size_t(window_.area()), pass_begin_[first_barrier_]);
  if (decided_passes() > 0)
    for (size_t i = 0; i < first.size(); ++i) first[i] = first_[i] + count_[i];
  return first;
}

void PassPlans::decide(uint32_t pass, const Film& film) {
  TESSERA_CHECK(pass == first_barrier_ + decided_passes() && pass < passes_.size());
  PassSamples s = plan_pass(film, next_first(), pass_begin_[pass], passes_[pass], spp_, &settings_);
  first_ = std::move(s.first);
  adopt(std::move(s.count));
}

bool PassPlans::restore(uint32_t pass, std::vector<uint32_t> counts, std::string& error) {
  const std::string what = "pass " + std::to_string(pass) + "'s stored sample counts ";
  if (pass != first_barrier_ + decided_passes() || pass >= passes_.size()) {
    error = what + "are out of order";
    return false;
  }
  const uint64_t total = std::accumulate(counts.begin(), counts.end(), uint64_t(0));
  const uint32_t cap = settings_.max_factor * passes_[pass];
  bool capped = true;
  for (uint32_t c : counts) capped &= c <= std::max(cap, passes_[pass]);
  if (counts.size() != size_t(window_.area()) || total != uint64_t(window_.area()) * passes_[pass] || !capped) {
    error = what + "do not fit the job";
    return false;
  }
  first_ = next_first();
  adopt(std::move(counts));
  return true;
}

void PassPlans::adopt(std::vector<uint32_t> counts) {
  count_ = std::move(counts);
  std::vector<uint64_t>& totals = tile_totals_.emplace_back(tiles_.size(), 0);
  for (size_t t = 0; t < tiles_.size(); ++t) {
    const TileRect& r = tiles_[t];
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) totals[t] += count_[window_index(window_, x, y)];
  }
}

PassSamples PassPlans::tile_samples(uint32_t tile, uint32_t pass) const {
  TESSERA_CHECK(decided_passes() > 0 && pass + 1 == first_barrier_ + decided_passes());
  PassSamples s;
  s.rect = tiles_[tile];
  for (int y = s.rect.y0; y < s.rect.y1; ++y)
    for (int x = s.rect.x0; x < s.rect.x1; ++x) {
      s.first.push_back(first_[window_index(window_, x, y)]);
      s.count.push_back(count_[window_index(window_, x, y)]);
    }
  return s;
}

bool PassPlans::matches(uint32_t tile, uint32_t pass, const FilmTile& film) const {
  if (count_.empty() || pass + 1 != first_barrier_ + decided_passes() || !(film.rect() == tiles_[tile]))
    return false;
  const TileRect& r = tiles_[tile];
  const std::vector<PixelSums>& px = film.pixels();
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x)
      if (px[size_t(y - r.y0) * size_t(r.width()) + size_t(x - r.x0)].count != count_[window_index(window_, x, y)])
        return false;
  return true;
}

}  // namespace tessera::server

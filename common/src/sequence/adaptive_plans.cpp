#include "tessera/sequence/adaptive_plans.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <numeric>

namespace tessera {

AdaptivePlans::AdaptivePlans(const TileRect& window, std::vector<TileRect> tiles, const PassProgram& program)
    : window_(window), tiles_(std::move(tiles)), passes_(program.passes), spp_(program.spp),
      settings_(program.adaptive_settings) {
  for (const PassSpec& p : passes_) adaptive_.push_back(p.adaptive);
}

namespace {

size_t window_index(const TileRect& window, int x, int y) {
  return size_t(y - window.y0) * size_t(window.width()) + size_t(x - window.x0);
}

}  // namespace

bool AdaptivePlans::decided(uint32_t pass) const {
  return !adaptive(pass) || std::find(decided_.begin(), decided_.end(), pass) != decided_.end();
}

// The next adaptive pass: the first one not decided (they are decided in pass order).
std::vector<uint32_t> AdaptivePlans::next_first() const {
  uint32_t next = 0;
  while (next < passes_.size() && (!adaptive(next) || decided(next))) ++next;
  std::vector<uint32_t> first(size_t(window_.area()), next < passes_.size() ? passes_[next].sample_begin : 0);
  if (!decided_.empty())  // (adaptive passes follow each other to the last: program_error)
    for (size_t i = 0; i < first.size(); ++i) first[i] = first_[i] + count_[i];
  return first;
}

void AdaptivePlans::decide(uint32_t pass, const Film& film) {
  TESSERA_CHECK(adaptive(pass) && !decided(pass));
  PassSamples s = plan_pass(film, next_first(), passes_[pass].sample_begin, passes_[pass].samples, spp_, &settings_);
  first_ = std::move(s.first);
  adopt(pass, std::move(s.count));
}

bool AdaptivePlans::restore(uint32_t pass, std::vector<uint32_t> counts, std::string& error) {
  const std::string what = "pass " + std::to_string(pass) + "'s stored sample counts ";
  uint32_t next = 0;
  while (next < passes_.size() && (!adaptive(next) || decided(next))) ++next;
  if (pass != next || pass >= passes_.size()) {
    error = what + "are out of order";
    return false;
  }
  const uint64_t total = std::accumulate(counts.begin(), counts.end(), uint64_t(0));
  const uint32_t n = passes_[pass].samples, cap = settings_.max_factor * n;
  bool capped = true;
  for (uint32_t c : counts) capped &= c <= std::max(cap, n);
  if (counts.size() != size_t(window_.area()) || total != uint64_t(window_.area()) * n || !capped) {
    error = what + "do not fit the job";
    return false;
  }
  first_ = next_first();
  adopt(pass, std::move(counts));
  return true;
}

void AdaptivePlans::adopt(uint32_t pass, std::vector<uint32_t> counts) {
  count_ = std::move(counts);
  decided_.push_back(pass);
  std::vector<uint64_t>& totals = tile_totals_.emplace_back(tiles_.size(), 0);
  for (size_t t = 0; t < tiles_.size(); ++t) {
    const TileRect& r = tiles_[t];
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) totals[t] += count_[window_index(window_, x, y)];
  }
}

uint64_t AdaptivePlans::samples(uint32_t tile, uint32_t pass) const {
  const auto it = std::find(decided_.begin(), decided_.end(), pass);
  TESSERA_CHECK(it != decided_.end());
  return tile_totals_[size_t(it - decided_.begin())][tile];
}

PassSamples AdaptivePlans::tile_samples(uint32_t tile, uint32_t pass) const {
  TESSERA_CHECK(is_latest(pass) && !count_.empty());
  PassSamples s;
  s.rect = tiles_[tile];
  for (int y = s.rect.y0; y < s.rect.y1; ++y)
    for (int x = s.rect.x0; x < s.rect.x1; ++x) {
      s.first.push_back(first_[window_index(window_, x, y)]);
      s.count.push_back(count_[window_index(window_, x, y)]);
    }
  return s;
}

bool AdaptivePlans::matches(uint32_t tile, uint32_t pass, const FilmTile& film) const {
  if (count_.empty() || !is_latest(pass) || !(film.rect() == tiles_[tile])) return false;
  const TileRect& r = tiles_[tile];
  const std::vector<PixelSums>& px = film.pixels();
  for (int y = r.y0; y < r.y1; ++y)
    for (int x = r.x0; x < r.x1; ++x)
      if (px[size_t(y - r.y0) * size_t(r.width()) + size_t(x - r.x0)].count != count_[window_index(window_, x, y)])
        return false;
  return true;
}

}  // namespace tessera

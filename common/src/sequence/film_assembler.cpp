#include "tessera/sequence/film_assembler.h"

#include "tessera/core/check.h"

#include <cmath>
#include <limits>

namespace tessera {
namespace {

// A pixel's term in an iteration's noise estimate counts at most this (its standard error at its
// own value): Müller clamps each pixel's variance likewise, so that a firefly does not decide an
// iteration's weight alone.
constexpr double kCombineClamp = 1.0;

}  // namespace

FilmAssembler::FilmAssembler(const PassProgram& program, std::vector<TileRect> tiles, const TileRect& window,
                             int full_width, int full_height, bool aovs)
    : program_(program), tiles_(std::move(tiles)), window_(window), full_width_(full_width),
      full_height_(full_height), aovs_(aovs) {
  for (const PassSpec& p : program_.passes)
    if (p.film != kNoFilm) primary_ = p.film;
  next_.assign(tiles_.size(), next_tile_pass(0));
  tile_counters_.assign(tiles_.size(), RenderCounters{});
  uint32_t first_paths = 0;
  while (first_paths < program_.passes.size() && program_.passes[first_paths].kind != UnitKind::Paths) ++first_paths;
  next_splat_ = {first_paths, 0};
}

// The first Tile pass at or after `after`.
uint32_t FilmAssembler::next_tile_pass(uint32_t after) const {
  while (after < program_.passes.size() && program_.passes[after].kind != UnitKind::Tile) ++after;
  return after;
}

void FilmAssembler::allocate() {
  if (!films_.empty() || released_) return;
  for (int f = 0; f < program_.films; ++f)
    films_.push_back(std::make_unique<Film>(window_, full_width_, full_height_, aovs_));
  splats_.resize(size_t(program_.films));
  splat_paths_.assign(size_t(program_.films), 0);
}

void FilmAssembler::release() {
  films_.clear();
  splats_.clear();
  held_tiles_.clear();
  held_splats_.clear();
  released_ = true;
}

void FilmAssembler::enter_tile(uint32_t pass, uint32_t tile, FilmTile& result) {
  const int f = program_.passes[pass].film;
  if (f != kNoFilm && !films_.empty()) films_[size_t(f)]->add_tile(result);
  tile_counters_[tile] += result.counters;
  counters_ += result.counters;
  ++changes_;
  next_[tile] = next_tile_pass(pass + 1);
}

void FilmAssembler::add_tile(uint32_t pass, uint32_t tile, FilmTile&& result) {
  TESSERA_CHECK(pass < program_.passes.size() && program_.passes[pass].kind == UnitKind::Tile);
  allocate();
  if (released_) {  // (a late result of a render whose image is written: counted only)
    counters_ += result.counters;
    return;
  }
  if (pass != next_[tile]) {
    held_tiles_.emplace(std::pair{pass, tile}, std::move(result));
    return;
  }
  enter_tile(pass, tile, result);
  for (auto it = held_tiles_.find({next_[tile], tile}); it != held_tiles_.end();
       it = held_tiles_.find({next_[tile], tile})) {
    enter_tile(it->first.first, tile, it->second);
    held_tiles_.erase(it);
  }
}

uint64_t FilmAssembler::unit_paths(uint32_t pass, uint32_t index) const {
  const uint64_t paths = pass_paths(program_.passes[pass], uint64_t(window_.area()));
  const uint64_t begin = uint64_t(index) * program_.paths_per_unit;
  return begin >= paths ? 0 : std::min(program_.paths_per_unit, paths - begin);
}

void FilmAssembler::add_splat(uint32_t pass, uint32_t index, SplatSums&& result) {
  TESSERA_CHECK(pass < program_.passes.size() && program_.passes[pass].kind == UnitKind::Paths);
  TESSERA_CHECK(result.window == window_ && result.pixel.size() == result.value.size());
  allocate();
  if (released_) {
    counters_ += result.counters;
    return;
  }
  held_splats_.emplace(std::pair{pass, index}, std::move(result));
  if (!fold_later_) (void)fold_splats(std::numeric_limits<size_t>::max());
}

size_t FilmAssembler::fold_splats(size_t max_splats) {
  size_t folded = 0;
  for (auto it = held_splats_.find(next_splat_); it != held_splats_.end() && folded < max_splats;
       it = held_splats_.find(next_splat_)) {
    const auto [p, i] = it->first;
    const int f = program_.passes[p].film;
    const SplatSums& s = it->second;
    const size_t end = std::min(s.pixel.size(), next_splat_entry_ + (max_splats - folded));
    if (f != kNoFilm && !films_.empty()) {
      std::vector<double>& layer = splats_[size_t(f)];
      if (layer.empty()) layer.assign(size_t(window_.area()) * 3, 0.0);
      for (size_t k = next_splat_entry_; k < end; ++k)
        for (int c = 0; c < 3; ++c) layer[size_t(s.pixel[k]) * 3 + size_t(c)] += s.value[k][size_t(c)];
    }
    folded += end - next_splat_entry_;
    next_splat_entry_ = end;
    ++changes_;
    if (end < s.pixel.size()) break;  // (the rest of this unit next time)
    if (f != kNoFilm && !films_.empty()) splat_paths_[size_t(f)] += unit_paths(p, i);
    counters_ += s.counters;
    held_splats_.erase(it);
    next_splat_entry_ = 0;
    next_splat_ = unit_paths(p, i + 1) > 0 ? std::pair{p, i + 1} : std::pair{p + 1, 0u};
    while (next_splat_.first < program_.passes.size() && program_.passes[next_splat_.first].kind != UnitKind::Paths)
      ++next_splat_.first;
  }
  return folded;
}

NoiseEstimate FilmAssembler::noise() const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (films_.empty()) return {kInf, 0};
  if (program_.combine == FilmCombine::Sum) return estimate_noise(*films_[0]);
  double total = 0;
  uint64_t pixels = 0;
  for (const auto& film : films_) {
    const NoiseEstimate e = estimate_noise(*film);
    if (std::isfinite(e.rel_mse)) total += 1.0 / (e.rel_mse + 1e-12), pixels = e.pixels;
  }
  return total > 0 ? NoiseEstimate{1.0 / total, pixels} : NoiseEstimate{kInf, 0};
}

void FilmAssembler::set_alike_from(uint32_t artifact) {
  for (const PassSpec& p : program_.passes)
    if (p.film != kNoFilm && p.uses && *p.uses >= artifact && (alike_from_ < 0 || p.film < alike_from_))
      alike_from_ = p.film;
}

std::vector<double> FilmAssembler::weights() const {
  std::vector<double> w(films_.size(), 0.0);
  if (program_.combine == FilmCombine::Sum) {
    w[0] = 1;
    return w;
  }
  double total = 0;
  for (size_t f = 0; f < films_.size(); ++f) {
    const double e = estimate_noise(*films_[f], kCombineClamp).rel_mse;
    w[f] = std::isfinite(e) ? 1.0 / (e + 1e-12) : 0.0;
    total += w[f];
  }
  if (alike_from_ >= 0) share_alike(w);
  for (double& x : w) x = total > 0 ? x / total : 1.0 / double(w.size());
  return w;
}

void FilmAssembler::share_alike(std::vector<double>& w) const {
  std::vector<double> samples(w.size(), 0.0);
  for (const PassSpec& p : program_.passes)
    if (p.kind == UnitKind::Tile && p.film >= alike_from_ && size_t(p.film) < w.size())
      samples[size_t(p.film)] += p.samples;
  // (Among the films begun: one without samples yet keeps its weight of 0.)
  double group = 0, group_samples = 0;
  for (size_t f = size_t(alike_from_); f < w.size(); ++f)
    if (w[f] > 0) group += w[f], group_samples += samples[f];
  if (!(group_samples > 0)) return;
  for (size_t f = size_t(alike_from_); f < w.size(); ++f)
    if (w[f] > 0) w[f] = group * samples[f] / group_samples;
}

Film FilmAssembler::take_film(int f) {
  Film film = std::move(*films_[size_t(f)]);
  if (!splats_[size_t(f)].empty())
    film.set_splats(std::move(splats_[size_t(f)]), double(splat_paths_[size_t(f)]) / double(window_.area()));
  return film;
}

// Film f's image over row y of the window (3 floats per pixel): its mean plus its splats.
void FilmAssembler::pixel_row(int f, int y, std::vector<float>& row) const {
  const Film& film = *films_[size_t(f)];
  const std::vector<double>& layer = splats_[size_t(f)];
  const double per_pixel = double(splat_paths_[size_t(f)]) / double(window_.area());
  for (int x = window_.x0; x < window_.x1; ++x) {
    const Rgb m = film.mean({x, y});
    const size_t i = size_t(y - window_.y0) * size_t(window_.width()) + size_t(x - window_.x0);
    for (int c = 0; c < 3; ++c) {
      double v = m[c];
      if (!layer.empty() && per_pixel > 0) v += layer[i * 3 + size_t(c)] / per_pixel;
      row[size_t(x - window_.x0) * 3 + size_t(c)] = float(v);
    }
  }
}

Image FilmAssembler::image() const {
  Image img(window_.width(), window_.height(), 3);
  image_rows(img, 0, window_.height());
  return img;
}

Image FilmAssembler::film_image(int f) const {
  Image img(window_.width(), window_.height(), 3);
  std::vector<float> row(size_t(window_.width()) * 3);
  for (int y = window_.y0; y < window_.y1; ++y) {
    pixel_row(f, y, row);
    for (int x = 0; x < window_.width(); ++x)
      img.set_rgb(x, y - window_.y0, Rgb(row[size_t(x) * 3], row[size_t(x) * 3 + 1], row[size_t(x) * 3 + 2]));
  }
  return img;
}

// Row y of the image by weights `w`: each film's pixel_row, summed in double and rounded once.
void FilmAssembler::combined_row(int y, const std::vector<double>& w, std::vector<float>& out) const {
  if (w.size() == 1) return pixel_row(0, y, out);
  std::vector<float> row(out.size());
  std::vector<double> sum(out.size(), 0.0);
  for (size_t f = 0; f < films_.size(); ++f) {
    if (w[f] == 0) continue;
    pixel_row(int(f), y, row);
    for (size_t i = 0; i < row.size(); ++i) sum[i] += w[f] * double(row[i]);
  }
  for (size_t i = 0; i < out.size(); ++i) out[i] = float(sum[i]);
}

void FilmAssembler::image_rows(Image& img, int row_begin, int row_end) const {
  TESSERA_CHECK(img.width() == window_.width() && img.height() == window_.height() && row_begin >= 0 &&
                row_end <= window_.height());
  if (films_.empty()) return;  // (black, as allocated)
  const std::vector<double> w = weights();
  std::vector<float> row(size_t(window_.width()) * 3);
  for (int y = window_.y0 + row_begin; y < window_.y0 + row_end; ++y) {
    combined_row(y, w, row);
    for (int x = 0; x < window_.width(); ++x)
      img.set_rgb(x, y - window_.y0, Rgb(row[size_t(x) * 3], row[size_t(x) * 3 + 1], row[size_t(x) * 3 + 2]));
  }
}

Film FilmAssembler::combined_film() const {
  Film out(window_, full_width_, full_height_, aovs_);
  if (films_.empty()) return out;
  const std::vector<double> w = weights();
  FilmTile all(window_, aovs_);
  std::vector<float> row(size_t(window_.width()) * 3);
  for (int y = window_.y0; y < window_.y1; ++y) {
    combined_row(y, w, row);
    for (int x = window_.x0; x < window_.x1; ++x) {
      const size_t i = size_t(y - window_.y0) * size_t(window_.width()) + size_t(x - window_.x0);
      uint64_t count = 0;
      Rgb variance;  // of the combined mean: the sum of w_f^2 times each film's
      for (size_t f = 0; f < films_.size(); ++f) {
        const uint64_t n = films_[f]->pixel({x, y}).count;
        count += n;
        if (w[f] > 0 && n > 0) variance += films_[f]->sample_variance({x, y}) * float(w[f] * w[f] / double(n));
      }
      // Over a power-of-two count the sum divides back to the image's float exactly; the sum of
      // squares gives the sample variance whose variance of the mean is the combination's.
      const double n = count ? std::ldexp(1.0, int(std::floor(std::log2(double(count))))) : 0.0;
      PixelSums& px = all.mutable_pixels()[i];
      px.count = uint64_t(n);
      for (int c = 0; c < 3 && n > 0; ++c) {
        const double m = double(row[size_t(x - window_.x0) * 3 + size_t(c)]);
        px.sum[c] = m * n;
        px.sum_sq[c] = double(variance[c]) * n * (n - 1) + n * m * m;
      }
      if (all.has_aovs()) all.mutable_aovs()[i] = films_[size_t(primary_)]->aov({x, y});
    }
  }
  out.add_tile(all);
  return out;
}

void FilmAssembler::aov_rows(AovLayer layer, Image& img, int row_begin, int row_end) const {
  if (films_.empty()) return;
  const Film& film = *films_[size_t(primary_)];
  if (film.has_aovs() || layer == AovLayer::Variance) film.aov_rows(layer, img, row_begin, row_end);
}

std::vector<FilmTile> FilmAssembler::tile_regions(uint32_t tile) const {
  const TileRect& r = tiles_[tile];
  std::vector<FilmTile> out;
  for (int f = 0; f < program_.films; ++f) {
    FilmTile& region = out.emplace_back(r, aovs_);
    if (films_.empty()) continue;
    const Film& film = *films_[size_t(f)];
    std::vector<PixelSums>& px = region.mutable_pixels();
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        const size_t i = size_t(y - r.y0) * size_t(r.width()) + size_t(x - r.x0);
        px[i] = film.pixel({x, y});
        if (region.has_aovs()) region.mutable_aovs()[i] = film.aov({x, y});
      }
  }
  out[0].counters = tile_counters_[tile];
  return out;
}

void FilmAssembler::restore_tile(uint32_t tile, uint32_t next_pass, std::vector<FilmTile>&& sums) {
  TESSERA_CHECK(sums.size() == size_t(program_.films));
  allocate();
  for (size_t f = 0; f < sums.size() && !films_.empty(); ++f) films_[f]->add_tile(sums[f]);
  counters_ += sums[0].counters;
  tile_counters_[tile] = sums[0].counters;
  next_[tile] = next_tile_pass(next_pass);
  ++changes_;
}

}  // namespace tessera

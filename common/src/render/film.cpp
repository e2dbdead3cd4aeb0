#include "tessera/render/film.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <cmath>

namespace tessera {

TileRect film_window(const FilmSettings& film) {
  if (film.crop_width <= 0 || film.crop_height <= 0) return {0, 0, film.width, film.height};
  return {film.crop_x, film.crop_y, film.crop_x + film.crop_w(), film.crop_y + film.crop_h()};
}

RenderCounters& RenderCounters::operator+=(const RenderCounters& o) {
  samples += o.samples;
  camera_rays += o.camera_rays;
  bounce_rays += o.bounce_rays;
  shadow_rays += o.shadow_rays;
  nonfinite += o.nonfinite;
  return *this;
}

FilmTile::FilmTile(const TileRect& rect, bool aovs) { reset(rect, aovs); }

void FilmTile::reset(const TileRect& rect, bool aovs) {
  TESSERA_CHECK(!rect.empty());
  rect_ = rect;
  pixels_.assign(size_t(rect.area()), PixelSums{});
  if (aovs) aovs_.assign(size_t(rect.area()), AovSums{});
  else aovs_.clear();
  counters = {};
}

namespace {

// A feature that is not finite (a degenerate BSDF sample) counts as 0, as a beauty sample does.
double finite_or_zero(float v) { return std::isfinite(v) ? double(v) : 0.0; }

}  // namespace

void FilmTile::add_sample(Vec2i pixel, Rgb value, uint32_t index_in_pixel, const SampleFeatures& f) {
  add_sample(pixel, value);
  TESSERA_DCHECK(!aovs_.empty());
  AovSums& a = aovs_[index(pixel)];
  for (int c = 0; c < 3; ++c) {
    a.albedo[c] += finite_or_zero(f.albedo[c]);
    a.normal[c] += finite_or_zero(f.normal[c]);
  }
  a.depth += finite_or_zero(f.depth);
  if (index_in_pixel % 2 != 0) return;
  ++a.half_count;
  if (value.is_finite())
    for (int c = 0; c < 3; ++c) a.half_sum[c] += double(value[c]);
}

Film::Film(const TileRect& window, int full_width, int full_height, bool aovs)
    : window_(window), full_width_(full_width), full_height_(full_height) {
  TESSERA_CHECK(!window.empty());
  pixels_.assign(size_t(window.area()), PixelSums{});
  if (aovs) aovs_.assign(size_t(window.area()), AovSums{});
}

Film::Film(const FilmSettings& s, bool aovs) : Film(film_window(s), s.width, s.height, aovs) {}

void Film::add_tile(const FilmTile& tile) {
  const TileRect& r = tile.rect();
  TESSERA_CHECK(window_.contains(r));
  TESSERA_CHECK(tile.has_aovs() == has_aovs());
  const auto& src = tile.pixels();
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const size_t i = size_t(y - r.y0) * size_t(r.width()) + size_t(x - r.x0);
      const PixelSums& s = src[i];
      PixelSums& d = pixels_[index({x, y})];
      for (int c = 0; c < 3; ++c) {
        d.sum[c] += s.sum[c];
        d.sum_sq[c] += s.sum_sq[c];
      }
      d.count += s.count;
      if (has_aovs()) add_aov_sums(aovs_[index({x, y})], tile.aovs()[i]);
    }
  }
}


Rgb Film::mean(Vec2i p) const {
  const PixelSums& s = pixel(p);
  Rgb m;
  if (s.count > 0) {
    const double inv = 1.0 / double(s.count);
    m = {float(s.sum[0] * inv), float(s.sum[1] * inv), float(s.sum[2] * inv)};
  }
  if (splats_.empty() || !(splat_paths_per_pixel_ > 0)) return m;
  const size_t i = index(p) * 3;
  for (int c = 0; c < 3; ++c) m[c] = float(double(m[c]) + splats_[i + size_t(c)] / splat_paths_per_pixel_);
  return m;
}

void Film::set_splats(std::vector<double> sums, double paths_per_pixel) {
  TESSERA_CHECK(sums.empty() || sums.size() == pixels_.size() * 3);
  splats_ = std::move(sums);
  splat_paths_per_pixel_ = paths_per_pixel;
}

Rgb Film::sample_variance(Vec2i p) const {
  const PixelSums& s = pixel(p);
  if (s.count < 2) return {};
  double n = double(s.count);
  Rgb v;
  for (int c = 0; c < 3; ++c) {
    double m = s.sum[c] / n;
    v[c] = float(std::max(0.0, (s.sum_sq[c] - n * m * m) / (n - 1)));
  }
  return v;
}

std::vector<float> Film::to_rgb() const {
  std::vector<float> out;
  out.reserve(pixels_.size() * 3);
  for (int y = window_.y0; y < window_.y1; ++y)
    for (int x = window_.x0; x < window_.x1; ++x) {
      Rgb m = mean({x, y});
      out.push_back(m.r);
      out.push_back(m.g);
      out.push_back(m.b);
    }
  return out;
}

Image Film::to_image() const {
  Image img(width(), height(), 3);
  to_image_rows(img, 0, height());
  return img;
}

void Film::to_image_rows(Image& img, int row_begin, int row_end) const {
  TESSERA_CHECK(img.width() == width() && img.height() == height() && row_begin >= 0 && row_end <= height());
  for (int y = window_.y0 + row_begin; y < window_.y0 + row_end; ++y)
    for (int x = window_.x0; x < window_.x1; ++x) img.set_rgb(x - window_.x0, y - window_.y0, mean({x, y}));
}

Image Film::aov_image(AovLayer layer) const {
  Image img(width(), height(), layer == AovLayer::Depth ? 1 : 3);
  aov_rows(layer, img, 0, height());
  return img;
}

void Film::aov_rows(AovLayer layer, Image& img, int row_begin, int row_end) const {
  TESSERA_CHECK(img.width() == width() && img.height() == height() && row_begin >= 0 && row_end <= height());
  if (layer == AovLayer::Variance) return variance_rows(img, row_begin, row_end);
  TESSERA_CHECK(has_aovs() && img.channels() == (layer == AovLayer::Depth ? 1 : 3));
  for (int y = window_.y0 + row_begin; y < window_.y0 + row_end; ++y)
    for (int x = window_.x0; x < window_.x1; ++x) {
      const PixelSums& p = pixel({x, y});
      const AovSums& a = aov({x, y});
      const double n = double(p.count), inv = p.count > 0 ? 1.0 / n : 0.0;
      double v[3] = {0, 0, 0};
      for (int c = 0; c < 3; ++c) {
        switch (layer) {
          case AovLayer::Albedo: v[c] = a.albedo[c] * inv; break;
          case AovLayer::Normal: v[c] = a.normal[c] * inv; break;
          case AovLayer::Depth: v[c] = a.depth * inv; break;
          case AovLayer::HalfA: v[c] = a.half_count > 0 ? a.half_sum[c] / double(a.half_count) : 0.0; break;
          default: {
            const uint64_t nb = p.count - a.half_count;
            v[c] = nb > 0 ? (p.sum[c] - a.half_sum[c]) / double(nb) : 0.0;
          }
        }
      }
      for (int c = 0; c < img.channels(); ++c) img.at(x - window_.x0, y - window_.y0, c) = float(v[c]);
    }
}

std::vector<ImageLayer> Film::aov_layers(const std::vector<AovLayer>& layers) const {
  std::vector<ImageLayer> out;
  for (AovLayer l : layers) out.push_back({aov_layer_name(l), aov_channel_names(l), aov_image(l)});
  return out;
}

Image Film::variance_image() const {
  Image img(width(), height(), 3);
  variance_rows(img, 0, height());
  return img;
}

void Film::variance_rows(Image& img, int row_begin, int row_end) const {
  for (int y = window_.y0 + row_begin; y < window_.y0 + row_end; ++y)
    for (int x = window_.x0; x < window_.x1; ++x) {
      uint64_t n = pixel({x, y}).count;
      Rgb v = n > 0 ? sample_variance({x, y}) / float(n) : Rgb();
      img.set_rgb(x - window_.x0, y - window_.y0, v);
    }
}

}  // namespace tessera

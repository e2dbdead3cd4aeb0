#include "tessera/render/film.h"

#include "tessera/core/check.h"

#include <algorithm>

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

FilmTile::FilmTile(const TileRect& rect) { reset(rect); }

void FilmTile::reset(const TileRect& rect) {
  TESSERA_CHECK(!rect.empty());
  rect_ = rect;
  pixels_.assign(size_t(rect.area()), PixelSums{});
  counters = {};
}

Film::Film(const TileRect& window, int full_width, int full_height)
    : window_(window), full_width_(full_width), full_height_(full_height) {
  TESSERA_CHECK(!window.empty());
  pixels_.assign(size_t(window.area()), PixelSums{});
}

Film::Film(const FilmSettings& s) : Film(film_window(s), s.width, s.height) {}

void Film::add_tile(const FilmTile& tile) {
  const TileRect& r = tile.rect();
  TESSERA_CHECK(window_.contains(r));
  const auto& src = tile.pixels();
  for (int y = r.y0; y < r.y1; ++y) {
    for (int x = r.x0; x < r.x1; ++x) {
      const PixelSums& s = src[size_t(y - r.y0) * size_t(r.width()) + size_t(x - r.x0)];
      PixelSums& d = pixels_[index({x, y})];
      for (int c = 0; c < 3; ++c) {
        d.sum[c] += s.sum[c];
        d.sum_sq[c] += s.sum_sq[c];
      }
      d.count += s.count;
    }
  }
}

Rgb Film::mean(Vec2i p) const {
  const PixelSums& s = pixel(p);
  if (s.count == 0) return {};
  double inv = 1.0 / double(s.count);
  return {float(s.sum[0] * inv), float(s.sum[1] * inv), float(s.sum[2] * inv)};
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

Image Film::variance_image() const {
  Image img(width(), height(), 3);
  for (int y = window_.y0; y < window_.y1; ++y)
    for (int x = window_.x0; x < window_.x1; ++x) {
      uint64_t n = pixel({x, y}).count;
      Rgb v = n > 0 ? sample_variance({x, y}) / float(n) : Rgb();
      img.set_rgb(x - window_.x0, y - window_.y0, v);
    }
  return img;
}

}  // namespace tessera

// Sample accumulation.
//
// Every pixel keeps double-precision sums of its samples' RGB and of their squares (for variance
// estimates) and a sample count. A FilmTile holds the sums of ONE pass over one rectangle; the
// Film adds finished tile passes. Each pixel's value is therefore
//   ((s_0 + s_1 + ...) in index order within a pass) + ... in pass order,
// which makes the result independent of thread count, tile size and the machine a tile ran on.
// Non-finite samples never reach the sums: they count as a sample of value 0 and are tallied.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/image/image.h"
#include "tessera/render/aov.h"
#include "tessera/render/camera.h"

#include <cstdint>
#include <vector>

namespace tessera {

/// Half-open pixel rectangle [x0, x1) x [y0, y1) in full-film raster pixels.
struct TileRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
  int64_t area() const { return int64_t(width()) * height(); }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  bool contains(Vec2i p) const { return p.x >= x0 && p.x < x1 && p.y >= y0 && p.y < y1; }
  bool contains(const TileRect& r) const {
    return r.x0 >= x0 && r.y0 >= y0 && r.x1 <= x1 && r.y1 <= y1;
  }
  bool operator==(const TileRect&) const = default;
};

/// The film's crop window (the pixels that are rendered).
TileRect film_window(const FilmSettings& film);

struct PixelSums {
  double sum[3] = {0, 0, 0};
  double sum_sq[3] = {0, 0, 0};
  uint64_t count = 0;
};

/// Work done while rendering; a tile carries its own so that totals are exact whatever the
/// threading, and a remote tile can report them.
struct RenderCounters {
  uint64_t samples = 0;
  uint64_t camera_rays = 0;
  uint64_t bounce_rays = 0;   // continuation rays, including the direct integrator's BSDF rays
  uint64_t shadow_rays = 0;
  uint64_t nonfinite = 0;     // NaN/Inf samples dropped
  uint64_t rays() const { return camera_rays + bounce_rays + shadow_rays; }
  RenderCounters& operator+=(const RenderCounters& o);
};

class FilmTile {
 public:
  FilmTile() = default;
  explicit FilmTile(const TileRect& rect, bool aovs = false);
  /// Zeroes the sums and counters and moves the tile to `rect` (reuses storage); with `aovs` it
  /// also keeps the AOV sums (aov.h), which add_sample with features fills.
  void reset(const TileRect& rect, bool aovs = false);

  const TileRect& rect() const { return rect_; }
  /// Adds one sample of `pixel` (inside rect()). A non-finite value adds 0 and is counted.
  void add_sample(Vec2i pixel, Rgb value) {
    PixelSums& px = pixels_[index(pixel)];
    ++px.count;
    ++counters.samples;
    if (!value.is_finite()) {
      ++counters.nonfinite;
      return;
    }
    for (int c = 0; c < 3; ++c) {
      double v = value[c];
      px.sum[c] += v;
      px.sum_sq[c] += v * v;
    }
  }
  /// Adds sample `index` of `pixel` with its features (a tile reset with AOVs): as above, and the
  /// features' sums; an even index also goes to half A.
  void add_sample(Vec2i pixel, Rgb value, uint32_t index, const SampleFeatures& features);

  const PixelSums& pixel(Vec2i p) const { return pixels_[index(p)]; }
  const std::vector<PixelSums>& pixels() const { return pixels_; }
  /// For decoders of remote tile results (farm/tile_result.h); size stays rect().area().
  std::vector<PixelSums>& mutable_pixels() { return pixels_; }
  bool has_aovs() const { return !aovs_.empty(); }
  /// Empty without AOVs, else one per pixel.
  const std::vector<AovSums>& aovs() const { return aovs_; }
  std::vector<AovSums>& mutable_aovs() { return aovs_; }

  RenderCounters counters;

 private:
  size_t index(Vec2i p) const { return size_t(p.y - rect_.y0) * size_t(rect_.width()) + size_t(p.x - rect_.x0); }
  TileRect rect_;
  std::vector<PixelSums> pixels_;
  std::vector<AovSums> aovs_;
};

class Film {
 public:
  Film() = default;
  /// A film for the pixels of `window` (full-film coordinates); `full_width/height` are the
  /// film's complete size, kept for writers that need the crop offset.
  /// With `aovs` the film also keeps the AOV sums, and takes only tiles that have them.
  Film(const TileRect& window, int full_width, int full_height, bool aovs = false);
  explicit Film(const FilmSettings& settings, bool aovs = false);

  const TileRect& window() const { return window_; }
  int width() const { return window_.width(); }
  int height() const { return window_.height(); }
  int full_width() const { return full_width_; }
  int full_height() const { return full_height_; }

  /// Adds the pixel sums of a finished tile pass (must lie inside window()). Concurrent calls for
  /// disjoint tiles are safe; the tile's counters are NOT added (see add_counters).
  void add_tile(const FilmTile& tile);
  void add_counters(const RenderCounters& c) { counters_ += c; }

  /// Pixel by full-film coordinates.
  const PixelSums& pixel(Vec2i p) const { return pixels_[index(p)]; }
  Rgb mean(Vec2i p) const;
  /// Unbiased sample variance of the pixel's samples, per channel (0 with fewer than 2 samples).
  Rgb sample_variance(Vec2i p) const;

  /// Mean radiance, row-major over window(), 3 floats per pixel.
  std::vector<float> to_rgb() const;
  /// Mean radiance as a 3-channel linear image of the window.
  Image to_image() const;
  /// Rows [row_begin, row_end) of to_image() (counted from the window's top) into `img`, which has
  /// the window's size: a large film converted a band at a time.
  void to_image_rows(Image& img, int row_begin, int row_end) const;
  /// Per-pixel variance of the mean (sample variance / count), 3 channels: a noise estimate.
  Image variance_image() const;

  bool has_aovs() const { return !aovs_.empty(); }
  /// An AOV layer over window() (aov.h): the mean of the pixel's features, the variance image, or
  /// the mean of half A's or half B's samples (0 for a half without samples). Requires has_aovs()
  /// except for Variance.
  Image aov_image(AovLayer layer) const;
  /// Rows [row_begin, row_end) of aov_image(layer) into `img` (the window's size, the layer's
  /// channels): a large film converted a band at a time.
  void aov_rows(AovLayer layer, Image& img, int row_begin, int row_end) const;
  const AovSums& aov(Vec2i p) const { return aovs_[index(p)]; }
  /// The layers, named and with channel names as written into an EXR (aov.h).
  std::vector<ImageLayer> aov_layers(const std::vector<AovLayer>& layers) const;

  const RenderCounters& counters() const { return counters_; }

  /// Light paths' splats (light tracing, bidirectional methods: sequence/splat_sums.h): 3 sums
  /// per window pixel, from `paths_per_pixel` light paths per pixel. From then on a pixel's mean
  /// is its samples' mean plus its splat sum over paths_per_pixel, rounded as FilmAssembler's image
  /// rounds it (so the two are the same bits); the variance stays its samples'.
  void set_splats(std::vector<double> sums, double paths_per_pixel);
  bool has_splats() const { return !splats_.empty(); }

 private:
  size_t index(Vec2i p) const { return size_t(p.y - window_.y0) * size_t(window_.width()) + size_t(p.x - window_.x0); }
  void variance_rows(Image& img, int row_begin, int row_end) const;
  TileRect window_;
  int full_width_ = 0, full_height_ = 0;
  std::vector<PixelSums> pixels_;
  std::vector<AovSums> aovs_;
  RenderCounters counters_;
  std::vector<double> splats_;
  double splat_paths_per_pixel_ = 0;
};

}  // namespace tessera

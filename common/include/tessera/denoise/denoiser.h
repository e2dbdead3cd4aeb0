// Tessera's denoiser: a render's noisy image and its AOV layers (render/aov.h) in, a denoised image
// out. No trained weights; deterministic (the same bits for any thread count).
//
// Full mode (after Bitterli et al. 2016, "Nonlinearly Weighted First-order Regression for Denoising
// Monte Carlo Renderings"):
//   1. Filter each half image (half_a, half_b) by first-order regression on the features (albedo,
//      normal, depth) with non-local-means weights from the OTHER half, at two bandwidths; a
//      candidate is the mean of its two filtered halves.
//   2. Estimate each candidate's error per pixel from the halves (a filtered half against the other,
//      raw half, less that half's variance) and, smoothed over 7×7 pixels, keep the candidate with
//      the smallest, or the raw pixel where no filter beats its own variance.
// Colour is not divided by the albedo first: with the albedo a regression feature that gained
// nothing, and dividing by a noisy albedo (glossy and coated surfaces) and multiplying back shifted
// bathroom's mean by +1.3% (docs/denoising.md).
// Preview mode: the same with a smaller window and one bandwidth.
#pragma once

#include "tessera/image/image.h"
#include "tessera/render/aov.h"

#include <string>
#include <vector>

namespace tessera {

/// What the denoiser reads: float32 images of one size. `color`, `variance`, `albedo`, `half_a`,
/// `half_b` have 3 channels, `normal` 3, `depth` 1.
struct DenoiseInput {
  Image color, albedo, normal, depth, variance, half_a, half_b;
};

enum class DenoiseMode { Full, Preview };

struct DenoiseSettings {
  DenoiseMode mode = DenoiseMode::Full;
  int threads = 0;  // 0: every hardware thread (the result does not depend on it)
};

/// The AOV layers the denoiser needs (every layer but none optional).
std::vector<AovLayer> denoise_layers();

/// From a multi-layer EXR written with those layers (`tessera render --aovs all`); `attributes`, if
/// given, receives its header's attributes. Throws SceneError naming the file and every missing layer.
DenoiseInput read_denoise_input(const std::string& path, ImageAttributes* attributes = nullptr);

/// Builds the input from a beauty image and its layers (as written to an EXR); throws
/// std::invalid_argument naming a missing layer or a size that differs from the beauty's.
DenoiseInput make_denoise_input(const Image& color, const std::vector<ImageLayer>& layers);

/// The input's AOV layers, named as written into an EXR (the inverse of make_denoise_input).
std::vector<ImageLayer> denoise_input_layers(const DenoiseInput& input);

/// The denoised image (3 channels, the input's size); never NaN or Inf.
Image denoise(const DenoiseInput& input, const DenoiseSettings& settings = {});

}  // namespace tessera

// Image statistics and comparisons, for tests and for judging renders against the Mitsuba
// references in ../shared/references/NAME/{reference,variance}.exr.
#pragma once

#include "tessera/image/image.h"

#include <string>
#include <vector>

namespace tessera {

/// Mean of each channel over all pixels (double accumulation).
std::vector<double> channel_means(const Image& image);
/// Number of NaN or infinite values.
size_t count_non_finite(const Image& image);

/// Relative MSE, the convention of Mitsuba's and Bitterli's comparisons:
///   mean over pixels and channels of (a - ref)^2 / (ref^2 + epsilon).
/// epsilon = 1e-2 by default: it keeps near-black reference pixels (where the ratio explodes and
/// which say nothing about bias) from dominating; a pixel of 0.1 has its weight halved, pixels
/// above ~0.3 are almost purely relative. Throws std::invalid_argument on a size/channel mismatch.
double rel_mse(const Image& a, const Image& ref, double epsilon = 1e-2);
/// What rel_mse against `ref` gains in expectation from the reference's own noise, given its
/// per-pixel variance: mean of var / (ref^2 + epsilon). A render's error cannot go below it.
double rel_mse_floor(const Image& ref, const Image& ref_variance, double epsilon = 1e-2);
double mse(const Image& a, const Image& b);
/// Mean over pixels and channels of |a - b|.
double mean_abs_error(const Image& a, const Image& b);

/// Per-pixel agreement of a render with a reference whose per-pixel variance (of the mean) is known.
/// For each pixel and channel z = (a - ref) / sqrt(var_ref + var_a + floor); without bias, z has
/// mean ~0 and mean square ~1 (for many samples per pixel). `a_variance` may be null (renders with
/// many more samples than the reference).
struct ZScoreStats {
  double mean_z = 0;         // a systematic offset shows here first
  double mean_z2 = 0;        // ~1 when unbiased; >> 1 when biased or the variances are wrong
  double frac_above_4 = 0;   // fraction of |z| > 4 (0.006% for a true normal)
  size_t count = 0;
};
ZScoreStats z_score_stats(const Image& a, const Image& ref, const Image& ref_variance,
                          const Image* a_variance = nullptr, double variance_floor = 1e-8);

/// Box-downsamples by an integer factor (partial blocks at the right/bottom edge are averaged over
/// the pixels they have). Averaging pixels trades resolution for noise when comparing renders.
Image downsample(const Image& image, int factor);
/// Same for a per-pixel variance image: the variance of a mean of k pixels is sum(var)/k^2.
Image downsample_variance(const Image& variance, int factor);

/// "256x256x3" for messages.
std::string describe_size(const Image& image);

}  // namespace tessera

// How noisy is an image, without a reference? The film keeps each pixel's sum and sum of squares,
// so the variance of each pixel's mean is known; its expectation is the squared error of that
// pixel against the converged image. Averaged in the relMSE form the benchmarks use against
// references, (x - ref)^2 / (ref^2 + 0.01), with the pixel's own mean standing in for ref:
//
//   estimate = mean over pixels and channels of  (s^2 / n) / (mean^2 + 0.01)
//
// It is an estimate: with few samples a pixel's variance is itself noisy (fireflies not yet
// seen count as zero), and the mean stands in for the reference. Pixels with fewer than two
// samples have no variance: an estimate over a film with any such pixel is +infinity.
#pragma once

#include "tessera/render/film.h"

#include <limits>

namespace tessera {

struct NoiseEstimate {
  double rel_mse = 0;     // the estimate above (+inf when not estimable)
  uint64_t pixels = 0;    // pixels it averages
};

/// With `clamp`, each pixel's and channel's term counts at most `clamp` (a single firefly then
/// weighs no more than any other noisy pixel).
NoiseEstimate estimate_noise(const Film& film, double clamp = std::numeric_limits<double>::infinity());

}  // namespace tessera

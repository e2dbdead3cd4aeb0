// Weighted first-order regression with non-local-means weights (after Bitterli et al. 2016, NFOR):
// each pixel's value is the intercept of a weighted least-squares fit of `value` over the pixels of
// a (2r+1)² window, linear in the features' differences from the pixel's own. The weights compare
// 7×7 patches of `guide` around the pixel and the neighbour, discounting their variance
// (Rousselle et al. 2012):
//   d² = mean over patch and channels of ((g_p - g_q)² - α (v_p + min(v_p, v_q))) / (ε + k² (v_p + v_q))
//   w  = exp(-max(0, d²))
// so pixels that differ by no more than their noise count fully. Filtering a half image with weights
// from the other half keeps the weights independent of the values they average.
//
// Each pixel's result depends only on the inputs around it, summed in a fixed order: the same bits
// for any thread count.
#pragma once

#include "denoise/planes.h"

namespace tessera::denoise_detail {

struct RegressionParams {
  int radius = 7;    // window (2r+1)²
  int patch = 3;     // patch (2f+1)²
  float k = 0.5f;    // weight bandwidth: larger averages more
  float alpha = 1.f; // variance cancellation
};

/// `guide` and `guide_var` (3 channels each) give the weights, `value` (3 channels) is averaged,
/// `features` (any number of channels) are the regression's variables. All of one size.
Planes regression_filter(const Planes& guide, const Planes& guide_var, const Planes& value, const Planes& features,
                         const RegressionParams& params);

}  // namespace tessera::denoise_detail

// `tessera bench convergence`: error against a reference image as the sample budget grows, per
// sampling strategy (integrator.h), with the reference-free noise estimate beside the true error.
// The pieces (metrics, time to target, CSV, SVG) are separate functions so tests can feed them
// known numbers; run_bench_convergence only strings them together around render().
#pragma once

#include "tessera/image/image.h"

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace tessera::cli {

struct ConvergenceOptions {
  std::string scene, reference;
  /// Budgets in samples per pixel, rendered in this order. Empty: 1, 2, 4, ..., 64 (or, with
  /// `seconds`, doubling from 1).
  std::vector<int> spp;
  /// > 0: after the listed budgets, keep doubling spp until one render takes at least this long
  /// (capped at 65536 spp), so each strategy spends about twice this in total.
  double seconds = 0;
  std::vector<std::string> strategies;  // "mis", "bsdf", "nee"; empty: mis
  std::vector<std::string> guiding;     // "off", "on" (each strategy with each); empty: off
  std::vector<std::string> adaptive;    // "off", "on" (each series with each); empty: off
  std::string csv, plot;                // output paths; empty: not written
  int width = 0, height = 0;            // > 0: film size (the reference must match it)
  int threads = 0;                      // 0: all cores
  uint32_t seed = 0;                    // budget i renders with seed + i
  std::string integrator;                // non-empty: overrides the scene's (LoadOptions::integrator)
  bool allow_unsupported = false;
};

/// Error of an image against a reference, both RGB of the same size.
struct ErrorMetrics {
  double rel_mse = 0;       // mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01)
  double rel_mse_trim = 0;  // the same without the pixels of the largest errors (trim_fraction)
  double mse = 0;
  double mean_ratio = 0;    // sum of x over sum of ref, all channels (1: no bias in the mean)
};

/// `trim_fraction` of the pixels (rounded down) with the largest per-pixel relative error (mean
/// over its channels) are left out of rel_mse_trim: a few fireflies then do not hide the trend.
/// Throws std::invalid_argument on a size mismatch.
ErrorMetrics measure_error(const Image& image, const Image& ref, double trim_fraction = 0.001);

struct ConvergencePoint {
  std::string strategy;
  int spp = 0;
  double seconds = 0;  // render time (the scene loaded once, before)
  ErrorMetrics error;
  double noise_estimate = 0;  // estimate_noise() of the film: +inf below 2 spp
};

struct TimeToTarget {
  bool reached = false;
  double seconds = 0;
  /// Already below the target at the first budget: `seconds` is that budget's, an upper bound.
  bool at_first_budget = false;
};

/// When the relMSE of one strategy's points (in budget order) first falls to `target`: linear
/// interpolation in log(seconds)-log(relMSE) between the last budget above and the first at or
/// below it.
TimeToTarget time_to_target(const std::vector<ConvergencePoint>& points, double target);

/// Header `strategy,spp,seconds,relmse,relmse_trim,mse,mean_ratio,noise_estimate`, one row a point.
void write_convergence_csv(std::ostream& out, const std::vector<ConvergencePoint>& points);

/// A standalone SVG: two log-log panels, relMSE against seconds and against spp, one polyline
/// (with markers) per strategy in order of first appearance, decade ticks and labels, a legend.
/// Points with non-positive or non-finite coordinates are left out.
std::string convergence_svg(const std::vector<ConvergencePoint>& points, const std::string& title);

/// Prints one line per render and the times to relMSE 0.01 and 0.001; returns the exit code.
int run_bench_convergence(const ConvergenceOptions& options);

}  // namespace tessera::cli

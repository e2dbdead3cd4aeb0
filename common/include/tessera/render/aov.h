// Arbitrary output variables (AOVs): what a denoiser needs besides the beauty image.
//
// Features are taken where a camera path first meets something that is not a perfect mirror or
// pane of glass, following delta (specular) bounces as Cycles does for its denoising passes:
//   albedo   the throughput of the specular chain so far times an estimate of the BSDF's
//            directional albedo there: the path's own BSDF sample weight (eval·|cos|/pdf) at that
//            vertex, whose mean over a pixel's samples is the albedo (exactly the reflectance for
//            a diffuse surface). At a scattering point in a medium: the throughput there.
//            0 where the path leaves the scene or ends first.
//   normal   the shading normal there (world space, unit length; the pixel's value is the mean of
//            its samples' normals, so shorter at silhouettes); 0 in a medium or where none is hit.
//   depth    the distance from the camera ray's origin to the first surface it hits (index-matched
//            boundaries of media are not surfaces); 0 where it hits none.
// Besides them the film keeps half A of each pixel's samples: those of even sample index. Half B is
// the rest. Under the independent sampler the halves are independent; under Owen-scrambled Sobol
// the two samples of each pair (2k, 2k+1) are stratified against each other, which makes the
// halves' difference somewhat larger than two independent halves' would be (docs/denoising.md).
//
// Capturing features draws no sampler dimension and changes no sample's value: the beauty image is
// the same bits with and without AOVs.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

/// The features of one camera sample (see above). `found` stays false until the path meets the
/// vertex they are taken at.
struct SampleFeatures {
  Rgb albedo;
  Vec3 normal{0.f};
  float depth = 0.f;
  bool found = false;
  bool depth_found = false;
};

/// Per-pixel sums of the features, and of half A's samples.
struct AovSums {
  double albedo[3] = {0, 0, 0};
  double normal[3] = {0, 0, 0};
  double depth = 0;
  double half_sum[3] = {0, 0, 0};  // samples of even index (non-finite ones count as 0)
  uint64_t half_count = 0;
};
/// d += s, field by field (a tile's sums into the film's).
void add_aov_sums(AovSums& d, const AovSums& s);

/// The layers a render can write beside the beauty image, in the order written.
enum class AovLayer : uint8_t { Albedo, Normal, Depth, Variance, HalfA, HalfB };
constexpr int kAovLayerCount = 6;

/// "albedo", "normal", "depth", "variance", "half_a", "half_b": the EXR layer names.
const char* aov_layer_name(AovLayer layer);
/// The layer's channel names: R,G,B (albedo, variance, halves), X,Y,Z (normal) or Z (depth).
std::vector<std::string> aov_channel_names(AovLayer layer);
/// A comma-separated list of layer names, or "all" (every layer). Empty optional on an unknown
/// name, which `error` then names.
std::optional<std::vector<AovLayer>> parse_aov_layers(const std::string& list, std::string* error = nullptr);

}  // namespace tessera

// The path tracer's side of path guiding (guiding/spatial_tree.h): what one render pass asks of
// the integrator, and the radiance a path brings back to the vertices where it chose a direction.
//
// Training record (Müller et al. 2017): at a vertex where the path sampled direction wi with
// (mixture) pdf p, the radiance arriving along wi is what the rest of the path added to the
// camera's estimate, over the path's throughput after that vertex: Li = dL / T. The guide records
// luminance(Li) / p, an estimate of the incident radiance integrated over the leaf's cells, at wi.
// A guided vertex also records luminance(f * cos * Li) / p with the mixture's two pdfs there, the
// loss from which its leaf learns the BSDF fraction (guiding/bsdf_fraction.h).
// Its rounding dither comes from a stream seeded by a dedicated sampler dimension (sampler.h), so
// the statistics are a function of (pixel, sample index, seed) like every sample value.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/guiding/guide_gain.h"
#include "tessera/guiding/spatial_tree.h"
#include "tessera/render/guided_sampling.h"

#include <cstdint>
#include <optional>

namespace tessera {

class Sampler;

/// What a pass asks of the path tracer (null: no guiding at all).
struct PathGuide {
  const SpatialTree* tree = nullptr;  // the learned distributions, and the leaves records go to
  SpatialTree* records = nullptr;     // where training records go: `tree`, or a recorder of it (tree_io.h)
  bool sample = false;                // guide directions with the tree's learned distributions
  bool train = false;                 // record the pass's radiance into `records`
  /// Russian roulette once the guide samples (before, by throughput).
  GuideRoulette roulette = GuideRoulette::Throughput;
  /// Where training records go (GuidingSettings).
  SpatialFilter spatial_filter = SpatialFilter::Nearest;
  DirectionalFilter directional_filter = DirectionalFilter::Nearest;

  /// A pass's guide as `settings` ask (the one way the renderer and the farm's worker make it):
  /// none once guiding stepped aside (SpatialTree::stepped_aside), when the pass renders as the
  /// unguided path tracer.
  static std::optional<PathGuide> of(const SpatialTree* tree, SpatialTree* records, bool sample, bool train,
                                     const GuidingSettings& settings) {
    if (tree->stepped_aside()) return std::nullopt;
    return PathGuide{tree, records, sample, train, settings.roulette, settings.spatial_filter, settings.directional_filter};
  }
};

/// The vertices of one path that sampled a direction to record, and at the path's end the
/// radiance each received. Fixed capacity (no allocation): deeper vertices are not recorded.
class GuideRecords {
 public:
  static constexpr int kCapacity = 32;
  /// The dimension whose value seeds a path's dithers (of the pixel sample and of each vertex's
  /// record) and its stochastic spatial filter's jitter (far from the sequential dimensions).
  static constexpr uint32_t kRecordDimension = 0xFFFFFE00u;

  /// A vertex at `p` in `leaf` (whose region's size is `extent`) sampled `wi` (world) with density `pdf`, where the BSDF's f * cos has
  /// luminance `f_cos`; `throughput` is the path's after the vertex's weight (before Russian
  /// roulette), `radiance` the camera's estimate so far. `mixture` holds the two pdfs of a guided
  /// vertex (none when the guide did not sample).
  void add(Vec3 p, Vec3 extent, uint32_t leaf, Vec3 wi, float pdf, float f_cos, std::optional<MixturePdfs> mixture,
           const Rgb& throughput, const Rgb& radiance) {
    if (mixture && mixture->bsdf > 0.f && pdf > 0.f) gain_.scattered(radiance.luminance(), pdf, mixture->bsdf);
    if (count_ >= kCapacity) return;
    // (A guided vertex knows where wi lies on the guide's square; otherwise it is mapped here.)
    const Vec2 square = mixture ? mixture->square : direction_to_square(wi);
    vertices_.at[size_t(count_++)] = {p, extent, leaf, square, pdf, f_cos, mixture, throughput, radiance};
  }
  /// Records every vertex into `guide.records` (through its filters) once the path's estimate is
  /// `radiance`, and that estimate as a pixel sample at the first vertex's leaf; in a pass that
  /// guides, also the path's second moments (guide_gain.h), a path without vertices too.
  void commit(const PathGuide& guide, const Rgb& radiance, Sampler& sampler) const;

 private:
  void record_gain(const PathGuide& guide, const Rgb& radiance, float dither) const;
  struct Vertex {
    Vec3 p, extent;
    uint32_t leaf;
    Vec2 square;  // wi's point on the guide's square
    float pdf, f_cos;
    std::optional<MixturePdfs> mixture;
    Rgb throughput, radiance;
  };
  // Left unmade: every path of a guided render makes a GuideRecords, and zeroing its 2.8 KB cost
  // more than most paths' records. (Assigning an element begins its life: Vertex is an aggregate.)
  union Storage {
    Storage() {}
    Vertex at[kCapacity];
  } vertices_;
  int count_ = 0;
  PathGain gain_;
};

}  // namespace tessera

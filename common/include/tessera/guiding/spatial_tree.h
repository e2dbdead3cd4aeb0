// The spatial half of path guiding's SD-tree (Müller et al. 2017): a binary tree over the scene's
// bounds, cut at midpoints along x, y, z in turn, whose leaves each hold a directional tree
// (directional_tree.h) of the radiance arriving in that region: the one learned in the previous
// training iteration (sampled from) and the one being recorded.
//
// Deterministic: records are exact integer sums (see directional_tree.h) and a sample count per
// leaf, and end_iteration() decides every split from them in leaf order, so the trees are the
// same bits for any order of the records. Memory is capped: no leaf is split once the tree would
// exceed GuidingSettings::max_bytes.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/guiding/bsdf_fraction.h"
#include "tessera/guiding/directional_tree.h"
#include "tessera/guiding/guide_gain.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tessera {

/// How a guided render's iterations make its image (Müller's sampleCombination).
enum class GuideCombination : uint8_t {
  /// The last iteration alone (Müller 2017's "discard"): it has at least half the samples.
  Discard,
  /// The last `combined_iterations` iterations, each image weighted by the inverse of its
  /// estimated (clamped) relMSE (Müller 2019's "inversevar"). Consistent, not unbiased: the
  /// weights come from the images they weigh.
  InverseVariance,
};
const char* guide_combination_name(GuideCombination c);

/// Russian roulette on a guided render's paths.
enum class GuideRoulette : uint8_t {
  /// From the throughput, as unguided paths (path_integrator: Mitsuba 3's rule). It ends the paths
  /// a guide sends toward bright light through a small opening (their f·cos/p is small).
  Throughput,
  /// Müller's code: once the guide samples, a path survives a vertex with probability 0.99 whatever
  /// its throughput. Every path in a closed interior then runs to its maximum depth.
  Guided,
  /// Adjoint-driven (after Vorba and Křivánek 2016, without splitting; the default): a path
  /// survives a vertex with probability T·L̂(wi) / (0.1·Î) within [0.35, 0.99], its expected
  /// contribution over a tenth of the pixel's, from the guide's estimates (SpatialTree::radiance,
  /// pixel); by its throughput where the guide has none.
  Radiance,
};
const char* guide_roulette_name(GuideRoulette r);
/// False when `name` is none of guide_roulette_name()'s.
[[nodiscard]] bool parse_guide_roulette(const std::string& name, GuideRoulette& out);

/// Where a training record goes in space (Müller 2019's spatialFilter).
enum class SpatialFilter : uint8_t {
  /// The leaf of the vertex (Müller 2017).
  Nearest,
  /// The leaf at a point drawn uniformly from a box of the vertex's leaf's size about the vertex
  /// ("stochastic"): a leaf also learns from its neighbours' edges, so small leaves are less noisy.
  Stochastic,
};
/// How a training record spreads over directions (Müller 2019's directionalFilter).
enum class DirectionalFilter : uint8_t {
  /// Into the directional cell of its direction (Müller 2017).
  Nearest,
  /// Over a square of the size of that cell about the direction's point, each cell it overlaps
  /// taking the share of the square's area it covers ("box").
  Box,
};
const char* spatial_filter_name(SpatialFilter f);
const char* directional_filter_name(DirectionalFilter f);
/// False when `name` is none of the names above.
[[nodiscard]] bool parse_spatial_filter(const std::string& name, SpatialFilter& out);
[[nodiscard]] bool parse_directional_filter(const std::string& name, DirectionalFilter& out);

struct GuidingSettings {
  /// c of the spatial split rule: a leaf is split at the end of an iteration of spp_k samples per
  /// pixel once its samples in it exceed c·sqrt(spp_k / 4) (Müller's sTreeThreshold, which his
  /// plugin applies as c·sqrt(2^k·sppPerPass / 4)). 4,000 goes with the directional box filter
  /// (Müller 2019); his plugin's default, without filters, is 12,000.
  double spatial_threshold = 4000.0;
  /// A direction quadrant is split when its share of its leaf's energy exceeds this (dTreeThreshold).
  double directional_threshold = 0.01;
  /// Cap on the memory of the whole tree.
  size_t max_bytes = size_t(256) << 20;
  /// Probability of sampling the BSDF rather than the guide, before (or without) learning it.
  float bsdf_fraction = 0.5f;
  /// Learn that probability per leaf (bsdf_fraction.h); otherwise it stays `bsdf_fraction`.
  bool learn_bsdf_fraction = true;
  /// The least fraction learning may choose (0: any candidate, as Müller's optimiser may).
  float min_bsdf_fraction = 0.f;
  /// Each iteration's directional trees start from the energy learned so far, rather than from
  /// zero as Müller's do (off by default: it kept early iterations' noise in the guide, 1.4–1.5x
  /// the error per sample on door-ajar and window-pane).
  bool keep_energy = false;
  GuideCombination combination = GuideCombination::InverseVariance;
  /// (InverseVariance) How many of the last iterations the image combines (Müller: 4).
  int combined_iterations = 4;
  GuideRoulette roulette = GuideRoulette::Radiance;
  /// Nearest: the stochastic filter let light leak through walls into the leaves beside a door
  /// ajar (docs/performance.md).
  SpatialFilter spatial_filter = SpatialFilter::Nearest;
  DirectionalFilter directional_filter = DirectionalFilter::Box;
  /// Guiding steps aside (the rest of the render is the unguided path tracer) when the first
  /// iteration of at least `gain_iteration_spp` samples per pixel and `gain_paths` paths predicts
  /// a gain below this (guide_gain.h; 0: never). Tessera's own: a guided sample costs 1.4-1.9x a
  /// plain one. (A guide learned from fewer paths is coarse, and predicts less than it will gain:
  /// window-pane's prediction at its 8-spp iteration grew from 1.13 at 64x48 to 2.41 at 320x240.)
  double min_gain = 1.3;
  uint32_t gain_iteration_spp = 8;
  uint64_t gain_paths = uint64_t(1) << 18;
};

/// The samples a leaf must exceed in an iteration of `iteration_spp` samples per pixel to be split:
/// c·sqrt(iteration_spp / 4).
double spatial_split_threshold(const GuidingSettings& settings, uint32_t iteration_spp);

class SpatialTree {
 public:
  /// One leaf over `bounds`, made a cube about its centre (so cuts halve its longest side first).
  explicit SpatialTree(const Bounds3& bounds, float bsdf_fraction = 0.5f);
  SpatialTree() = default;  // (empty: to be read, tree_io.h)

  /// The leaf whose region holds `p` (a point outside the bounds goes to the nearest region), and
  /// if asked the size of that region.
  uint32_t leaf_of(Vec3 p, Vec3* extent = nullptr) const;
  /// Asks for the leaf's estimates and its trees' places to be brought into the cache.
  void prefetch_leaf(uint32_t leaf) const {
    __builtin_prefetch(&leaves_[leaf]);
    __builtin_prefetch(&leaves_[leaf].bsdf_fraction);
  }
  /// Asks for the top of the leaf's recording tree to be brought into the cache (DirectionalTree::prefetch_records).
  void prefetch_records(uint32_t leaf) const { leaves_[leaf].building.prefetch_records(); }
  /// The leaf's distribution learned in the previous iteration (uniform before the first).
  const DirectionalTree& sampling(uint32_t leaf) const { return leaves_[leaf].sampling; }
  /// Records radiance `value` arriving from `dir` in the leaf (see DirectionalTree::record) and
  /// counts the sample, also when `value` is 0. Thread-safe against other record() calls.
  void record(uint32_t leaf, Vec3 dir, float value, float dither) {
    record_at(leaf, direction_to_square(dir), value, dither);
  }
  /// The same at the direction's point on the square (DirectionalTree::record_at, or record_box
  /// with DirectionalFilter::Box).
  void record_at(uint32_t leaf, Vec2 square, float value, float dither,
                 DirectionalFilter filter = DirectionalFilter::Nearest);
  /// Records the luminance of a path's estimate (a pixel sample) whose first recorded vertex is in
  /// the leaf. Thread-safe against other record calls.
  void record_pixel(uint32_t leaf, float value, float dither);
  /// The previous iteration's estimates at the leaf: the incident luminance integrated over the
  /// sphere (the radiance from wi is that times sampling(leaf).pdf(wi)), and the mean pixel sample
  /// of the paths that began there (record_pixel). 0 where nothing was recorded.
  float radiance(uint32_t leaf) const { return leaves_[leaf].radiance; }
  float pixel(uint32_t leaf) const { return leaves_[leaf].pixel; }
  /// The leaf's probability of sampling the BSDF rather than its guide.
  float bsdf_fraction(uint32_t leaf) const { return leaves_[leaf].bsdf_fraction; }
  /// Records a guided sample's share of the loss that chooses that probability (BsdfFractionLoss).
  void record_fraction(uint32_t leaf, float weight, float bsdf_pdf, float guide_pdf) {
    leaves_[leaf].fraction_loss.record(weight, bsdf_pdf, guide_pdf);
  }

  /// Records a guided path's second moments (PathGain), in units of gain_scale() squared.
  void record_gain(double plain_moment, double guided_moment, float dither) {
    gain_.record(plain_moment, guided_moment, dither);
  }
  /// A scale of the image's pixel values (the leaves' mean pixel estimate; 1 before there is one),
  /// which keeps the gain's fixed-point sums well inside their range.
  float gain_scale() const { return gain_scale_; }

  /// Ends a training iteration of `iteration_spp` samples per pixel: splits the leaves that saw
  /// more than spatial_split_threshold() samples in it (within the memory cap), then makes each
  /// leaf's recorded tree its sampling tree and starts a refined one for the next iteration, and
  /// (if learned) picks each leaf's BSDF fraction from the iteration's loss. At the iteration that
  /// decides (GuidingSettings::min_gain) a predicted gain below the least steps aside instead.
  /// Not thread-safe: at a pass barrier.
  void end_iteration(uint32_t iteration_spp, const GuidingSettings& settings);
  /// Guiding stepped aside: the tree is a single empty leaf, and the passes that use it render as
  /// the unguided path tracer (PathGuide::of).
  bool stepped_aside() const { return aside_from_ > 0; }
  /// The gain the deciding iteration predicted (0 before it).
  float predicted_gain() const { return predicted_gain_; }
  /// The tree's iteration: 0 as made, one more at every end_iteration().
  uint32_t iteration() const { return iteration_; }
  /// (Stepped aside) the iteration of the first tree that did: the passes that use it and every
  /// later one render unguided.
  uint32_t aside_from() const { return aside_from_; }

  size_t leaf_count() const { return leaves_.size(); }
  size_t node_count() const { return nodes_.size(); }
  /// The tree's memory (nodes, leaves and their directional trees).
  size_t bytes() const;
  bool operator==(const SpatialTree& other) const;

 private:
  static constexpr uint32_t kNoLeaf = ~uint32_t(0);
  struct Node {
    uint32_t child[2] = {0, 0};  // (below `lo`/above the midpoint along axis = depth % 3)
    uint32_t leaf = kNoLeaf;
    bool operator==(const Node&) const = default;
  };
  struct Leaf {
    DirectionalTree sampling, building;
    uint64_t samples = 0;
    uint64_t pixel_sum = 0, pixel_paths = 0;  // record_pixel's, fixed point as DirectionalTree's
    BsdfFractionLoss fraction_loss;
    float bsdf_fraction = 0.5f;
    float radiance = 0.f, pixel = 0.f;
    bool operator==(const Leaf&) const = default;
  };
  void split(uint32_t node);
  // leaf_of()'s view of the nodes, three cuts (along x, y, z) per step so that its chain of
  // dependent loads is a third as long: entry e of a step (bit 0 set: the upper half along x, bit
  // 1: y, bit 2: z) is the next step, or kLeafEntry | levels << 29 | leaf for a leaf reached after
  // `levels` (0 to 3) of the step's cuts. Made again whenever the nodes change.
  static constexpr uint32_t kLeafEntry = 1u << 31;
  void index_nodes();
  uint32_t make_step(uint32_t node);
  static size_t leaf_bytes(const Leaf& leaf);
  // Decides at the first iteration of at least settings.gain_iteration_spp; true to step aside.
  bool decide_gain(uint32_t iteration_spp, const GuidingSettings& settings);
  void step_aside();
  void update_gain_scale();
  friend struct TreeIo;  // tree_io.h

  Bounds3 bounds_;
  std::vector<Node> nodes_;
  std::vector<Leaf> leaves_;
  std::vector<std::array<uint32_t, 8>> steps_;
  GuideGain gain_;  // the iteration's, as records are
  float gain_scale_ = 1.f;
  float predicted_gain_ = 0.f;
  uint32_t iteration_ = 0, aside_from_ = 0;  // (aside_from_ 0: guiding has not stepped aside)
};

}  // namespace tessera

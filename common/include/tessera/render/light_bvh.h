// A bounding volume hierarchy over lights (pbrt-v4's BVHLightSampler): each node bounds its
// lights' positions, emission directions and power (LightBounds); sampling walks from the root,
// choosing a child in proportion to its importance at the shading point, so the probability of a
// light is the product of the choices on its path. pmf() replays that path from a per-light bit
// trail, giving exactly the probability sample() would have had.
//
// Only bounded lights live in the tree (one per leaf); lights without bounds (infinite, or types
// that do not report LightBounds) are the caller's business (LightSampler).
#pragma once

#include "tessera/render/light_bounds.h"

#include <cstdint>
#include <vector>

namespace tessera {

class LightBvh {
 public:
  static constexpr uint32_t kNone = 0xFFFFFFFFu;

  LightBvh() = default;
  /// `bounds[i]` belongs to light index i (the caller's numbering); lights with phi <= 0 are left
  /// out (pmf 0). Deterministic for a given input.
  explicit LightBvh(const std::vector<LightBounds>& bounds);

  bool empty() const { return nodes_.empty(); }
  size_t num_nodes() const { return nodes_.size(); }
  int depth() const { return depth_; }
  /// Bounds of everything in the tree (the root's).
  const LightBounds* root() const { return nodes_.empty() ? nullptr : &nodes_[0].bounds; }

  /// A light index chosen at (p, n) (n = 0 in a medium) with probability `pmf`, or kNone when
  /// every light has zero importance there. Allocation-free.
  uint32_t sample(Vec3 p, Vec3 n, float u, float& pmf) const;
  /// Probability that sample(p, n, ., .) returns `light`.
  float pmf(Vec3 p, Vec3 n, uint32_t light) const;

 private:
  struct Node {
    LightBounds bounds;
    // Interior: index of the second child (the first follows the node). Leaf: the light index.
    uint32_t index = 0;
    bool leaf = false;
  };
  struct BuildItem {
    uint32_t light;
    LightBounds bounds;
  };
  std::vector<Node> nodes_;
  // Per light: the path from the root, bit d set when the second child was taken at depth d;
  // and its leaf (kNone: not in the tree).
  std::vector<uint64_t> trail_;
  std::vector<uint32_t> leaf_;
  int depth_ = 0;

  uint32_t build(std::vector<BuildItem>& items, size_t begin, size_t end, int depth, uint64_t trail);
  /// Probability of the FIRST child at an interior node; negative when both children have zero
  /// importance. Sample and pmf both call it, so they see the same floats.
  float first_child_probability(const Node& node, Vec3 p, Vec3 n) const;
};

}  // namespace tessera

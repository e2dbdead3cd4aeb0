#include "tessera/guiding/directional_tree.h"

#include "tessera/core/check.h"
#include "tessera/core/sampling.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace tessera {
namespace {

constexpr double kOneBelow = 1.0 - std::numeric_limits<double>::epsilon() / 2;

uint64_t saturating_add(uint64_t a, uint64_t b) {
  const uint64_t s = a + b;
  return s < a ? std::numeric_limits<uint64_t>::max() : s;
}

// Picks the half of [0,1) that `u` falls in, with probability `p_low` for the lower one, and
// rescales `u` to [0,1) within it (so one number serves every level of the descent).
bool pick_upper(double& u, double p_low) {
  if (u < p_low) {
    u = std::min(u / p_low, kOneBelow);
    return false;
  }
  u = std::min((u - p_low) / (1.0 - p_low), kOneBelow);
  return true;
}

}  // namespace

Vec2 direction_to_square(Vec3 dir) {
  const float x = std::clamp(0.5f * (1.f - dir.z), 0.f, 1.f);
  float phi = std::atan2(dir.y, dir.x);
  if (phi < 0.f) phi += 2.f * kPi;
  const float y = phi * (0.5f * kInvPi);
  constexpr float kBelowOne = 1.f - std::numeric_limits<float>::epsilon() / 2;
  return {std::min(x, kBelowOne), std::clamp(y, 0.f, kBelowOne)};
}

DirectionalTree::DirectionalTree() : nodes_(1), density_(1, {1.f, 1.f, 1.f, 1.f}) {}

int DirectionalTree::quadrant(Vec2& p) {
  // (Exact in floating point: doubling, and subtracting 1 from a number in [1, 2).)
  int i = 0;
  if (p.x < 0.5f) {
    p.x *= 2.f;
  } else {
    p.x = 2.f * p.x - 1.f;
    i |= 1;
  }
  if (p.y < 0.5f) {
    p.y *= 2.f;
  } else {
    p.y = 2.f * p.y - 1.f;
    i |= 2;
  }
  return i;
}

void DirectionalTree::record_at(Vec2 p, float value, float dither) {
  if (!(value > 0.f)) return;  // (NaN too)
  const double scaled = double(std::min(value, kMaxRecord)) * double(uint64_t(1) << kScaleBits);
  uint64_t q = uint64_t(scaled);
  if (double(dither) < scaled - double(q)) ++q;  // rounds up with probability equal to the fraction
  if (q == 0) return;
  for (uint32_t n = 0;;) {
    const int i = quadrant(p);
    const uint32_t c = nodes_[n].child[i];
    if (c == 0) {
      std::atomic_ref<uint64_t>(nodes_[n].sum[i]).fetch_add(q, std::memory_order_relaxed);
      return;
    }
    n = c;
  }
}

void DirectionalTree::merge(const DirectionalTree& other) {
  TESSERA_CHECK(other.nodes_.size() == nodes_.size());
  for (size_t n = 0; n < nodes_.size(); ++n) {
    TESSERA_CHECK(other.nodes_[n].child == nodes_[n].child);
    for (int i = 0; i < 4; ++i)
      if (nodes_[n].child[i] == 0) nodes_[n].sum[i] = saturating_add(nodes_[n].sum[i], other.nodes_[n].sum[i]);
  }
}

uint64_t DirectionalTree::build_node(uint32_t n) {
  uint64_t total = 0;
  for (int i = 0; i < 4; ++i) {
    if (const uint32_t c = nodes_[n].child[i]) nodes_[n].sum[i] = build_node(c);
    total = saturating_add(total, nodes_[n].sum[i]);
  }
  return total;
}

void DirectionalTree::build() {
  (void)build_node(0);
  set_densities();
}

void DirectionalTree::set_densities() {
  density_.resize(nodes_.size());
  for (size_t n = 0; n < nodes_.size(); ++n) {
    const std::array<uint64_t, 4>& s = nodes_[n].sum;
    const double total = double(s[0]) + double(s[1]) + double(s[2]) + double(s[3]);
    for (int i = 0; i < 4; ++i) density_[n][size_t(i)] = total > 0.0 ? float(4.0 * double(s[size_t(i)]) / total) : 1.f;
  }
}

uint64_t DirectionalTree::total() const {
  uint64_t total = 0;
  for (uint64_t s : nodes_[0].sum) total = saturating_add(total, s);
  return total;
}

Vec3 DirectionalTree::sample(Vec2 u, float& pdf, Vec2* square) const {
  double ux = std::min(double(u.x), kOneBelow), uy = std::min(double(u.y), kOneBelow);
  double density = 1.0, x0 = 0.0, y0 = 0.0, size = 1.0;
  for (uint32_t n = 0;;) {
    const std::array<uint64_t, 4>& s = nodes_[n].sum;
    const double total = double(s[0]) + double(s[1]) + double(s[2]) + double(s[3]);
    if (!(total > 0.0)) break;  // no energy below: uniform over the node
    // The column (x half) by its marginal, then the row within it.
    int i = pick_upper(ux, (double(s[0]) + double(s[2])) / total) ? 1 : 0;
    const double column = double(s[i]) + double(s[i + 2]);
    if (pick_upper(uy, double(s[i]) / column)) i |= 2;
    density *= 4.0 * double(s[i]) / total;
    size *= 0.5;
    x0 += (i & 1) ? size : 0.0;
    y0 += (i & 2) ? size : 0.0;
    n = nodes_[n].child[i];
    if (n == 0) break;
  }
  pdf = float(density * (0.25 * kInvPi));
  // (Clamped below 1 like direction_to_square, so the point stays in the cell it was drawn in.)
  constexpr float kBelowOne = 1.f - std::numeric_limits<float>::epsilon() / 2;
  const Vec2 p(std::min(float(x0 + ux * size), kBelowOne), std::min(float(y0 + uy * size), kBelowOne));
  if (square) *square = p;
  return square_to_uniform_sphere(p);
}

float DirectionalTree::pdf_at(Vec2 p) const {
  TESSERA_DCHECK(density_.size() == nodes_.size());
  float density = 1.f;
  for (uint32_t n = 0;;) {
    const int i = quadrant(p);
    density *= density_[n][size_t(i)];
    n = nodes_[n].child[i];
    if (n == 0) break;
  }
  return density * (0.25f * kInvPi);
}

void DirectionalTree::refine_into(DirectionalTree& out, uint32_t out_node, const Node* node, double scale,
                                  uint64_t energy, int depth, double threshold, bool keep_sums) const {
  // `node` null: below a leaf of this tree, whose energy counts as spread evenly over its
  // quadrants (each then has the share `scale` and a quarter of `energy`); otherwise a quadrant's
  // share is its sum times `scale`.
  for (int i = 0; i < 4; ++i) {
    const double share = node ? double(node->sum[i]) * scale : scale;
    const uint64_t quadrant_energy = node ? node->sum[i] : energy / 4;
    if (depth >= kMaxDepth || !(share > threshold)) {
      if (keep_sums) out.nodes_[out_node].sum[i] = quadrant_energy;
      continue;
    }
    const uint32_t child = uint32_t(out.nodes_.size());
    out.nodes_.emplace_back();
    out.nodes_[out_node].child[i] = child;
    const Node* below = node && node->child[i] != 0 ? &nodes_[node->child[i]] : nullptr;
    refine_into(out, child, below, below ? scale : share / 4.0, quadrant_energy, depth + 1, threshold, keep_sums);
  }
}

DirectionalTree DirectionalTree::refined(double threshold, bool keep_sums) const {
  DirectionalTree out;
  const double total = double(this->total());
  if (total > 0.0) refine_into(out, 0, &nodes_[0], 1.0 / total, 0, 1, threshold, keep_sums);
  out.set_densities();  // (of its sums so far; build() makes them again, and every tree holds them)
  return out;
}

DirectionalTree DirectionalTree::cleared() const {
  DirectionalTree out = *this;
  for (Node& n : out.nodes_) n.sum = {};
  return out;
}

int DirectionalTree::depth() const {
  // Children are always appended after their parent, so one pass in index order finds depths.
  std::vector<int> depth(nodes_.size(), 1);
  int deepest = 1;
  for (size_t n = 0; n < nodes_.size(); ++n)
    for (uint32_t c : nodes_[n].child)
      if (c != 0) deepest = std::max(deepest, depth[c] = depth[n] + 1);
  return deepest;
}

bool DirectionalTree::operator==(const DirectionalTree& other) const {
  if (nodes_.size() != other.nodes_.size()) return false;
  for (size_t n = 0; n < nodes_.size(); ++n)
    if (nodes_[n].child != other.nodes_[n].child || nodes_[n].sum != other.nodes_[n].sum) return false;
  return true;
}

}  // namespace tessera

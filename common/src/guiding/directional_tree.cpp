#include "tessera/guiding/directional_tree.h"

#include "tessera/core/check.h"
#include "tessera/core/sampling.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
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

// A point of the square in 32-bit fixed point: bit 31 - d of each coordinate is the half it lies in
// at depth d (exact: a float below 1 times 2^32 is an integer plus an exact fraction).
struct SquareBits {
  explicit SquareBits(Vec2 p) : x(uint32_t(double(p.x) * 0x1p32)), y(uint32_t(double(p.y) * 0x1p32)) {}
  int quadrant(int depth) const { return int((x >> (31 - depth)) & 1u) | int(((y >> (31 - depth)) & 1u) << 1); }
  uint32_t x, y;
};

// The angle of (x, y) about the origin in [0, 2 pi]: the arc tangent of the smaller over the larger
// magnitude (in [0, 1]) by a polynomial fitted to within 2.5e-7 radians (about float's rounding of
// an angle near 2 pi), then mirrored into its octant: no call into libm on the hot path.
float azimuth(float x, float y) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float hi = std::max(ax, ay), t = hi > 0.f ? std::min(ax, ay) / hi : 0.f, t2 = t * t;
  float a = t * (0.99999612f +
                 t2 * (-0.33317390f + t2 * (0.19808013f + t2 * (-0.13234101f + t2 * (0.07963768f + t2 * (-0.03361648f + t2 * 0.00681588f))))));
  if (ay > ax) a = 0.5f * kPi - a;
  if (x < 0.f) a = kPi - a;
  return y < 0.f ? 2.f * kPi - a : a;
}

}  // namespace

Vec2 direction_to_square(Vec3 dir) {
  const float x = std::clamp(0.5f * (1.f - dir.z), 0.f, 1.f);
  const float y = azimuth(dir.x, dir.y) * (0.5f * kInvPi);
  constexpr float kBelowOne = 1.f - std::numeric_limits<float>::epsilon() / 2;
  return {std::min(x, kBelowOne), std::clamp(y, 0.f, kBelowOne)};
}

DirectionalTree::DirectionalTree() : nodes_(1), cells_(1) {}

uint64_t DirectionalTree::fixed_point(float value, float dither) {
  if (!(value > 0.f)) return 0;  // (NaN too)
  const double scaled = double(std::min(value, kMaxRecord)) * double(uint64_t(1) << kScaleBits);
  const uint64_t q = uint64_t(scaled);
  return double(dither) < scaled - double(q) ? q + 1 : q;
}

void DirectionalTree::record_at(Vec2 p, float value, float dither) {
  const uint64_t q = fixed_point(value, dither);
  if (q == 0) return;
  const SquareBits bits(p);
  for (uint32_t n = 0, depth = 0;; ++depth) {
    const int i = bits.quadrant(int(depth));
    const uint32_t c = nodes_[n].child[size_t(i)];
    if (c == 0) {
      std::atomic_ref<uint64_t>(nodes_[n].sum[size_t(i)]).fetch_add(q, std::memory_order_relaxed);
      return;
    }
    n = c;
  }
}

void DirectionalTree::record_box(Vec2 p, float value, float dither) {
  if (!(value > 0.f)) return;
  const SquareBits bits(p);
  int depth = 0;  // (of the node whose quadrant holds p: the quadrant's side is 2^-(depth + 1))
  for (uint32_t n = 0; (n = nodes_[n].child[size_t(bits.quadrant(depth))]) != 0;) ++depth;
  const double side = std::ldexp(1.0, -(depth + 1));
  const double box[3] = {double(p.x) - side / 2, double(p.y) - side / 2, side};
  splat(0, 0.0, 0.0, 1.0, box, double(std::min(value, kMaxRecord)) / (side * side), dither);
}

void DirectionalTree::splat(uint32_t n, double x, double y, double size, const double box[3], double density,
                            float dither) {
  const double half = size / 2;
  const auto overlap = [&](double lo, double box_lo) { return std::min(lo + half, box_lo + box[2]) - std::max(lo, box_lo); };
  for (size_t i = 0; i < 4; ++i) {
    const double qx = x + ((i & 1) ? half : 0.0), qy = y + ((i & 2) ? half : 0.0);
    const double wx = overlap(qx, box[0]), wy = overlap(qy, box[1]);
    if (!(wx > 0.0) || !(wy > 0.0)) continue;
    if (const uint32_t c = nodes_[n].child[i]) {
      splat(c, qx, qy, half, box, density, dither);
    } else if (const uint64_t q = fixed_point(float(density * wx * wy), dither)) {
      std::atomic_ref<uint64_t>(nodes_[n].sum[i]).fetch_add(q, std::memory_order_relaxed);
    }
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
  set_cells();
}

void DirectionalTree::set_cells() {
  cells_.resize(nodes_.size());
  for (size_t n = 0; n < nodes_.size(); ++n) {
    const std::array<uint64_t, 4>& s = nodes_[n].sum;
    const double total = double(s[0]) + double(s[1]) + double(s[2]) + double(s[3]);
    for (size_t i = 0; i < 4; ++i) cells_[n].density[i] = total > 0.0 ? float(4.0 * double(s[i]) / total) : 1.f;
    cells_[n].child = nodes_[n].child;
  }
}

uint64_t DirectionalTree::total() const {
  uint64_t total = 0;
  for (uint64_t s : nodes_[0].sum) total = saturating_add(total, s);
  return total;
}

Vec3 DirectionalTree::sample(Vec2 u, float& pdf, Vec2* square) const {
  // The same factors as pdf_at() in the same order, so the density is the same bits there.
  double ux = std::min(double(u.x), kOneBelow), uy = std::min(double(u.y), kOneBelow);
  double x0 = 0.0, y0 = 0.0, size = 1.0;
  float density = 1.f;
  for (uint32_t n = 0;;) {
    const std::array<float, 4>& d = cells_[n].density;
    // The column (x half) by its marginal, then the row within it (a zero share is never taken).
    int i = pick_upper(ux, double(d[0] + d[2]) / double(d[0] + d[1] + d[2] + d[3])) ? 1 : 0;
    if (pick_upper(uy, double(d[size_t(i)]) / double(d[size_t(i)] + d[size_t(i) + 2]))) i |= 2;
    density *= d[size_t(i)];
    size *= 0.5;
    x0 += (i & 1) ? size : 0.0;
    y0 += (i & 2) ? size : 0.0;
    n = cells_[n].child[size_t(i)];
    if (n == 0) break;
  }
  pdf = density * (0.25f * kInvPi);
  // (Clamped below 1 like direction_to_square, so the point stays in the cell it was drawn in.)
  constexpr float kBelowOne = 1.f - std::numeric_limits<float>::epsilon() / 2;
  const Vec2 p(std::min(float(x0 + ux * size), kBelowOne), std::min(float(y0 + uy * size), kBelowOne));
  if (square) *square = p;
  return square_to_uniform_sphere(p);
}

float DirectionalTree::pdf_at(Vec2 p) const {
  TESSERA_DCHECK(cells_.size() == nodes_.size());
  const SquareBits bits(p);
  float density = 1.f;
  for (uint32_t n = 0, depth = 0;; ++depth) {
    const int i = bits.quadrant(int(depth));
    density *= cells_[n].density[size_t(i)];
    n = cells_[n].child[size_t(i)];
    if (n == 0) break;
  }
  return density * (0.25f * kInvPi);
}

DirectionalTree DirectionalTree::refined(double threshold, bool keep_sums) const {
  DirectionalTree out;
  const double total = double(this->total());
  if (total > 0.0) {
    // Breadth first, so that a tree's top levels are its first cells (prefetch()). A quadrant's
    // share is its sum times `scale`; below a leaf of this tree (`node` null) the leaf's energy
    // counts as spread evenly over its quadrants, each with the share `scale` and a quarter of
    // `energy`.
    struct Pending {
      uint32_t out_node;
      const Node* node;
      double scale;
      uint64_t energy;
      int depth;
    };
    std::deque<Pending> queue{{0, &nodes_[0], 1.0 / total, 0, 1}};
    for (; !queue.empty(); queue.pop_front()) {
      const Pending q = queue.front();
      for (int i = 0; i < 4; ++i) {
        const double share = q.node ? double(q.node->sum[i]) * q.scale : q.scale;
        const uint64_t quadrant_energy = q.node ? q.node->sum[i] : q.energy / 4;
        if (q.depth >= kMaxDepth || !(share > threshold)) {
          if (keep_sums) out.nodes_[q.out_node].sum[i] = quadrant_energy;
          continue;
        }
        const uint32_t child = uint32_t(out.nodes_.size());
        out.nodes_.emplace_back();
        out.nodes_[q.out_node].child[i] = child;
        const Node* below = q.node && q.node->child[i] != 0 ? &nodes_[q.node->child[i]] : nullptr;
        queue.push_back({child, below, below ? q.scale : share / 4.0, quadrant_energy, q.depth + 1});
      }
    }
  }
  out.set_cells();  // (of its sums so far; build() makes them again, and every tree holds them)
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

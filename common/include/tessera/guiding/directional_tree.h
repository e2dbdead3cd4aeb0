// A learned distribution of directions for path guiding, after the directional quadtree ("D-tree")
// of Müller et al. 2017, "Practical Path Guiding for Efficient Light-Transport Simulation".
//
// Directions live on the unit square through the equal-area map of square_to_uniform_sphere
// (x = (1 - cos theta) / 2, y = phi / 2 pi, about world +z), so a density over the square is the
// solid-angle density times 4 pi. The square is cut into a quadtree; each node holds the energy
// recorded in its four quadrants, and a direction is drawn by descending in proportion to them.
//
// Exact, order-free statistics: a record is quantised to 64-bit fixed point (rounded up or down by
// a dither the caller draws from the sample's own random numbers, so the rounding is unbiased and
// deterministic) and added atomically to its leaf. Integer sums do not depend on the order of the
// records, so training statistics are the same bits for any thread count, tile size, or order in
// which a farm's tiles arrive, and two trees of one structure merge exactly (merge()).
//
// Life cycle per training iteration: record() into the building tree from many threads; build()
// once (sums up the quadrants of inner nodes); the built tree then samples (sample(), pdf()) for
// the next iteration, whose building tree is refined(): the same directions, cut finer where the
// energy is, with zero sums.
#pragma once

#include "tessera/core/vec.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace tessera {

/// Equal-area map of a unit direction onto [0,1)^2 (the inverse of square_to_uniform_sphere).
Vec2 direction_to_square(Vec3 dir);

class DirectionalTree {
 public:
  /// Nodes deeper than this are never made (a leaf then is 4^-20 of the sphere).
  static constexpr int kMaxDepth = 20;
  /// Fixed-point resolution: a record's value times 2^kScaleBits is what is added.
  static constexpr int kScaleBits = 16;
  /// A larger record is clamped to this (keeps sums of millions of records within 64 bits).
  static constexpr float kMaxRecord = float(1 << 24);

  /// `value` (clamped to [0, kMaxRecord]) in fixed point, rounded up with probability equal to
  /// its fraction, decided by `dither` in [0,1); 0 for NaN.
  static uint64_t fixed_point(float value, float dither);
  static double from_fixed_point(double sum) { return sum * (1.0 / double(uint64_t(1) << kScaleBits)); }

  /// One node: the whole sphere in four leaf quadrants.
  DirectionalTree();

  /// Adds `value` (>= 0; others are ignored) at `dir`. `dither` in [0,1) decides the rounding.
  /// Thread-safe against other record() calls; not against build() or merge().
  void record(Vec3 dir, float value, float dither) { record_at(direction_to_square(dir), value, dither); }
  /// The same at the direction's point on the square (direction_to_square, or where sample() drew it).
  void record_at(Vec2 square, float value, float dither);
  /// DirectionalFilter::Box (Müller 2019): `value` spread over a square of the size of the leaf
  /// cell at `square` about it, each leaf it overlaps taking its share of the square's area (the
  /// part outside the unit square is dropped, as in Müller's code). Each share is rounded with the
  /// same `dither`, which keeps every leaf's expected sum exact.
  void record_box(Vec2 square, float value, float dither);
  /// Adds the sums of a tree of the same structure (the same refined() ancestry).
  void merge(const DirectionalTree& other);
  /// Makes the inner quadrants' sums the totals of their subtrees. Before sampling.
  void build();

  /// Draws a direction; `pdf` is its solid-angle density (a tree without energy is uniform), and
  /// `square` (if given) the point on the square it was drawn at, which pdf_at() and record_at()
  /// take without mapping the direction back (its arc tangent is most of that map's cost).
  Vec3 sample(Vec2 u, float& pdf, Vec2* square = nullptr) const;
  /// Solid-angle density of sample() at `dir`.
  float pdf(Vec3 dir) const { return pdf_at(direction_to_square(dir)); }
  /// The same at a point of the square.
  float pdf_at(Vec2 square) const;
  /// Asks for the cells of the tree's top levels (its first, breadth first: refined()) to be
  /// brought into the cache, ahead of a sample() or pdf_at() whose direction is not known yet: a
  /// descent otherwise waits on memory at every level of a tree no recent path has used.
  void prefetch() const { prefetch_top<false>(cells_); }
  /// The same for a record() (which reads and adds to the nodes, not the cells).
  void prefetch_records() const { prefetch_top<true>(nodes_); }

  /// The next iteration's tree (of a built tree): a quadrant whose share of the total energy is
  /// above `threshold` is split (to at most kMaxDepth), a subtree whose share is not is merged. A
  /// leaf's energy counts as spread evenly over the quadrants it is split into. The sums are zero,
  /// or with `keep_sums` each new cell's energy (rounded down), so later records add to it.
  DirectionalTree refined(double threshold, bool keep_sums = false) const;

  /// The same cells with zero sums (for when a refined tree would not fit the memory cap).
  DirectionalTree cleared() const;

  /// All energy recorded (after build()), in fixed-point units.
  uint64_t total() const;
  size_t node_count() const { return nodes_.size(); }
  size_t bytes() const { return sizeof(*this) + nodes_.size() * (sizeof(Node) + sizeof(Cell)); }
  int depth() const;
  /// The sums and structure compare equal.
  bool operator==(const DirectionalTree& other) const;

 private:
  struct Node {
    std::array<uint32_t, 4> child{};  // 0: the quadrant is a leaf
    std::array<uint64_t, 4> sum{};
  };
  // Quadrant i covers x in [i&1 ? 0.5 : 0, ...) and y in [i&2 ? 0.5 : 0, ...) of its node.
  // What sampling and densities read, half a cache line per node: each quadrant's factor of the
  // density on the square, 4 x its share of the node's energy (1 in a node without energy), and
  // the children again. pdf_at() multiplies the factors along its descent instead of dividing sums.
  struct alignas(32) Cell {
    std::array<float, 4> density{1.f, 1.f, 1.f, 1.f};
    std::array<uint32_t, 4> child{};
  };
  // The root and the two levels below it.
  static constexpr size_t kPrefetchCells = 1 + 4 + 16;
  // Asks for the first kPrefetchCells elements of `v` (for writing, with `kWrite`).
  template <bool kWrite, typename T>
  static void prefetch_top(const std::vector<T>& v) {
    const char* first = reinterpret_cast<const char*>(v.data());
    const size_t bytes = std::min(v.size(), kPrefetchCells) * sizeof(T);
    for (size_t b = 0; b < bytes; b += 64) __builtin_prefetch(first + b, kWrite ? 1 : 0);
  }
  uint64_t build_node(uint32_t n);
  // record_box below node `n`, whose region has corner (x, y) and side `size`.
  void splat(uint32_t n, double x, double y, double size, const double box[3], double density, float dither);
  void set_cells();
  friend struct TreeIo;  // tree_io.h

  std::vector<Node> nodes_;
  // A Cell per node, made by build() and when a tree is refined or read: every tree holds them.
  std::vector<Cell> cells_;
};

}  // namespace tessera

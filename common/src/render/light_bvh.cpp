// Light BVH build and traversal. The build is top-down with pbrt-v4's surface-area-orientation
// heuristic: a split's cost is, per side, power x (box area) x (measure of the emission cone), with
// a factor for thin boxes, over 12 centroid buckets per axis; one light per leaf. Trails are 64
// bits, so the build balances (median split) whenever an unlucky sequence of cheap splits would
// otherwise run out of depth.
#include "tessera/render/light_bvh.h"

#include "tessera/core/check.h"
#include "tessera/core/sampling.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

namespace tessera {
namespace {

constexpr int kBuckets = 12;
constexpr int kMaxDepth = 64;

// Solid-angle-like measure of the directions a cluster emits into (pbrt-v4's M_Omega).
float orientation_measure(const LightBounds& b) {
  const float theta_o = std::acos(std::clamp(b.cos_theta_o, -1.f, 1.f));
  const float theta_e = std::acos(std::clamp(b.cos_theta_e, -1.f, 1.f));
  const float theta_w = std::min(theta_o + theta_e, kPi);
  const float sin_o = std::sqrt(std::max(0.f, 1.f - b.cos_theta_o * b.cos_theta_o));
  return 2.f * kPi * (1.f - b.cos_theta_o) +
         0.5f * kPi *
             (2.f * theta_w * sin_o - std::cos(theta_o - 2.f * theta_w) - 2.f * theta_o * sin_o + b.cos_theta_o);
}

double split_cost(const LightBounds& b, const Bounds3& node_box, int dim) {
  const Vec3 diag = node_box.diagonal();
  const double kr = diag[dim] > 0.f ? double(max_component(diag)) / double(diag[dim]) : 1.0;
  // Point lights have a zero-area box; their power still has to count.
  const double area = std::max(double(b.bounds.surface_area()), 1e-12 * double(node_box.surface_area()));
  return double(b.phi) * double(orientation_measure(b)) * kr * area;
}

int ceil_log2(size_t n) { return n <= 1 ? 0 : int(std::bit_width(n - 1)); }

}  // namespace

LightBvh::LightBvh(const std::vector<LightBounds>& bounds) {
  std::vector<BuildItem> items;
  items.reserve(bounds.size());
  for (uint32_t i = 0; i < bounds.size(); ++i)
    if (bounds[i].phi > 0.f && std::isfinite(bounds[i].phi) && !bounds[i].bounds.empty())
      items.push_back({i, bounds[i]});
  trail_.assign(bounds.size(), 0);
  leaf_.assign(bounds.size(), kNone);
  if (items.empty()) return;
  nodes_.reserve(2 * items.size() - 1);
  build(items, 0, items.size(), 0, 0);
}

uint32_t LightBvh::build(std::vector<BuildItem>& items, size_t begin, size_t end, int depth, uint64_t trail) {
  TESSERA_CHECK(depth < kMaxDepth);
  const uint32_t self = uint32_t(nodes_.size());
  nodes_.emplace_back();
  if (end - begin == 1) {
    Node& leaf = nodes_[self];
    leaf.bounds = items[begin].bounds;
    leaf.index = items[begin].light;
    leaf.leaf = true;
    trail_[leaf.index] = trail;
    leaf_[leaf.index] = self;
    depth_ = std::max(depth_, depth);
    return self;
  }

  LightBounds all;
  Bounds3 centroids;
  for (size_t i = begin; i < end; ++i) {
    all = merge(all, items[i].bounds);
    centroids.extend(items[i].bounds.centroid());
  }

  size_t mid = begin;
  const bool must_balance = depth + 1 + ceil_log2(end - begin) >= kMaxDepth;
  if (!must_balance) {
    double best_cost = kInfinity;
    int best_dim = -1, best_split = -1;
    const Vec3 extent = centroids.diagonal();
    for (int dim = 0; dim < 3; ++dim) {
      if (!(extent[dim] > 0.f)) continue;
      std::array<LightBounds, kBuckets> bucket{};
      std::array<size_t, kBuckets> count{};
      for (size_t i = begin; i < end; ++i) {
        float c = (items[i].bounds.centroid()[dim] - centroids.lo[dim]) / extent[dim];
        int b = std::clamp(int(c * float(kBuckets)), 0, kBuckets - 1);
        bucket[size_t(b)] = merge(bucket[size_t(b)], items[i].bounds);
        ++count[size_t(b)];
      }
      for (int split = 0; split + 1 < kBuckets; ++split) {
        LightBounds below, above;
        size_t n_below = 0, n_above = 0;
        for (int b = 0; b <= split; ++b) below = merge(below, bucket[size_t(b)]), n_below += count[size_t(b)];
        for (int b = split + 1; b < kBuckets; ++b) above = merge(above, bucket[size_t(b)]), n_above += count[size_t(b)];
        if (n_below == 0 || n_above == 0) continue;
        double cost = split_cost(below, all.bounds, dim) + split_cost(above, all.bounds, dim);
        if (cost < best_cost) best_cost = cost, best_dim = dim, best_split = split;
      }
    }
    if (best_dim >= 0) {
      const int dim = best_dim, split = best_split;
      auto it = std::partition(items.begin() + std::ptrdiff_t(begin), items.begin() + std::ptrdiff_t(end),
                               [&](const BuildItem& item) {
                                 float c = (item.bounds.centroid()[dim] - centroids.lo[dim]) / extent[dim];
                                 return std::clamp(int(c * float(kBuckets)), 0, kBuckets - 1) <= split;
                               });
      mid = size_t(it - items.begin());
    }
  }
  if (mid == begin || mid == end) {
    // Median along the widest centroid axis (light index breaks ties, for determinism).
    const int dim = max_dimension(centroids.diagonal());
    mid = begin + (end - begin) / 2;
    std::nth_element(items.begin() + std::ptrdiff_t(begin), items.begin() + std::ptrdiff_t(mid),
                     items.begin() + std::ptrdiff_t(end), [dim](const BuildItem& a, const BuildItem& b) {
                       float ca = a.bounds.centroid()[dim], cb = b.bounds.centroid()[dim];
                       return ca < cb || (ca == cb && a.light < b.light);
                     });
  }

  build(items, begin, mid, depth + 1, trail);
  const uint32_t second = build(items, mid, end, depth + 1, trail | (uint64_t(1) << depth));
  Node& node = nodes_[self];
  node.bounds = all;
  node.index = second;
  node.leaf = false;
  return self;
}

float LightBvh::first_child_probability(const Node& node, Vec3 p, Vec3 n) const {
  const Node* first = &node + 1;
  const float i0 = first->bounds.importance(p, n);
  const float i1 = nodes_[node.index].bounds.importance(p, n);
  if (!(i0 > 0.f) && !(i1 > 0.f)) return -1.f;
  return i0 / (i0 + i1);
}

uint32_t LightBvh::sample(Vec3 p, Vec3 n, float u, float& pmf) const {
  pmf = 0.f;
  if (nodes_.empty()) return kNone;
  float prob = 1.f;
  const Node* node = &nodes_[0];
  if (node->leaf && !(node->bounds.importance(p, n) > 0.f)) return kNone;
  while (!node->leaf) {
    const float p0 = first_child_probability(*node, p, n);
    if (p0 < 0.f) return kNone;
    if (u < p0) {
      u = u / p0;
      prob *= p0;
      node = node + 1;
    } else {
      u = (u - p0) / (1.f - p0);
      prob *= 1.f - p0;
      node = &nodes_[node->index];
    }
    u = std::min(u, 0x1.fffffep-1f);
  }
  pmf = prob;
  return node->index;
}

float LightBvh::pmf(Vec3 p, Vec3 n, uint32_t light) const {
  if (light >= leaf_.size() || leaf_[light] == kNone) return 0.f;
  const uint64_t trail = trail_[light];
  float prob = 1.f;
  const Node* node = &nodes_[0];
  if (node->leaf) return node->bounds.importance(p, n) > 0.f ? 1.f : 0.f;
  for (int depth = 0; !node->leaf; ++depth) {
    const float p0 = first_child_probability(*node, p, n);
    if (p0 < 0.f) return 0.f;
    if ((trail >> depth) & 1u) {
      prob *= 1.f - p0;
      node = &nodes_[node->index];
    } else {
      prob *= p0;
      node = node + 1;
    }
  }
  TESSERA_DCHECK(uint32_t(node - nodes_.data()) == leaf_[light]);
  return prob;
}

}  // namespace tessera

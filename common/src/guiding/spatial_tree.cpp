#include "tessera/guiding/spatial_tree.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace tessera {

SpatialTree::SpatialTree(const Bounds3& bounds, float bsdf_fraction) : nodes_(1), leaves_(1) {
  TESSERA_CHECK(!bounds.empty() && bsdf_fraction >= 0.f && bsdf_fraction <= 1.f);
  leaves_[0].bsdf_fraction = bsdf_fraction;
  const Vec3 d = bounds.diagonal();
  const float half = 0.5f * std::max({d.x, d.y, d.z, 1e-6f});
  const Vec3 c = bounds.center();
  bounds_.lo = c - Vec3(half);
  bounds_.hi = c + Vec3(half);
  nodes_[0].leaf = 0;
  index_nodes();
}

namespace {

// A coordinate of the cube's [0,1] in 64-bit fixed point: bit 63 - k is the half it lies in at the
// k-th cut of its axis (as repeated doubling would find; 1 stays in the upper halves).
uint64_t cube_bits(float x) {
  if (!(x < 1.f)) return x >= 1.f ? ~uint64_t(0) : uint64_t(1) << 63;  // (NaN: the middle)
  return x > 0.f ? uint64_t(double(x) * 0x1p64) : 0;
}

}  // namespace

uint32_t SpatialTree::leaf_of(Vec3 p, Vec3* extent) const {
  const Vec3 size = bounds_.diagonal();
  const uint64_t bits[3] = {cube_bits((p.x - bounds_.lo.x) / size.x), cube_bits((p.y - bounds_.lo.y) / size.y),
                            cube_bits((p.z - bounds_.lo.z) / size.z)};
  const auto upper = [&](int axis, uint32_t cut) { return cut < 64 ? uint32_t(bits[axis] >> (63 - cut)) & 1u : 0u; };
  uint32_t entry = 0, cut = 0;
  for (uint32_t step = 0;; step = entry, ++cut) {
    entry = steps_[step][upper(0, cut) | upper(1, cut) << 1 | upper(2, cut) << 2];
    if (entry & kLeafEntry) break;
  }
  if (extent) {
    // (`levels` cuts in all, in turn along x, y, z: a third of them along each, one more along the
    // axes before `axis`.)
    const uint32_t levels = 3 * cut + ((entry >> 29) & 3u), all = levels / 3, axis = levels % 3;
    *extent = Vec3(std::ldexp(size.x, -int(all + (axis > 0))), std::ldexp(size.y, -int(all + (axis > 1))),
                   std::ldexp(size.z, -int(all)));
  }
  return entry & ((1u << 29) - 1);
}

void SpatialTree::index_nodes() {
  TESSERA_CHECK(leaves_.size() < (size_t(1) << 29));
  steps_.clear();
  (void)make_step(0);
}

uint32_t SpatialTree::make_step(uint32_t node) {
  const uint32_t step = uint32_t(steps_.size());
  steps_.emplace_back();
  for (uint32_t e = 0; e < 8; ++e) {
    uint32_t n = node, levels = 0;
    for (; levels < 3 && nodes_[n].leaf == kNoLeaf; ++levels) n = nodes_[n].child[(e >> levels) & 1u];
    const uint32_t entry = nodes_[n].leaf != kNoLeaf ? kLeafEntry | levels << 29 | nodes_[n].leaf : make_step(n);
    steps_[step][e] = entry;
  }
  return step;
}

void SpatialTree::record_at(uint32_t leaf, Vec2 square, float value, float dither, DirectionalFilter filter) {
  Leaf& l = leaves_[leaf];
  std::atomic_ref<uint64_t>(l.samples).fetch_add(1, std::memory_order_relaxed);
  if (filter == DirectionalFilter::Box)
    l.building.record_box(square, value, dither);
  else
    l.building.record_at(square, value, dither);
}

void SpatialTree::record_pixel(uint32_t leaf, float value, float dither) {
  Leaf& l = leaves_[leaf];
  std::atomic_ref<uint64_t>(l.pixel_paths).fetch_add(1, std::memory_order_relaxed);
  if (const uint64_t q = DirectionalTree::fixed_point(value, dither))
    std::atomic_ref<uint64_t>(l.pixel_sum).fetch_add(q, std::memory_order_relaxed);
}

size_t SpatialTree::leaf_bytes(const Leaf& leaf) {
  return sizeof(Leaf) - 2 * sizeof(DirectionalTree) + leaf.sampling.bytes() + leaf.building.bytes();
}

size_t SpatialTree::bytes() const {
  size_t total = sizeof(*this) + nodes_.size() * sizeof(Node);
  for (const Leaf& l : leaves_) total += leaf_bytes(l);
  return total;
}

void SpatialTree::split(uint32_t node) {
  // Both halves start from the parent's trees (the same directions, half the samples each).
  const uint32_t leaf = nodes_[node].leaf, other = uint32_t(leaves_.size());
  leaves_[leaf].samples /= 2;
  leaves_.push_back(leaves_[leaf]);
  const uint32_t lo = uint32_t(nodes_.size());
  nodes_.resize(nodes_.size() + 2);
  nodes_[lo].leaf = leaf;
  nodes_[lo + 1].leaf = other;
  nodes_[node].leaf = kNoLeaf;
  nodes_[node].child[0] = lo;
  nodes_[node].child[1] = lo + 1;
}

const char* guide_combination_name(GuideCombination c) {
  return c == GuideCombination::Discard ? "discard" : "inversevar";
}

const char* guide_roulette_name(GuideRoulette r) {
  switch (r) {
    case GuideRoulette::Throughput: return "throughput";
    case GuideRoulette::Guided: return "guided";
    case GuideRoulette::Radiance: break;
  }
  return "radiance";
}

namespace {

// The one of `all` named `name` by `name_of`.
template <typename E, size_t N>
bool parse_named(const std::string& name, const E (&all)[N], const char* (*name_of)(E), E& out) {
  for (E e : all)
    if (name == name_of(e)) {
      out = e;
      return true;
    }
  return false;
}

}  // namespace

bool parse_guide_roulette(const std::string& name, GuideRoulette& out) {
  constexpr GuideRoulette kAll[] = {GuideRoulette::Throughput, GuideRoulette::Guided, GuideRoulette::Radiance};
  return parse_named(name, kAll, guide_roulette_name, out);
}

const char* spatial_filter_name(SpatialFilter f) { return f == SpatialFilter::Nearest ? "nearest" : "stochastic"; }

const char* directional_filter_name(DirectionalFilter f) { return f == DirectionalFilter::Nearest ? "nearest" : "box"; }

bool parse_spatial_filter(const std::string& name, SpatialFilter& out) {
  constexpr SpatialFilter kAll[] = {SpatialFilter::Nearest, SpatialFilter::Stochastic};
  return parse_named(name, kAll, spatial_filter_name, out);
}

bool parse_directional_filter(const std::string& name, DirectionalFilter& out) {
  constexpr DirectionalFilter kAll[] = {DirectionalFilter::Nearest, DirectionalFilter::Box};
  return parse_named(name, kAll, directional_filter_name, out);
}

double spatial_split_threshold(const GuidingSettings& settings, uint32_t iteration_spp) {
  return settings.spatial_threshold * std::sqrt(double(iteration_spp) / 4.0);
}

void SpatialTree::end_iteration(uint32_t iteration_spp, const GuidingSettings& settings) {
  ++iteration_;
  if (stepped_aside()) return;
  if (decide_gain(iteration_spp, settings)) {
    step_aside();
    return;
  }
  const double threshold = spatial_split_threshold(settings, iteration_spp);
  // The estimates first: a split leaf's halves keep its trees whole but half its samples.
  for (Leaf& l : leaves_) {
    l.building.build();
    const double samples = double(l.samples), paths = double(l.pixel_paths);
    l.radiance = samples > 0.0 ? float(DirectionalTree::from_fixed_point(double(l.building.total())) / samples) : 0.f;
    l.pixel = paths > 0.0 ? float(DirectionalTree::from_fixed_point(double(l.pixel_sum)) / paths) : 0.f;
    l.pixel_sum = l.pixel_paths = 0;
  }
  size_t total = bytes();
  // In index order, children right after they are made: a half that still has too many samples
  // is split again. The order, and so the result, depends only on the counts.
  for (uint32_t n = 0; n < nodes_.size(); ++n) {
    const uint32_t leaf = nodes_[n].leaf;
    if (leaf == kNoLeaf || !(double(leaves_[leaf].samples) > threshold)) continue;
    const size_t cost = 2 * sizeof(Node) + leaf_bytes(leaves_[leaf]);
    if (total + cost > settings.max_bytes) continue;
    split(n);
    total += cost;
  }
  index_nodes();
  for (Leaf& l : leaves_) {
    const size_t before = leaf_bytes(l);
    l.sampling = std::move(l.building);
    l.building = l.sampling.refined(settings.directional_threshold, settings.keep_energy);
    // A refined tree that would not fit keeps the cells it has.
    if (total - before + leaf_bytes(l) > settings.max_bytes)
      l.building = settings.keep_energy ? l.sampling : l.sampling.cleared();
    total = total - before + leaf_bytes(l);
    l.samples = 0;
    if (settings.learn_bsdf_fraction) l.bsdf_fraction = l.fraction_loss.best(l.bsdf_fraction, settings.min_bsdf_fraction);
    l.fraction_loss = {};
  }
  update_gain_scale();  // (of the leaves as split: what a tree read from bytes computes again)
}

bool SpatialTree::decide_gain(uint32_t iteration_spp, const GuidingSettings& settings) {
  const GuideGain gain = gain_;
  gain_ = {};
  // (Once: a guide that paid at the deciding iteration is not asked again.)
  if (!(settings.min_gain > 0.0) || predicted_gain_ > 0.f || iteration_spp < settings.gain_iteration_spp ||
      gain.paths < std::max<uint64_t>(settings.gain_paths, 1) || gain.guided == 0)
    return false;
  predicted_gain_ = std::max(float(gain.ratio()), std::numeric_limits<float>::min());
  return double(predicted_gain_) < settings.min_gain;
}

void SpatialTree::step_aside() {
  nodes_.assign(1, Node{});
  nodes_[0].leaf = 0;
  leaves_.assign(1, Leaf{});
  index_nodes();
  gain_scale_ = 1.f;
  aside_from_ = iteration_;
}

void SpatialTree::update_gain_scale() {
  double sum = 0.0;
  for (const Leaf& l : leaves_) sum += double(l.pixel);
  const float mean = float(sum / double(leaves_.size()));
  gain_scale_ = mean > 0.f && std::isfinite(mean) ? mean : 1.f;
}

bool SpatialTree::operator==(const SpatialTree& other) const {
  return nodes_ == other.nodes_ && leaves_ == other.leaves_ && gain_ == other.gain_ &&
         gain_scale_ == other.gain_scale_ && predicted_gain_ == other.predicted_gain_ &&
         iteration_ == other.iteration_ && aside_from_ == other.aside_from_;
}

}  // namespace tessera

#include "tessera/render/path_guide.h"

#include "tessera/core/hash.h"
#include "tessera/render/sampler.h"

#include <algorithm>
#include <array>
#include <bit>

namespace tessera {

void GuideRecords::commit(const PathGuide& guide, const Rgb& radiance, Sampler& sampler) const {
  SpatialTree& tree = *guide.records;
  if (count_ == 0 && !guide.sample) return;
  // Dithers and jitter need no stratification, and a sampler value costs its scrambling hashes:
  // one value seeds a stream for all of them.
  Pcg32 rng(std::bit_cast<uint32_t>(sampler.sample_1d_at(kRecordDimension)));
  if (count_ == 0) {
    record_gain(guide, radiance, rng.next_float());
    return;
  }
  tree.record_pixel(vertices_.at[0].leaf, radiance.luminance(), rng.next_float());
  // The leaves first, each asked into the cache while the next is found: a record descends a
  // directional tree no recent path has used.
  std::array<uint32_t, kCapacity> leaves;
  for (int k = 0; k < count_; ++k) {
    const Vertex& v = vertices_.at[size_t(k)];
    leaves[size_t(k)] = v.leaf;
    if (guide.spatial_filter == SpatialFilter::Stochastic) {
      const Vec3 u(rng.next_float(), rng.next_float(), rng.next_float());
      leaves[size_t(k)] = tree.leaf_of(v.p + (u - Vec3(0.5f)) * v.extent);
    }
    tree.prefetch_records(leaves[size_t(k)]);
  }
  for (int k = 0; k < count_; ++k) {
    const Vertex& v = vertices_.at[size_t(k)];
    const uint32_t leaf = leaves[size_t(k)];
    const float through = v.throughput.luminance();
    // (A path that ended at the vertex, or carries nothing further, still counts as a sample.)
    const float li = through > 0.f ? std::max(0.f, (radiance - v.radiance).luminance()) / through : 0.f;
    const float value = v.pdf > 0.f ? li / v.pdf : 0.f;
    tree.record_at(leaf, v.square, value, rng.next_float(), guide.directional_filter);
    if (v.mixture) tree.record_fraction(leaf, value * v.f_cos, v.mixture->bsdf, v.mixture->guide);
  }
  if (guide.sample) record_gain(guide, radiance, rng.next_float());
}

void GuideRecords::record_gain(const PathGuide& guide, const Rgb& radiance, float dither) const {
  const float estimate = radiance.luminance();
  const double scale = double(guide.tree->gain_scale());
  const double unit = 1.0 / (scale * scale);
  guide.records->record_gain(gain_.plain_moment(estimate) * unit, PathGain::guided_moment(estimate) * unit, dither);
}

}  // namespace tessera

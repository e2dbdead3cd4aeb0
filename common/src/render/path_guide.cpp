#include "tessera/render/path_guide.h"

#include "tessera/core/hash.h"
#include "tessera/render/sampler.h"

#include <algorithm>
#include <bit>

namespace tessera {

void GuideRecords::commit(const PathGuide& guide, const Rgb& radiance, Sampler& sampler) const {
  SpatialTree& tree = *guide.records;
  if (count_ > 0)
    tree.record_pixel(vertices_[0].leaf, radiance.luminance(), sampler.sample_1d_at(kPixelDitherDimension));
  // The leaves first, each asked into the cache while the next is found: a record descends a
  // directional tree no recent path has used.
  std::array<uint32_t, kCapacity> leaves;
  for (int k = 0; k < count_; ++k) {
    const Vertex& v = vertices_[size_t(k)];
    leaves[size_t(k)] = v.leaf;
    if (guide.spatial_filter == SpatialFilter::Stochastic) {
      const uint64_t h = mix64(std::bit_cast<uint32_t>(sampler.sample_1d_at(kJitterDimension + uint32_t(k))));
      const Vec3 u(float(h & 0x1FFFFFu), float((h >> 21) & 0x1FFFFFu), float((h >> 42) & 0x1FFFFFu));
      leaves[size_t(k)] = tree.leaf_of(v.p + (u * 0x1p-21f - Vec3(0.5f)) * v.extent);
    }
    tree.prefetch_records(leaves[size_t(k)]);
  }
  for (int k = 0; k < count_; ++k) {
    const Vertex& v = vertices_[size_t(k)];
    const uint32_t leaf = leaves[size_t(k)];
    const float through = v.throughput.luminance();
    // (A path that ended at the vertex, or carries nothing further, still counts as a sample.)
    const float li = through > 0.f ? std::max(0.f, (radiance - v.radiance).luminance()) / through : 0.f;
    const float value = v.pdf > 0.f ? li / v.pdf : 0.f;
    tree.record_at(leaf, v.square, value, sampler.sample_1d_at(kDitherDimension + uint32_t(k)), guide.directional_filter);
    if (v.mixture) tree.record_fraction(leaf, value * v.f_cos, v.mixture->bsdf, v.mixture->guide);
  }
}

}  // namespace tessera

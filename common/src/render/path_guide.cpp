#include "tessera/render/path_guide.h"

#include "tessera/render/sampler.h"

#include <algorithm>

namespace tessera {

void GuideRecords::commit(SpatialTree& tree, const Rgb& radiance, Sampler& sampler) const {
  if (count_ > 0)
    tree.record_pixel(vertices_[0].leaf, radiance.luminance(), sampler.sample_1d_at(kPixelDitherDimension));
  for (int k = 0; k < count_; ++k) {
    const Vertex& v = vertices_[size_t(k)];
    const float through = v.throughput.luminance();
    // (A path that ended at the vertex, or carries nothing further, still counts as a sample.)
    const float li = through > 0.f ? std::max(0.f, (radiance - v.radiance).luminance()) / through : 0.f;
    const float value = v.pdf > 0.f ? li / v.pdf : 0.f;
    tree.record_at(v.leaf, v.square, value, sampler.sample_1d_at(kDitherDimension + uint32_t(k)));
    if (v.mixture) tree.record_fraction(v.leaf, value * v.f_cos, v.mixture->bsdf, v.mixture->guide);
  }
}

}  // namespace tessera

#include "tessera/guiding/guide_gain.h"

#include "tessera/guiding/directional_tree.h"

#include <algorithm>
#include <atomic>

namespace tessera {

void GuideGain::record(double plain_moment, double guided_moment, float dither) {
  // (A moment beyond float's range counts as the largest record; NaN as nothing.)
  const auto fixed = [&](double m) { return DirectionalTree::fixed_point(float(std::min(m, 1e30)), dither); };
  if (const uint64_t q = fixed(plain_moment)) std::atomic_ref<uint64_t>(plain).fetch_add(q, std::memory_order_relaxed);
  if (const uint64_t q = fixed(guided_moment)) std::atomic_ref<uint64_t>(guided).fetch_add(q, std::memory_order_relaxed);
  std::atomic_ref<uint64_t>(paths).fetch_add(1, std::memory_order_relaxed);
}

}  // namespace tessera

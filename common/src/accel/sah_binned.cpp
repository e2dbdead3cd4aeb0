#include "accel/sah_binned.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace tessera::accel_detail {
namespace {

/// One bin: bounds of its primitives and their number. Plain floats, so an array of bins is not
/// initialised behind our back (Bounds3 and Vec3 have default initialisers).
struct Bin {
  float lo[3], hi[3];
  uint32_t count;
  void reset() {
    for (int a = 0; a < 3; ++a) lo[a] = kInfinity, hi[a] = -kInfinity;
    count = 0;
  }
  void add(const PrimRef& r) {
    lo[0] = std::min(lo[0], r.lo.x), lo[1] = std::min(lo[1], r.lo.y), lo[2] = std::min(lo[2], r.lo.z);
    hi[0] = std::max(hi[0], r.hi.x), hi[1] = std::max(hi[1], r.hi.y), hi[2] = std::max(hi[2], r.hi.z);
    ++count;
  }
  void merge(const Bin& o) {
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], o.lo[a]), hi[a] = std::max(hi[a], o.hi[a]);
    count += o.count;
  }
};

/// Per-axis bins; only the first `n` of each axis are initialised and used.
struct Bins {
  Bin bin[3][kNumBins];
  explicit Bins(int n = kNumBins) {
    for (int axis = 0; axis < 3; ++axis)
      for (int b = 0; b < n; ++b) bin[axis][b].reset();
  }
};

void bin_range(const PrimRef* refs, size_t begin, size_t end, const BinMapper& m, Bins& bins) {
  for (size_t i = begin; i < end; ++i) {
    const PrimRef& r = refs[i];
    const Vec3 c = r.centroid();
    for (int axis = 0; axis < 3; ++axis)
      if (m.usable[axis]) bins.bin[axis][m.bin(c, axis)].add(r);
  }
}

void merge_into(Bins& into, const Bins& from, int n) {
  for (int axis = 0; axis < 3; ++axis)
    for (int b = 0; b < n; ++b) into.bin[axis][b].merge(from.bin[axis][b]);
}

/// Surface area of a box given as accumulated lo/hi (zero when empty).
float area(const float lo[3], const float hi[3]) {
  const float dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
  if (dx < 0.f) return 0.f;
  return 2.f * (dx * dy + dy * dz + dz * dx);
}

size_t num_chunks(size_t n) { return (n + kReduceChunk - 1) / kReduceChunk; }

}  // namespace

RangeBounds compute_range_bounds(const PrimRef* refs, size_t n, bool parallel) {
  auto reduce = [refs](size_t begin, size_t end) {
    RangeBounds rb;
    for (size_t i = begin; i < end; ++i) {
      rb.bounds.lo = vmin(rb.bounds.lo, refs[i].lo);
      rb.bounds.hi = vmax(rb.bounds.hi, refs[i].hi);
      rb.centroids.extend(refs[i].centroid());
    }
    return rb;
  };
  if (!parallel || n <= kReduceChunk) return reduce(0, n);
  // Fixed chunks, merged in chunk order: the result does not depend on the thread count (min/max
  // are exact, but the sign of a zero could depend on the merge order).
  const size_t chunks = num_chunks(n);
  std::vector<RangeBounds> partial(chunks);
  tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
    partial[k] = reduce(k * kReduceChunk, std::min(n, (k + 1) * kReduceChunk));
  });
  RangeBounds rb;
  for (const RangeBounds& p : partial) {
    rb.bounds.extend(p.bounds);
    rb.centroids.extend(p.centroids);
  }
  return rb;
}

BinMapper::BinMapper(const Bounds3& centroids, int bins) : num_bins(bins) {
  for (int axis = 0; axis < 3; ++axis) {
    const float extent = centroids.hi[axis] - centroids.lo[axis];
    lo[axis] = centroids.lo[axis];
    scale[axis] = extent > 0.f ? float(bins) / extent : 0.f;
    usable[axis] = extent > 0.f && std::isfinite(scale[axis]) && std::isfinite(extent);
  }
}

SahSplit find_sah_split(const PrimRef* refs, size_t n, const Bounds3& bounds, const BinMapper& mapper,
                        bool parallel) {
  const int nb = mapper.num_bins;
  Bins bins(nb);
  if (!parallel || n <= kReduceChunk) {
    bin_range(refs, 0, n, mapper, bins);
  } else {
    const size_t chunks = num_chunks(n);
    std::vector<Bins> partial(chunks, Bins(nb));
    tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
      bin_range(refs, k * kReduceChunk, std::min(n, (k + 1) * kReduceChunk), mapper, partial[k]);
    });
    for (const Bins& p : partial) merge_into(bins, p, nb);
  }

  const float node_area = bounds.surface_area();
  const float inv_area = node_area > 0.f ? 1.f / node_area : 0.f;
  SahSplit best;
  for (int axis = 0; axis < 3; ++axis) {
    if (!mapper.usable[axis]) continue;
    // right_cost[b]: n_R * SA(R) for the primitives in bins b+1 .. end.
    float right_cost[kNumBins];
    uint32_t right_count[kNumBins];
    Bin acc;
    acc.reset();
    for (int b = nb - 1; b > 0; --b) {
      acc.merge(bins.bin[axis][b]);
      right_cost[b - 1] = float(acc.count) * area(acc.lo, acc.hi);
      right_count[b - 1] = acc.count;
    }
    acc.reset();
    for (int b = 0; b + 1 < nb; ++b) {
      acc.merge(bins.bin[axis][b]);
      if (acc.count == 0 || right_count[b] == 0) continue;
      const float cost = kTraversalCost + (float(acc.count) * area(acc.lo, acc.hi) + right_cost[b]) * inv_area;
      if (!best.valid || cost < best.cost) best = SahSplit{true, axis, b, cost};
    }
  }
  return best;
}

}  // namespace tessera::accel_detail

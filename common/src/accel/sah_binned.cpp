#include "accel/sah_binned.h"

#include <tbb/parallel_for.h>

#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace tessera::accel_detail {
namespace {

// Binning dominates the build, so it is written with SSE2 (part of the x86-64 baseline: no extra
// compiler flags). Lane 3 of every vector is unused; it is masked to zero on load so that the
// primitive index stored beside the bounds never takes part in arithmetic.
const __m128 kXyzMask = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));

inline __m128 load_xyz(const Vec3& v) { return _mm_and_ps(_mm_loadu_ps(&v.x), kXyzMask); }

struct Box4 {
  __m128 lo = _mm_set1_ps(kInfinity), hi = _mm_set1_ps(-kInfinity);
  void extend(__m128 l, __m128 h) {
    lo = _mm_min_ps(lo, l);
    hi = _mm_max_ps(hi, h);
  }
  void extend(const Box4& b) { extend(b.lo, b.hi); }
  /// Surface area; zero when empty.
  float area() const {
    alignas(16) float d[4];
    _mm_store_ps(d, _mm_sub_ps(hi, lo));
    if (d[0] < 0.f) return 0.f;
    return 2.f * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
  }
  Bounds3 bounds() const {
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo);
    _mm_store_ps(h, hi);
    return Bounds3{Vec3(l[0], l[1], l[2]), Vec3(h[0], h[1], h[2])};
  }
};

/// Per-axis bins; only the first `n` of each axis are initialised and used.
struct Bins {
  Box4 box[3][kNumBins];
  uint32_t count[3][kNumBins];
  explicit Bins(int n) {
    for (int axis = 0; axis < 3; ++axis)
      for (int b = 0; b < n; ++b) {
        box[axis][b] = Box4{};
        count[axis][b] = 0;
      }
  }
};

void bin_range(const PrimRef* refs, size_t begin, size_t end, const BinMapper& m, Bins& bins) {
  const __m128 lo = _mm_setr_ps(m.lo[0], m.lo[1], m.lo[2], 0.f);
  const __m128 scale = _mm_setr_ps(m.scale[0], m.scale[1], m.scale[2], 0.f);
  const __m128 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f);
  const __m128 last = _mm_set1_ps(float(m.num_bins - 1));
  alignas(16) int32_t b[4];
  for (size_t i = begin; i < end; ++i) {
    const __m128 plo = load_xyz(refs[i].lo), phi = load_xyz(refs[i].hi);
    // Same arithmetic as BinMapper::bin, lane by lane.
    const __m128 c = _mm_mul_ps(_mm_add_ps(plo, phi), half);
    const __m128 f = _mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_sub_ps(c, lo), scale), zero), last);
    _mm_store_si128(reinterpret_cast<__m128i*>(b), _mm_cvttps_epi32(f));
    for (int axis = 0; axis < 3; ++axis) {
      bins.box[axis][b[axis]].extend(plo, phi);
      ++bins.count[axis][b[axis]];
    }
  }
}

void merge_into(Bins& into, const Bins& from, int n) {
  for (int axis = 0; axis < 3; ++axis)
    for (int b = 0; b < n; ++b) {
      into.box[axis][b].extend(from.box[axis][b]);
      into.count[axis][b] += from.count[axis][b];
    }
}

size_t num_chunks(size_t n) { return (n + kReduceChunk - 1) / kReduceChunk; }

struct RangeBox {
  Box4 bounds, centroids;
};

RangeBox reduce_range(const PrimRef* refs, size_t begin, size_t end) {
  RangeBox rb;
  const __m128 half = _mm_set1_ps(0.5f);
  for (size_t i = begin; i < end; ++i) {
    const __m128 plo = load_xyz(refs[i].lo), phi = load_xyz(refs[i].hi);
    const __m128 c = _mm_mul_ps(_mm_add_ps(plo, phi), half);
    rb.bounds.extend(plo, phi);
    rb.centroids.extend(c, c);
  }
  return rb;
}

}  // namespace

RangeBounds compute_range_bounds(const PrimRef* refs, size_t n, bool parallel) {
  RangeBox rb;
  if (!parallel || n <= kReduceChunk) {
    rb = reduce_range(refs, 0, n);
  } else {
    // Fixed chunks, merged in chunk order: the result does not depend on the thread count (min/max
    // are exact, but the sign of a zero could depend on the merge order).
    const size_t chunks = num_chunks(n);
    std::vector<RangeBox> partial(chunks);
    tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
      partial[k] = reduce_range(refs, k * kReduceChunk, std::min(n, (k + 1) * kReduceChunk));
    });
    for (const RangeBox& p : partial) {
      rb.bounds.extend(p.bounds);
      rb.centroids.extend(p.centroids);
    }
  }
  return {rb.bounds.bounds(), rb.centroids.bounds()};
}

BinMapper::BinMapper(const Bounds3& centroids, int bins) : num_bins(bins) {
  for (int axis = 0; axis < 3; ++axis) {
    const float extent = centroids.hi[axis] - centroids.lo[axis];
    lo[axis] = centroids.lo[axis];
    scale[axis] = extent > 0.f ? float(bins) / extent : 0.f;
    usable[axis] = extent > 0.f && std::isfinite(scale[axis]) && std::isfinite(extent);
    if (!usable[axis]) scale[axis] = 0.f;  // every centroid in bin 0
  }
}

SahSplit find_sah_split(const PrimRef* refs, size_t n, const Bounds3& bounds, const BinMapper& mapper,
                        uint32_t block_shift, bool parallel) {
  const uint32_t round = (1u << block_shift) - 1;
  const auto blocks = [&](uint32_t count) { return float((count + round) >> block_shift); };
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
    Box4 acc;
    uint32_t count = 0;
    for (int b = nb - 1; b > 0; --b) {
      acc.extend(bins.box[axis][b]);
      count += bins.count[axis][b];
      right_cost[b - 1] = blocks(count) * acc.area();
      right_count[b - 1] = count;
    }
    acc = Box4{};
    count = 0;
    for (int b = 0; b + 1 < nb; ++b) {
      acc.extend(bins.box[axis][b]);
      count += bins.count[axis][b];
      if (count == 0 || right_count[b] == 0) continue;
      const float cost = kTraversalCost + (blocks(count) * acc.area() + right_cost[b]) * inv_area;
      if (!best.valid || cost < best.cost) best = SahSplit{true, axis, b, cost};
    }
  }
  return best;
}

}  // namespace tessera::accel_detail

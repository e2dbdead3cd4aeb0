// The watertight triangle test on a Tri4 packet: four triangles against one ray with SSE2 (private
// to accel). Lane by lane it performs exactly the float operations of intersect_triangle_k (same
// order, no contraction: the build uses -ffp-contract=off), so a triangle hit here and one hit by
// the scalar test give the same bits.
#pragma once

#include "accel/intersect_inline.h"
#include "tessera/accel/bvh.h"

#include <emmintrin.h>

#include <type_traits>

namespace tessera::accel_detail {

/// Per-ray broadcasts for the packet test.
struct WatertightRay4 {
  __m128 o[3];  // origin, by axis
  __m128 sx, sy;
  static WatertightRay4 make(const WatertightRay& r) {
    return {{_mm_set1_ps(r.o.x), _mm_set1_ps(r.o.y), _mm_set1_ps(r.o.z)}, _mm_set1_ps(r.sx), _mm_set1_ps(r.sy)};
  }
};

/// Lanes whose triangle the ray's line passes through (edge test and det != 0), as a 4-bit mask;
/// e1, e2 and det of those lanes are stored for the barycentrics. Unused lanes never pass.
template <int kz>
inline int tri4_candidates(const Tri4& p, const WatertightRay4& r, float e1_out[4], float e2_out[4],
                           float det_out[4]) {
  constexpr int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  const __m128 akx = _mm_sub_ps(_mm_load_ps(p.v[0][kx]), r.o[kx]);
  const __m128 aky = _mm_sub_ps(_mm_load_ps(p.v[0][ky]), r.o[ky]);
  const __m128 akz = _mm_sub_ps(_mm_load_ps(p.v[0][kz]), r.o[kz]);
  const __m128 bkx = _mm_sub_ps(_mm_load_ps(p.v[1][kx]), r.o[kx]);
  const __m128 bky = _mm_sub_ps(_mm_load_ps(p.v[1][ky]), r.o[ky]);
  const __m128 bkz = _mm_sub_ps(_mm_load_ps(p.v[1][kz]), r.o[kz]);
  const __m128 ckx = _mm_sub_ps(_mm_load_ps(p.v[2][kx]), r.o[kx]);
  const __m128 cky = _mm_sub_ps(_mm_load_ps(p.v[2][ky]), r.o[ky]);
  const __m128 ckz = _mm_sub_ps(_mm_load_ps(p.v[2][kz]), r.o[kz]);
  const __m128 ax = _mm_sub_ps(akx, _mm_mul_ps(r.sx, akz)), ay = _mm_sub_ps(aky, _mm_mul_ps(r.sy, akz));
  const __m128 bx = _mm_sub_ps(bkx, _mm_mul_ps(r.sx, bkz)), by = _mm_sub_ps(bky, _mm_mul_ps(r.sy, bkz));
  const __m128 cx = _mm_sub_ps(ckx, _mm_mul_ps(r.sx, ckz)), cy = _mm_sub_ps(cky, _mm_mul_ps(r.sy, ckz));
  __m128 e0 = _mm_sub_ps(_mm_mul_ps(bx, cy), _mm_mul_ps(by, cx));
  __m128 e1 = _mm_sub_ps(_mm_mul_ps(cx, ay), _mm_mul_ps(cy, ax));
  __m128 e2 = _mm_sub_ps(_mm_mul_ps(ax, by), _mm_mul_ps(ay, bx));

  const __m128 zero = _mm_setzero_ps();
  const int used = ~_mm_movemask_ps(_mm_castsi128_ps(
                       _mm_cmpeq_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(p.prim)),
                                       _mm_set1_epi32(-1)))) & 0xF;
  const int zeros =
      _mm_movemask_ps(_mm_or_ps(_mm_cmpeq_ps(e0, zero), _mm_or_ps(_mm_cmpeq_ps(e1, zero), _mm_cmpeq_ps(e2, zero)))) &
      used;
  if (zeros) [[unlikely]] {
    alignas(16) float f[9][4];
    const __m128 v[9] = {ax, ay, bx, by, cx, cy, e0, e1, e2};
    for (int i = 0; i < 9; ++i) _mm_store_ps(f[i], v[i]);
    for (int l = 0; l < 4; ++l)
      if (zeros & (1 << l)) exact_edges(f[0][l], f[1][l], f[2][l], f[3][l], f[4][l], f[5][l], f[6][l], f[7][l], f[8][l]);
    e0 = _mm_load_ps(f[6]);
    e1 = _mm_load_ps(f[7]);
    e2 = _mm_load_ps(f[8]);
  }
  const __m128 neg = _mm_or_ps(_mm_cmplt_ps(e0, zero), _mm_or_ps(_mm_cmplt_ps(e1, zero), _mm_cmplt_ps(e2, zero)));
  const __m128 pos = _mm_or_ps(_mm_cmpgt_ps(e0, zero), _mm_or_ps(_mm_cmpgt_ps(e1, zero), _mm_cmpgt_ps(e2, zero)));
  const __m128 det = _mm_add_ps(_mm_add_ps(e0, e1), e2);
  const __m128 pass = _mm_andnot_ps(_mm_and_ps(neg, pos), _mm_cmpneq_ps(det, zero));
  const int mask = _mm_movemask_ps(pass) & used;
  if (mask) {
    _mm_storeu_ps(e1_out, e1);
    _mm_storeu_ps(e2_out, e2);
    _mm_storeu_ps(det_out, det);
  }
  return mask;
}

/// Any-hit filter that lets every hit block; a filter says whether a candidate hit blocks the ray
/// (HitFilter::blocks with the ray bound).
struct NoFilter {
  constexpr bool operator()(const Hit&) const { return true; }
};

/// Closest (or, with kAnyHit, any blocking) hit among a packet's triangles with t in (tmin, tmax];
/// lanes in order, so ties go to the lower lane as in a scalar loop. Updates tmax and hit on a hit.
template <int kz, bool kAnyHit, class Filter = NoFilter>
inline bool intersect_tri4(const Tri4& p, const WatertightRay& wr, const WatertightRay4& r4, float tmin,
                           float& tmax, Hit& hit, const Filter& blocks = {}) {
  float e1[4], e2[4], det[4];
  int mask = tri4_candidates<kz>(p, r4, e1, e2, det);
  bool found = false;
  while (mask) {
    const int l = __builtin_ctz(unsigned(mask));
    mask &= mask - 1;
    const Vec3 p0(p.v[0][0][l], p.v[0][1][l], p.v[0][2][l]);
    const Vec3 p1(p.v[1][0][l], p.v[1][1][l], p.v[1][2][l]);
    const Vec3 p2(p.v[2][0][l], p.v[2][1][l], p.v[2][2][l]);
    const float t = plane_distance(wr, p0, p1, p2);
    if (!(t > tmin) || t > tmax) continue;
    const float inv_det = 1.f / det[l];
    if constexpr (kAnyHit) {
      if (std::is_same_v<Filter, NoFilter> || blocks(Hit{t, p.prim[l], e1[l] * inv_det, e2[l] * inv_det})) return true;
      continue;
    }
    tmax = t;
    hit.t = t;
    hit.prim = p.prim[l];
    hit.b1 = e1[l] * inv_det;
    hit.b2 = e2[l] * inv_det;
    found = true;
  }
  return found;
}

}  // namespace tessera::accel_detail

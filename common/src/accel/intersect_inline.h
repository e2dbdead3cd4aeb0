// Inline ray/primitive kernels shared by the BVH traversal and the public intersect_* functions.
// Private to the accel sources: the public entry points are in tessera/accel/bvh.h.
#pragma once

#include "tessera/core/ray.h"
#include "tessera/core/vec.h"

#include <array>
#include <cmath>
#include <limits>

namespace tessera::accel_detail {

/// pbrt's gamma(n): bound on the relative error of n chained float roundings.
constexpr float gamma(int n) {
  constexpr float eps = std::numeric_limits<float>::epsilon() * 0.5f;
  return (float(n) * eps) / (1.f - float(n) * eps);
}

/// Index of the largest |d| component: the axis the watertight test projects along.
inline int watertight_axis(Vec3 d) { return max_dimension(vabs(d)); }

/// Per-ray constants of the watertight test (Woop, Benthin, Wald 2013, sec. 3): with kz the
/// dominant direction axis, kx and ky the next two cyclically, a vertex relative to the origin is
/// sheared so that the ray becomes the +z axis. The axis choice is a template parameter in the
/// kernels so the permutation costs nothing per triangle.
struct WatertightRay {
  Vec3 o;
  double d[3] = {0, 0, 0};  // the direction, for the double-precision distance
  float sx = 0, sy = 0, sz = 0;
  template <int kz>
  static WatertightRay make(const Ray& ray) {
    constexpr int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    WatertightRay r;
    r.o = ray.o;
    r.sz = 1.f / ray.d[kz];
    r.sx = ray.d[kx] * r.sz;
    r.sy = ray.d[ky] * r.sz;
    r.d[0] = ray.d.x, r.d[1] = ray.d.y, r.d[2] = ray.d.z;
    return r;
  }
};

/// The edge functions again when a float one came out zero: a float zero may be a rounded
/// non-zero, so decide the sign exactly (products of floats are exact in double, and so is the
/// difference of two of them up to one rounding).
inline void exact_edges(float ax, float ay, float bx, float by, float cx, float cy, float& e0, float& e1,
                        float& e2) {
  e0 = float(double(bx) * double(cy) - double(by) * double(cx));
  e1 = float(double(cx) * double(ay) - double(cy) * double(ax));
  e2 = float(double(ax) * double(by) - double(ay) * double(bx));
}

/// Distance along the ray to the triangle's plane: dot(n, p0 - o) / dot(n, d) in double, where the
/// vertex differences and the cross product are (nearly) exact. NaN when the ray is parallel to the
/// plane, so that every range test rejects it.
inline float plane_distance(const WatertightRay& r, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const double e1x = double(p1.x) - p0.x, e1y = double(p1.y) - p0.y, e1z = double(p1.z) - p0.z;
  const double e2x = double(p2.x) - p0.x, e2y = double(p2.y) - p0.y, e2z = double(p2.z) - p0.z;
  const double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
  const double denom = nx * r.d[0] + ny * r.d[1] + nz * r.d[2];
  if (denom == 0.0) return std::numeric_limits<float>::quiet_NaN();
  const double num = nx * (double(p0.x) - r.o.x) + ny * (double(p0.y) - r.o.y) + nz * (double(p0.z) - r.o.z);
  return float(num / denom);
}

/// Watertight ray/triangle test; accepts t in (tmin, tmax].
///
/// Inside/outside comes from Woop, Benthin and Wald: edge functions evaluated in a frame where the
/// ray is an axis, ties re-evaluated in double, zeros admitted, so a ray through a shared edge or
/// vertex of a closed mesh hits at least one of the triangles. The distance does not come from the
/// sheared z (its error grows with the triangle's size over t, which made pbrt-v4's conservative
/// t > 0 bound reject real hits on long slivers seen at grazing angles, and put t off by 1e-3
/// relative on short rays): it is plane_distance, accurate to a few double ULPs of the float
/// triangle. Only candidates that pass the edge test pay for it. The 4-wide test (tri4_inline.h)
/// performs the same float operations lane by lane, so both give the same bits.
template <int kz>
inline bool intersect_triangle_k(const WatertightRay& r, const Vec3& p0, const Vec3& p1, const Vec3& p2,
                                 float tmin, float tmax, float& t_out, float& b1_out, float& b2_out) {
  constexpr int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  const Vec3 a = p0 - r.o, b = p1 - r.o, c = p2 - r.o;
  const float ax = a[kx] - r.sx * a[kz], ay = a[ky] - r.sy * a[kz];
  const float bx = b[kx] - r.sx * b[kz], by = b[ky] - r.sy * b[kz];
  const float cx = c[kx] - r.sx * c[kz], cy = c[ky] - r.sy * c[kz];

  // Edge functions; e0 weighs p0, e1 p1, e2 p2 (pbrt-v4 naming).
  float e0 = bx * cy - by * cx;
  float e1 = cx * ay - cy * ax;
  float e2 = ax * by - ay * bx;
  if (e0 == 0.f || e1 == 0.f || e2 == 0.f) [[unlikely]]
    exact_edges(ax, ay, bx, by, cx, cy, e0, e1, e2);
  if ((e0 < 0.f || e1 < 0.f || e2 < 0.f) && (e0 > 0.f || e1 > 0.f || e2 > 0.f)) return false;
  const float det = e0 + e1 + e2;
  if (det == 0.f) return false;

  const float t = plane_distance(r, p0, p1, p2);
  if (!(t > tmin) || t > tmax) return false;

  const float inv_det = 1.f / det;
  t_out = t;
  b1_out = e1 * inv_det;
  b2_out = e2 * inv_det;
  return true;
}

/// Sphere test after Haines et al., "Precision Improvements for Ray/Sphere Intersection" (Ray
/// Tracing Gems, ch. 7): the discriminant comes from the distance of the centre to the ray's line,
/// not from b^2 - ac (which cancels catastrophically for small, distant spheres), and the two roots
/// from the stable q-form. Nearest root in (tmin, tmax].
inline bool intersect_sphere_inline(const Ray& ray, Vec3 center, float radius, float tmin, float tmax,
                                    float& t_out) {
  const Vec3 f = ray.o - center;
  const float a = dot(ray.d, ray.d);
  const float b = -dot(f, ray.d);  // half of the usual -b
  const Vec3 l = f + ray.d * (b / a);  // centre -> closest point of the line
  const float len_l = length(l);
  const float disc = a * ((radius - len_l) * (radius + len_l));
  if (!(disc >= 0.f)) return false;
  const float c = dot(f, f) - radius * radius;
  const float q = b + std::copysign(std::sqrt(disc), b);
  float t0, t1;
  if (q == 0.f) {  // grazing the sphere at the origin
    t0 = t1 = 0.f;
  } else {
    t0 = c / q;
    t1 = q / a;
  }
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > tmin && t0 <= tmax) {
    t_out = t0;
    return true;
  }
  if (t1 > tmin && t1 <= tmax) {
    t_out = t1;
    return true;
  }
  return false;
}

}  // namespace tessera::accel_detail

// Public single-primitive tests. The BVH uses the same kernels (intersect_inline.h) with the per-ray
// constants hoisted out of the leaf loop.
#include "accel/intersect_inline.h"
#include "tessera/accel/bvh.h"

namespace tessera {

bool intersect_triangle(const Ray& ray, Vec3 p0, Vec3 p1, Vec3 p2, float& t, float& b1, float& b2) {
  using namespace accel_detail;
  switch (watertight_axis(ray.d)) {
    case 0:
      return intersect_triangle_k<0>(WatertightRay::make<0>(ray), p0, p1, p2, ray.tmin, ray.tmax, t, b1, b2);
    case 1:
      return intersect_triangle_k<1>(WatertightRay::make<1>(ray), p0, p1, p2, ray.tmin, ray.tmax, t, b1, b2);
    default:
      return intersect_triangle_k<2>(WatertightRay::make<2>(ray), p0, p1, p2, ray.tmin, ray.tmax, t, b1, b2);
  }
}

bool intersect_sphere(const Ray& ray, Vec3 center, float radius, float& t) {
  return accel_detail::intersect_sphere_inline(ray, center, radius, ray.tmin, ray.tmax, t);
}

}  // namespace tessera

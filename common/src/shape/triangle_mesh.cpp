// World-space triangle meshes: area sampling and hit completion.
#include "tessera/core/check.h"
#include "tessera/render/shape.h"

#include <cmath>

namespace tessera {

namespace {

struct Tri {
  Vec3 p0, p1, p2;
};

inline Tri triangle(const MeshData& m, uint32_t t) {
  const uint32_t* i = &m.indices[3 * size_t(t)];
  return {m.positions[i[0]], m.positions[i[1]], m.positions[i[2]]};
}

inline bool usable(Vec3 n) {
  float l2 = length_squared(n);
  return l2 > 0.f && std::isfinite(l2);
}

/// Unit geometric normal by winding order; degenerate triangles (which loaders drop, but a
/// to_world can still collapse) get +z so that callers always receive a valid frame.
inline Vec3 geometric_normal(const Tri& t, bool flip) {
  Vec3 c = cross(t.p1 - t.p0, t.p2 - t.p0);
  Vec3 n = usable(c) ? normalize(c) : Vec3(0.f, 0.f, 1.f);
  return flip ? -n : n;
}

}  // namespace

TriangleMeshShape::TriangleMeshShape(std::shared_ptr<const MeshData> mesh, bool flip_normals,
                                     bool face_normals)
    : mesh_(std::move(mesh)), flip_(flip_normals), face_normals_(face_normals) {
  TESSERA_CHECK(mesh_ != nullptr);
  TESSERA_CHECK(mesh_->indices.size() % 3 == 0);
  TESSERA_CHECK(mesh_->normals.empty() || mesh_->normals.size() == mesh_->positions.size());
  TESSERA_CHECK(mesh_->uvs.empty() || mesh_->uvs.size() == mesh_->positions.size());
  const size_t n = mesh_->num_triangles();
  std::vector<float> areas(n);
  double total = 0;
  for (size_t t = 0; t < n; ++t) {
    Tri tri = triangle(*mesh_, uint32_t(t));
    float a = 0.5f * length(cross(tri.p1 - tri.p0, tri.p2 - tri.p0));
    areas[t] = std::isfinite(a) ? a : 0.f;
    total += areas[t];
  }
  area_ = float(total);
  tri_area_ = Distribution1D(areas);
}

Bounds3 TriangleMeshShape::bounds() const {
  Bounds3 b;
  for (uint32_t i : mesh_->indices) b.extend(mesh_->positions[i]);
  return b;
}

void TriangleMeshShape::sample_area(Vec2 u, Vec3& p, Vec3& n, float& pdf_area) const {
  if (!(area_ > 0.f)) {
    p = Vec3(0.f);
    n = Vec3(0.f, 0.f, 1.f);
    pdf_area = 0.f;
    return;
  }
  // The triangle is chosen with u.y; its remapped remainder and u.x place the point, so one
  // stratified 2D sample stays well distributed over the whole mesh.
  float u_rest = 0.f;
  uint32_t t = tri_area_.sample_discrete(u.y, nullptr, &u_rest);
  Tri tri = triangle(*mesh_, t);
  Vec2 b = square_to_uniform_triangle({u.x, u_rest});
  p = tri.p0 * (1.f - b.x - b.y) + tri.p1 * b.x + tri.p2 * b.y;
  n = geometric_normal(tri, flip_);
  pdf_area = 1.f / area_;
}

void TriangleMeshShape::fill_interaction(const Ray& ray, const Hit& hit, uint32_t prim,
                                         SurfaceInteraction& si) const {
  TESSERA_DCHECK(prim < mesh_->num_triangles());
  const uint32_t* idx = &mesh_->indices[3 * size_t(prim)];
  Tri tri = triangle(*mesh_, prim);
  const float b1 = hit.b1, b2 = hit.b2, b0 = 1.f - b1 - b2;

  // Re-interpolating from the vertices keeps p on the triangle's plane (ray.at(t) drifts off it
  // by the error in t), which the self-intersection offset relies on.
  si.p = tri.p0 * b0 + tri.p1 * b1 + tri.p2 * b2;
  si.p_error = barycentric_point_error(tri.p0, tri.p1, tri.p2, b0, b1, b2);
  si.t = hit.t;
  si.ng = geometric_normal(tri, flip_);

  Vec3 ns = si.ng;
  if (!face_normals_ && !mesh_->normals.empty()) {
    const auto& nn = mesh_->normals;
    Vec3 s = nn[idx[0]] * b0 + nn[idx[1]] * b1 + nn[idx[2]] * b2;
    if (usable(s)) {
      s = normalize(s);
      ns = flip_ ? -s : s;
      // Contract: the shading normal lies on ng's side, so BSDFs and the integrator agree on
      // which side of the surface a direction is.
      if (dot(ns, si.ng) < 0.f) ns = -ns;
    }
  }
  si.shading = Frame(ns);

  bool have_dpduv = false;
  if (!mesh_->uvs.empty()) {
    const auto& uv = mesh_->uvs;
    const Vec2 uv0 = uv[idx[0]], uv1 = uv[idx[1]], uv2 = uv[idx[2]];
    si.uv = uv0 * b0 + uv1 * b1 + uv2 * b2;
    // pbrt's solve of [dp02 dp12] = [dpdu dpdv] [duv02 duv12] (per hit: a 2x2 inverse is cheaper
    // than storing six floats per triangle).
    const Vec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
    const float det = duv02.x * duv12.y - duv02.y * duv12.x;
    if (det != 0.f) {
      const float inv = 1.f / det;
      const Vec3 dp02 = tri.p0 - tri.p2, dp12 = tri.p1 - tri.p2;
      si.dpdu = (dp02 * duv12.y - dp12 * duv02.y) * inv;
      si.dpdv = (dp12 * duv02.x - dp02 * duv12.x) * inv;
      // A tiny determinant can still overflow, and collinear results span no plane.
      have_dpduv = is_finite(si.dpdu) && is_finite(si.dpdv) && usable(cross(si.dpdu, si.dpdv));
    }
  } else {
    si.uv = Vec2(b1, b2);  // Mitsuba 3's parameterization of a mesh without uvs
  }
  if (!have_dpduv) coordinate_system(si.ng, si.dpdu, si.dpdv);
  si.wo = normalize(-ray.d);
  si.shape = this;
  si.prim = prim;
}

}  // namespace tessera

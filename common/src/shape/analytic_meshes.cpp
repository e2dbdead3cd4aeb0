// Mitsuba's analytic flat shapes as triangle meshes (object space). The renderer intersects only
// triangles and spheres, so rectangle, cube and disk are tessellated once here.
// Flat faces carry no vertex normals where none are needed (rectangle, disk): the geometric normal
// is exact, and it stays exact under any to_world. The cube keeps Mitsuba's 24 vertices with
// per-face normals.
#include "tessera/shape/mesh_io.h"

#include "tessera/core/check.h"

#include <cmath>

namespace tessera {

MeshData make_rectangle_mesh() {
  MeshData m;
  m.positions = {{-1.f, -1.f, 0.f}, {1.f, -1.f, 0.f}, {1.f, 1.f, 0.f}, {-1.f, 1.f, 0.f}};
  // Mitsuba: uv = (x, y) * 0.5 + 0.5.
  m.uvs = {{0.f, 0.f}, {1.f, 0.f}, {1.f, 1.f}, {0.f, 1.f}};
  m.indices = {0, 1, 2, 2, 3, 0};  // counter-clockwise seen from +z: normal +z
  return m;
}

MeshData make_cube_mesh() {
  MeshData m;
  static const float kCorner[4][2] = {{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}};
  for (int axis = 0; axis < 3; ++axis) {
    for (float sign : {-1.f, 1.f}) {
      // (u, v, axis) is a cyclic permutation, so e_u x e_v = e_axis.
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Vec3 n(0.f);
      n[axis] = sign;
      uint32_t base = uint32_t(m.positions.size());
      for (const auto& c : kCorner) {
        Vec3 p(0.f);
        p[axis] = sign;
        p[u] = c[0];
        p[v] = c[1];
        m.positions.push_back(p);
        m.normals.push_back(n);
        m.uvs.push_back({0.5f * (c[0] + 1.f), 0.5f * (c[1] + 1.f)});
      }
      if (sign > 0.f)
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
      else
        m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    }
  }
  return m;
}

MeshData make_disk_mesh(int segments) {
  TESSERA_CHECK(segments >= 3);
  MeshData m;
  const double n = double(segments);
  const double two_pi = 2.0 * 3.14159265358979323846;
  // A regular N-gon of circumradius R has area (N/2) R^2 sin(2 pi / N); choose R so it equals pi.
  const double rim = std::sqrt(two_pi / (n * std::sin(two_pi / n)));
  // Rim vertices 0..N (N repeats 0 at phi = 2 pi so the uv seam does not wrap across a triangle),
  // then one centre vertex per segment carrying that segment's mid angle in uv.
  for (int k = 0; k <= segments; ++k) {
    double phi = two_pi * double(k) / n;
    int kk = k % segments;  // exact same position for the seam vertex
    double phi_pos = two_pi * double(kk) / n;
    m.positions.push_back(Vec3(float(rim * std::cos(phi_pos)), float(rim * std::sin(phi_pos)), 0.f));
    m.uvs.push_back({1.f, float(phi / two_pi)});
  }
  for (int k = 0; k < segments; ++k) {
    m.positions.push_back(Vec3(0.f, 0.f, 0.f));
    m.uvs.push_back({0.f, float((k + 0.5) / n)});
  }
  const uint32_t center0 = uint32_t(segments + 1);
  for (int k = 0; k < segments; ++k)
    m.indices.insert(m.indices.end(), {center0 + uint32_t(k), uint32_t(k), uint32_t(k + 1)});
  return m;
}

}  // namespace tessera

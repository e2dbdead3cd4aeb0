// Post-processing every mesh loader shares: validation, degenerate removal, vertex normals.
#include "tessera/shape/mesh_io.h"

#include "tessera/scene/error.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace tessera {

namespace {

bool finite2(Vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }

/// Angle between two unit vectors, accurate for small and near-pi angles (unlike acos of the dot).
float unit_angle(Vec3 a, Vec3 b) {
  if (dot(a, b) < 0.f) return kPi - 2.f * std::asin(std::min(1.f, length(a + b) * 0.5f));
  return 2.f * std::asin(std::min(1.f, length(a - b) * 0.5f));
}

bool usable_normal(Vec3 n) {
  float l2 = length_squared(n);
  return std::isfinite(l2) && l2 > 0.f;
}

}  // namespace

void validate_mesh(const MeshData& mesh, const FileLoc& loc) {
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (!is_finite(mesh.positions[i]))
      throw SceneError(loc, "vertex " + std::to_string(i) + " has a NaN or infinite coordinate");
  for (size_t i = 0; i < mesh.uvs.size(); ++i)
    if (!finite2(mesh.uvs[i]))
      throw SceneError(loc, "texture coordinate of vertex " + std::to_string(i) +
                                " is NaN or infinite");
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
    throw SceneError(loc, "normal count differs from vertex count");
  if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
    throw SceneError(loc, "texture coordinate count differs from vertex count");
  if (mesh.indices.size() % 3 != 0) throw SceneError(loc, "index count is not a multiple of 3");
  const size_t n = mesh.positions.size();
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= n)
      throw SceneError(loc, "triangle " + std::to_string(i / 3) + " references vertex " +
                                std::to_string(mesh.indices[i]) + ", but the mesh has " +
                                std::to_string(n) + " vertices");
}

size_t drop_degenerate_triangles(MeshData& mesh) {
  size_t kept = 0, n = mesh.num_triangles();
  auto& idx = mesh.indices;
  for (size_t t = 0; t < n; ++t) {
    uint32_t a = idx[3 * t], b = idx[3 * t + 1], c = idx[3 * t + 2];
    Vec3 p0 = mesh.positions[a], p1 = mesh.positions[b], p2 = mesh.positions[c];
    // Same test the shape's normalize(cross(..)) relies on: a triangle whose normal cannot be
    // normalized in float can neither be hit reliably nor shaded.
    if (!usable_normal(cross(p1 - p0, p2 - p0))) continue;
    idx[3 * kept] = a;
    idx[3 * kept + 1] = b;
    idx[3 * kept + 2] = c;
    ++kept;
  }
  idx.resize(3 * kept);
  return n - kept;
}

void compute_smooth_normals(MeshData& mesh, const std::vector<bool>& only_missing) {
  const size_t nv = mesh.positions.size();
  const bool all = only_missing.empty();
  std::vector<Vec3> acc(nv, Vec3(0.f));
  for (size_t t = 0; t < mesh.num_triangles(); ++t) {
    const uint32_t* tri = &mesh.indices[3 * t];
    Vec3 n = cross(mesh.positions[tri[1]] - mesh.positions[tri[0]],
                   mesh.positions[tri[2]] - mesh.positions[tri[0]]);
    if (!usable_normal(n)) continue;
    n = normalize(n);
    for (int k = 0; k < 3; ++k) {
      uint32_t v = tri[k];
      if (!all && !only_missing[v]) continue;
      Vec3 e1 = mesh.positions[tri[(k + 1) % 3]] - mesh.positions[v];
      Vec3 e2 = mesh.positions[tri[(k + 2) % 3]] - mesh.positions[v];
      if (!usable_normal(e1) || !usable_normal(e2)) continue;
      // Weighting by the corner angle makes the result independent of how a flat region is
      // tessellated (Thuermer & Wuethrich, JGT 1998); Mitsuba does the same.
      acc[v] += n * unit_angle(normalize(e1), normalize(e2));
    }
  }
  if (all) mesh.normals.assign(nv, Vec3(0.f, 0.f, 1.f));
  mesh.normals.resize(nv, Vec3(0.f, 0.f, 1.f));
  for (size_t v = 0; v < nv; ++v) {
    if (!all && !only_missing[v]) continue;
    mesh.normals[v] = usable_normal(acc[v]) ? normalize(acc[v]) : Vec3(0.f, 0.f, 1.f);
  }
}

void normalize_vertex_normals(MeshData& mesh) {
  std::vector<bool> missing(mesh.normals.size(), false);
  bool any_missing = false;
  for (size_t v = 0; v < mesh.normals.size(); ++v) {
    Vec3 n = mesh.normals[v];
    if (usable_normal(n)) {
      mesh.normals[v] = normalize(n);
    } else {
      missing[v] = true;
      any_missing = true;
    }
  }
  if (any_missing) compute_smooth_normals(mesh, missing);
}

void finish_mesh(MeshData& mesh, bool face_normals, const FileLoc& loc, MeshLoadStats* stats) {
  validate_mesh(mesh, loc);
  size_t dropped = drop_degenerate_triangles(mesh);
  if (stats) stats->degenerate_dropped += dropped;
  if (face_normals)
    mesh.normals.clear();
  else if (mesh.normals.empty())
    compute_smooth_normals(mesh);
  else
    normalize_vertex_normals(mesh);
}

}  // namespace tessera

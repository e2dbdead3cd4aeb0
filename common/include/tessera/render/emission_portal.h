// Where light subpaths from distant lights (environments, the sun and sky, directional lights)
// start, for the bidirectional integrators (bdpt.h).
//
// Where light subpaths from distant lights (environments, the sun and sky, directional lights)
// start, for the bidirectional integrators (bdpt.h).
//
// A distant light's rays would otherwise start on a disk covering the whole scene, so in a room
// lit through a window almost every one lands on the outside of the building. The portal is the
// set of places through which the camera's own paths leave the scene for the sky: a pilot of
// camera paths (BSDF sampling only, a fixed seed) records the point of every path's last
// surface before it escapes; the points are grouped by the cells of a coarse grid over the scene,
// and each group's bounding box (padded, clipped to the scene's bounds) is one box of the portal.
//
// A ray along a direction of travel starts, with probability kDiskShare, on the disk of the
// scene's bounding sphere facing it (as without a portal), and otherwise on the boxes'
// silhouettes: a (box, front face) in proportion to its projected area, a point uniformly on it.
// Densities are per unit area perpendicular to the direction, as the disk's are: a line has
//   kDiskShare / (pi R^2) + (1 - kDiskShare) * (boxes it crosses) / (projected area of all boxes)
// (the first term for every line through the scene's bounds). The disk's share keeps every line
// reachable, so light tracing alone stays unbiased wherever the pilot did not look.
//
// The portal is a function of the scene only (geometry, camera, film size), computed once by
// Scene::finalize for the bidirectional integrators, so every worker finds the same one.
// Hot path (sample, pdf): no throwing, no allocation.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/vec.h"

#include <array>
#include <cstdint>

namespace tessera {

class Scene;

class EmissionPortal {
 public:
  static constexpr int kMaxBoxes = 64;
  static constexpr float kDiskShare = 0.2f;
  static constexpr uint32_t kPilotPaths = 4096;

  /// True once found for a scene (else distant lights start on their own disk).
  bool active() const { return radius_ > 0.f; }
  int box_count() const { return count_; }
  const Bounds3& box(int i) const { return boxes_[size_t(i)]; }
  /// How many escapes of the pilot's camera paths the boxes were made from.
  uint32_t escapes() const { return escapes_; }

  /// A ray along the unit direction of travel `dir` through a point of the portal's silhouette,
  /// from `u`: `p`, where it starts, lies upstream of the scene's bounding sphere; `pdf` is the
  /// density of its line per unit area perpendicular to `dir`. False when it has no density.
  bool sample(Vec3 dir, Vec2 u, Vec3& p, float& pdf) const;
  /// The density sample() gives the line through `p` along the unit `dir` (0 when it misses the
  /// scene's bounding sphere and every box).
  float pdf(Vec3 p, Vec3 dir) const;

  /// Adds a box (ignored past kMaxBoxes or when empty); boxes must lie inside the scene sphere.
  void add_box(const Bounds3& b);
  void set_escapes(uint32_t n) { escapes_ = n; }
  /// The scene's bounding sphere: the disk's, and what sample()'s starting points stay outside of.
  void set_scene_sphere(Vec3 center, float radius) {
    center_ = center;
    radius_ = radius;
  }

 private:
  float projected_area(Vec3 dir) const;
  Vec3 box_point(Vec3 dir, Vec2 u) const;
  std::array<Bounds3, kMaxBoxes> boxes_{};
  int count_ = 0;
  // Per axis k, the boxes' face areas perpendicular to it: the projected area along dir is
  // sum_k |dir_k| face_area_sum_[k].
  std::array<float, 3> face_area_sum_{};
  uint32_t escapes_ = 0;
  Vec3 center_;
  float radius_ = 0.f;
};

/// The portal of `scene` (its camera, geometry and BSDFs), or an empty one when its pilot paths
/// escape too rarely to say where the light gets in.
EmissionPortal find_emission_portal(const Scene& scene);

}  // namespace tessera

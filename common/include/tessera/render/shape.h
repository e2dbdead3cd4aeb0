// Shapes: world-space geometry the accelerator intersects, with what the integrator needs at a hit.
//
// Two kinds reach the accelerator: triangle meshes (all of obj/ply/serialized/rectangle/cube/disk
// end up as these) and analytic spheres. Both are stored in WORLD space (transforms applied once at
// load time, so most rays are never transformed), except members of shapegroups and moving shapes,
// which keep object space and are placed by instances (render/instance.h).
// Orientation: the geometric normal of a triangle (v0,v1,v2) is normalize(cross(v1-v0, v2-v0)),
// negated when `flip_normals` is set; a sphere's faces outward (inward when flipped).
// Area sampling returns a density with respect to AREA on the shape.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/hit.h"
#include "tessera/core/ray.h"
#include "tessera/core/distribution.h"
#include "tessera/core/sampling.h"
#include "tessera/core/vec.h"
#include "tessera/render/interaction.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace tessera {

class AnimatedTransform;
class Bsdf;
class Light;
class Medium;

/// Triangle mesh data as loaders produce it (object space) and as shapes keep it (world space).
struct MeshData {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;   // per vertex; empty when the mesh has none (or face normals wanted)
  std::vector<Vec2> uvs;       // per vertex; empty when none
  std::vector<uint32_t> indices;  // three per triangle
  size_t num_triangles() const { return indices.size() / 3; }
};

class Shape {
 public:
  enum class Kind { Mesh, Sphere };
  virtual ~Shape() = default;
  virtual Kind kind() const = 0;
  virtual uint32_t num_primitives() const = 0;
  virtual Bounds3 bounds() const = 0;
  virtual float area() const = 0;
  /// Uniformly (by area) samples a point; returns its position, geometric normal and area pdf.
  virtual void sample_area(Vec2 u, Vec3& p, Vec3& n, float& pdf_area) const = 0;
  /// Completes `si` for a hit on local primitive `prim` found by the accelerator.
  virtual void fill_interaction(const Ray& ray, const Hit& hit, uint32_t prim,
                                SurfaceInteraction& si) const = 0;

  const Bsdf* bsdf = nullptr;
  const Light* light = nullptr;  // area light attached to this shape, if any
  // Per-primitive lights that replace `light` for sampling and MIS (an emissive mesh split into
  // triangle lights by Scene::finalize); empty when `light` stays whole.
  std::vector<const Light*> prim_lights;
  /// The light a hit on primitive `prim` sees (SurfaceInteraction::area_light()).
  const Light* area_light(uint32_t prim) const { return prim < prim_lights.size() ? prim_lights[prim] : light; }
  // Participating media on either side (null: vacuum); see medium_after() in scene.h.
  const Medium* interior = nullptr;
  const Medium* exterior = nullptr;
  bool medium_interface = false;  // the scene gave this shape an interior or exterior medium
  // Set for a moving shape (motion blur): its geometry is then in OBJECT space and this places it
  // in the world at each time (render/instance.h). Null: world-space geometry, as everywhere else.
  std::shared_ptr<const AnimatedTransform> motion;
  // Set for a member of a shapegroup: its geometry is in the group's OBJECT space and the scene's
  // instances of the group place it (render/instance.h).
  static constexpr uint32_t kNoGroup = 0xFFFFFFFFu;
  uint32_t group = kNoGroup;
  /// True when the geometry is in object space (a group member or a moving shape).
  bool is_placed() const { return motion != nullptr || group != kNoGroup; }
  std::string name;              // for messages: "shape 'obj' (models/Mesh001.obj)"
};

class TriangleMeshShape final : public Shape {
 public:
  /// `mesh` is in world space already. `face_normals` ignores vertex normals.
  TriangleMeshShape(std::shared_ptr<const MeshData> mesh, bool flip_normals, bool face_normals);
  Kind kind() const override { return Kind::Mesh; }
  uint32_t num_primitives() const override { return uint32_t(mesh_->num_triangles()); }
  Bounds3 bounds() const override;
  float area() const override { return area_; }
  void sample_area(Vec2 u, Vec3& p, Vec3& n, float& pdf_area) const override;
  void fill_interaction(const Ray& ray, const Hit& hit, uint32_t prim,
                        SurfaceInteraction& si) const override;
  const MeshData& mesh() const { return *mesh_; }
  bool flip_normals() const { return flip_; }

 private:
  std::shared_ptr<const MeshData> mesh_;
  bool flip_, face_normals_;
  float area_ = 0.f;
  Distribution1D tri_area_;
};

class SphereShape final : public Shape {
 public:
  SphereShape(Vec3 center, float radius, bool flip_normals);
  Kind kind() const override { return Kind::Sphere; }
  uint32_t num_primitives() const override { return 1; }
  Bounds3 bounds() const override;
  float area() const override { return 4.f * kPi * radius_ * radius_; }
  void sample_area(Vec2 u, Vec3& p, Vec3& n, float& pdf_area) const override;
  void fill_interaction(const Ray& ray, const Hit& hit, uint32_t prim,
                        SurfaceInteraction& si) const override;
  Vec3 center() const { return center_; }
  float radius() const { return radius_; }
  /// Projects `p` (near the surface) onto the sphere and bounds the rounding error of the result
  /// per axis in `p_error` (pbrt-v4's gamma(5) |p - c|, plus the addition of the centre). `unit`,
  /// when given, gets the unit direction from the centre towards `p` that the projection used.
  Vec3 reproject(Vec3 p, Vec3& p_error, Vec3* unit = nullptr) const;

 private:
  Vec3 center_;
  float radius_;
  bool flip_;
};

}  // namespace tessera

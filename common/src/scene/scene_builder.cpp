// Description -> Scene: shapes (to world space, with BSDF and area light), shapegroups (their
// members once, in the group's object space) and their instances (render/instance.h), stand-alone
// emitters; then the sensor, the report of what was not consumed, finalize().
//
// Orientation under mirroring transforms follows Mitsuba: a mesh's geometric normal comes from its
// world-space winding (so a mirrored mesh turns inside out, as in Mitsuba), while the analytic
// `rectangle` and `disk` keep the normal to_world gives their +z axis (inverse transpose), so
// their triangles are re-wound when to_world swaps handedness.
// A sphere needs a to_world that scales uniformly; anything else is reported as unsupported and
// the sphere keeps the volume-preserving radius r * cbrt(|det|).
#include "tessera/scene/load_context.h"

#include "scene/builder_internal.h"

#include <cmath>
#include <map>

namespace tessera {

namespace detail {

namespace {

std::shared_ptr<const MeshData> to_world_mesh(const std::shared_ptr<const MeshData>& mesh, const Transform& xf,
                                              bool rewind, const SceneNode& node) {
  if (xf.is_identity()) return mesh;
  MeshData w;
  w.positions.reserve(mesh->positions.size());
  for (Vec3 p : mesh->positions) {
    Vec3 q = xf.apply_point(p);
    if (!is_finite(q)) throw SceneError(node.loc_of("to_world"), "to_world maps a vertex to a non-finite position");
    w.positions.push_back(q);
  }
  w.normals.reserve(mesh->normals.size());
  for (Vec3 n : mesh->normals) {
    Vec3 m = xf.apply_normal(n);
    float len = length(m);
    w.normals.push_back(len > 0.f && std::isfinite(len) ? m / len : Vec3(0.f));
  }
  w.uvs = mesh->uvs;
  w.indices = mesh->indices;
  if (rewind)
    for (size_t t = 0; t + 2 < w.indices.size(); t += 3) std::swap(w.indices[t + 1], w.indices[t + 2]);
  return std::make_shared<const MeshData>(std::move(w));
}

/// World-space sphere from an object-space one.
void sphere_to_world(BuildState& st, const SceneNode& node, const Transform& xf, const ShapeGeometry& g,
                     Vec3& center, float& radius) {
  center = xf.apply_point(g.center);
  const auto& m = xf.matrix().m;
  double col[3][3], len[3];
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) col[c][r] = m[r][c];
    len[c] = std::sqrt(col[c][0] * col[c][0] + col[c][1] * col[c][1] + col[c][2] * col[c][2]);
  }
  double s = (len[0] + len[1] + len[2]) / 3.0;
  bool uniform = m[3][0] == 0 && m[3][1] == 0 && m[3][2] == 0 && m[3][3] == 1;
  for (int a = 0; a < 3 && uniform; ++a) {
    uniform = std::abs(len[a] - s) <= 1e-4 * s;
    for (int b = a + 1; b < 3 && uniform; ++b) {
      double d = col[a][0] * col[b][0] + col[a][1] * col[b][1] + col[a][2] * col[b][2];
      uniform = std::abs(d) <= 1e-4 * s * s;
    }
  }
  if (!uniform) {
    const auto& a = m;
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    s = std::cbrt(std::abs(det));
    st.ctx.unsupported(node.loc_of("to_world"),
                       "non-uniform scale, shear or projection in to_world of " + node.describe(),
                       "a sphere of the same volume (radius scaled by cbrt|det|)");
  }
  radius = float(double(g.radius) * s);
  if (!is_finite(center) || !(radius > 0.f) || !std::isfinite(radius))
    throw SceneError(node.loc_of("to_world"), "to_world makes the sphere degenerate or non-finite");
}

class ShapeBuilder {
 public:
  explicit ShapeBuilder(BuildState& st) : st_(st) {}

  /// `group`: the shapegroup the shape is a member of (Shape::kNoGroup for a world-space shape).
  void build(const std::shared_ptr<SceneNode>& node_ptr, uint32_t group) {
    const SceneNode& node = *node_ptr;
    if (node.type == "instance") {
      build_instance(node);
      return;
    }
    ShapeFactory factory = find_shape_factory(node.type);
    if (!factory) return;  // reported by the final walk: skipped
    node.used = true;
    auto cached = geometry_.find(&node);
    if (cached == geometry_.end()) cached = geometry_.emplace(&node, make_geometry(node, factory)).first;
    const ShapeGeometry& g = cached->second;

    // Motion blur (docs/scene-support.md): an <animation> to_world or a sphere's center_close make
    // the shape move over the shutter; it then keeps object-space geometry and `motion`. Without a
    // shutter interval everything is placed at shutter_open. A shapegroup's members are shared by
    // all its instances, so they cannot move on their own (an instance can).
    AnimatedTransform anim = placement(node, g);
    if (group != Shape::kNoGroup && !anim.is_static() && st_.scene.has_shutter_interval()) {
      st_.ctx.unsupported(node.loc_of("to_world"), "a moving " + node.describe() + " inside a shapegroup",
                          "its placement at shutter_open (animate the instance instead)");
      anim = AnimatedTransform(anim.at(st_.scene.shutter_open));
    }
    const bool moving = !anim.is_static() && st_.scene.has_shutter_interval();
    const Transform xf = anim.is_static() || !moving ? anim.at(st_.scene.shutter_open) : Transform();
    auto bsdfs = node.children_with_tag("bsdf");
    if (bsdfs.size() > 1) throw SceneError(bsdfs[1]->loc, node.describe() + " has more than one BSDF");
    const ShapeMedia media = build_shape_media(st_, node);
    const Bsdf* bsdf = bsdfs.empty() && media.any ? st_.ctx.null_bsdf() : st_.ctx.bsdf(bsdfs.empty() ? nullptr : bsdfs[0]);

    std::unique_ptr<Shape> shape;
    if (g.is_sphere && moving) {
      shape = std::make_unique<SphereShape>(g.center, g.radius, g.flip_normals);
    } else if (g.is_sphere) {
      Vec3 center;
      float radius = 1.f;
      sphere_to_world(st_, node, xf, g, center, radius);
      shape = std::make_unique<SphereShape>(center, radius, g.flip_normals);
    } else {
      if (!g.mesh) throw SceneError(node.loc, node.describe() + ": the shape plugin returned no geometry");
      if (g.mesh->num_triangles() == 0) {
        st_.ctx.warn(node.loc, node.describe() + " has no triangles; skipped");
        return;
      }
      bool analytic_normal = node.type == "rectangle" || node.type == "disk";
      // A moving mesh's normals come from the transform (as rectangle/disk's do); a mirroring
      // animation re-winds the others so they turn inside out as their static form does.
      auto mesh = moving ? to_world_mesh(g.mesh, Transform(), false, node) : to_world_mesh(g.mesh, xf, analytic_normal && xf.swaps_handedness(), node);
      if (moving && !analytic_normal && anim.at(st_.scene.shutter_open).swaps_handedness()) {
        auto rewound = std::make_shared<MeshData>(*mesh);
        for (size_t t = 0; t + 2 < rewound->indices.size(); t += 3) std::swap(rewound->indices[t + 1], rewound->indices[t + 2]);
        mesh = rewound;
      }
      shape = std::make_unique<TriangleMeshShape>(std::move(mesh), g.flip_normals, g.face_normals);
    }
    shape->bsdf = bsdf;
    shape->interior = media.interior;
    shape->exterior = media.exterior;
    shape->medium_interface = media.any;
    shape->name = node.describe();
    const Property* file = node.peek("filename");
    if (file && file->type == PropType::String) shape->name += " (" + file->s + ")";
    if (moving) shape->motion = std::make_shared<const AnimatedTransform>(std::move(anim));
    shape->group = group;
    attach_emitter(node, *shape, group != Shape::kNoGroup, moving);
    st_.scene.shapes.push_back(std::move(shape));
  }

  // A mesh file's error names the mesh file and line; say which scene element asked for it too.
  ShapeGeometry make_geometry(const SceneNode& node, ShapeFactory factory) {
    try {
      return factory(node, st_.ctx);
    } catch (const UnsupportedError&) {
      throw;
    } catch (const SceneError& e) {
      if (e.loc().file == node.loc.file) throw;
      if (e.loc().file.empty()) throw SceneError(node.loc, node.describe() + ": " + e.what());
      throw SceneError(e.loc(), std::string(e.what()).substr(e.loc().str().size() + 2) + " (loading " +
                                    node.describe() + " at " + node.loc.str() + ")");
    }
  }

 private:
  BuildState& st_;
  std::map<const SceneNode*, ShapeGeometry> geometry_;  // a mesh file is loaded once
  std::map<const SceneNode*, uint32_t> groups_;         // shapegroup -> its index (Shape::group)

  /// world_from_object over time (a group member's: group_from_object): to_world * (sphere) centre motion.
  AnimatedTransform placement(const SceneNode& node, const ShapeGeometry& g) {
    const float t0 = st_.scene.shutter_open, t1 = st_.scene.shutter_close;
    AnimatedTransform anim = node.get_animated_transform("to_world", Transform());
    if (anim.is_static()) anim = AnimatedTransform(anim.at(t0));
    // Tessera extension: a sphere's centre at shutter close (docs/plugins.md), linear in between.
    const Property* cc = g.is_sphere ? node.find("center_close") : nullptr;
    if (!cc) return anim;
    const Vec3 c1 = node.get_vector("center_close", g.center);
    if (!is_finite(c1)) throw SceneError(cc->loc, "center_close must be finite");
    if (!(t1 > t0) || c1 == g.center) return anim;
    if (!anim.is_static()) {
      st_.ctx.unsupported(cc->loc, "center_close on a sphere whose to_world is animated", "the sphere stays at 'center'");
      return anim;
    }
    AnimatedTransform slide({{t0, Transform()}, {t1, Transform::translate(c1 - g.center)}});
    return slide.composed(anim.at(t0), Transform());
  }

  void attach_emitter(const SceneNode& node, Shape& shape, bool in_group, bool moving) {
    auto emitters = node.children_with_tag("emitter");
    if (emitters.size() > 1) throw SceneError(emitters[1]->loc, node.describe() + " has more than one emitter");
    if (emitters.empty()) return;
    const SceneNode& e = *emitters[0];
    if (e.type != "area") {
      st_.ctx.unsupported(e.loc, e.describe() + " nested in a shape (only 'area' emitters attach to shapes)",
                          "dropped");
      st_.reported.insert(&e);
      return;
    }
    if (in_group) {
      if (st_.reported.insert(&e).second)
        st_.ctx.unsupported(e.loc, "area emitter inside a shapegroup (instanced emitters)", "dropped");
      return;
    }
    if (moving) {
      st_.ctx.unsupported(e.loc, "area emitter on a moving shape (" + node.describe() + ")", "dropped");
      st_.reported.insert(&e);
      return;
    }
    e.used = true;
    std::unique_ptr<Light> light = make_area_light(e, st_.ctx, shape);
    if (!light) return;
    shape.light = light.get();
    st_.scene.lights.push_back(std::move(light));
  }

  void build_instance(const SceneNode& node) {
    node.used = true;
    std::shared_ptr<SceneNode> group;
    for (const auto& c : node.children)
      if (c->tag == "shape" && c->type == "shapegroup") {
        if (group) throw SceneError(c->loc, "an instance refers to exactly one shapegroup");
        group = c;
      }
    if (!group) throw SceneError(node.loc, "an instance needs a <ref> to a shapegroup");
    group->used = true;
    const auto [it, first_use] = groups_.emplace(group.get(), uint32_t(groups_.size()));
    if (first_use) {
      for (const auto& child : group->children) {
        if (child->tag != "shape") continue;  // anything else is reported by the final walk
        if (child->type == "shapegroup" || child->type == "instance")
          throw SceneError(child->loc, "shapegroups cannot contain " + child->type + "s");
        build(child, it->second);
      }
    }
    AnimatedTransform xf = node.get_animated_transform("to_world", Transform());
    if (xf.is_static() || !st_.scene.has_shutter_interval()) xf = AnimatedTransform(xf.at(st_.scene.shutter_open));
    st_.scene.instances.push_back({it->second, std::move(xf)});
  }
};

}  // namespace

void build_shapes(BuildState& st) {
  ShapeBuilder builder(st);
  for (const auto& c : st.desc.root->children)
    if (c->tag == "shape" && c->type != "shapegroup") builder.build(c, Shape::kNoGroup);
}

void build_emitters(BuildState& st) {
  for (const auto& c : st.desc.root->children) {
    if (c->tag != "emitter") continue;
    if (c->type == "area") throw SceneError(c->loc, "an 'area' emitter must be nested in a <shape>");
    LightFactory factory = find_light_factory(c->type);
    if (!factory) continue;  // reported by the final walk: dropped
    c->used = true;
    if (std::unique_ptr<Light> light = factory(*c, st.ctx)) st.scene.lights.push_back(std::move(light));
  }
}

namespace {

void reset_used(const SceneNode& node, std::set<const SceneNode*>& seen) {
  if (!seen.insert(&node).second) return;
  node.used = false;
  for (const Property& p : node.props) p.used = false;
  for (const auto& c : node.children) reset_used(*c, seen);
}

}  // namespace

}  // namespace detail

LoadResult load_scene(const SceneDesc& desc, const LoadOptions& options) {
  if (!desc.root) throw SceneError("empty scene description");
  {
    // A description may be loaded more than once (e.g. with other overrides): start clean.
    std::set<const SceneNode*> seen;
    detail::reset_used(*desc.root, seen);
  }
  auto scene = std::make_unique<Scene>();
  LoadContext ctx(desc, options, *scene);
  detail::BuildState st{ctx, desc, *scene, {}, {}};
  desc.root->used = true;
  detail::build_integrator(st);
  detail::read_shutter(st);
  detail::build_shapes(st);
  detail::build_emitters(st);
  detail::build_sensor(st);
  if (st.spp_budget > 0 && st.spp_budget != scene->sampler.sample_count) {
    ctx.note(desc.root->loc, "the integrator's budget of " + std::to_string(st.spp_budget) +
                                 " samples per pixel replaces the sampler's " + std::to_string(scene->sampler.sample_count));
    scene->sampler.sample_count = st.spp_budget;
  }
  detail::finish_media(st);
  detail::check_integrator_sensor(st);
  detail::report_unsupported(st);
  if (!options.allow_unsupported && !ctx.unsupported_items().empty())
    throw UnsupportedError(ctx.unsupported_items());
  scene->finalize();
  LoadResult result;
  result.scene = std::move(scene);
  result.messages = ctx.messages();
  result.files = ctx.resolved_files();
  if (options.allow_unsupported) result.unsupported = ctx.unsupported_items();
  return result;
}

}  // namespace tessera

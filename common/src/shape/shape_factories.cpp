// Shape plugins: Mitsuba parameters -> object-space geometry. `to_world`, the BSDF and any area
// light are the builder's business; a factory only loads (once, through the context's mesh cache)
// and reads the parameters that change the geometry.
#include "tessera/scene/load_context.h"
#include "tessera/shape/mesh_io.h"

#include <cmath>
#include <string>

namespace tessera {

namespace {

std::string required_filename(const SceneNode& node) {
  std::string file = node.get_string("filename", "");
  if (file.empty()) throw SceneError(node.loc, node.describe() + " needs a 'filename'");
  return file;
}

/// Loads through the cache; the degenerate-triangle warning is emitted once, when the file is
/// actually read.
std::shared_ptr<const MeshData> cached(LoadContext& ctx, const std::string& key, const FileLoc& loc,
                                       const std::string& what,
                                       const std::function<MeshData(MeshLoadStats*)>& load) {
  return ctx.cached_mesh(key, [&] {
    MeshLoadStats stats;
    MeshData mesh = load(&stats);
    if (stats.degenerate_dropped > 0)
      ctx.warn(loc, what + ": dropped " + std::to_string(stats.degenerate_dropped) +
                        " zero-area triangle(s)");
    return mesh;
  });
}

ShapeGeometry mesh_geometry(std::shared_ptr<const MeshData> mesh, bool face_normals, bool flip) {
  ShapeGeometry g;
  g.mesh = std::move(mesh);
  g.face_normals = face_normals;
  g.flip_normals = flip;
  return g;
}

ShapeGeometry analytic(const SceneNode& node, LoadContext& ctx, const char* name,
                       MeshData (*make)()) {
  bool flip = node.get_bool("flip_normals", false);
  auto mesh = ctx.cached_mesh(std::string("analytic:") + name, [make] { return make(); });
  return mesh_geometry(std::move(mesh), false, flip);
}

}  // namespace

ShapeGeometry make_obj(const SceneNode& node, LoadContext& ctx) {
  std::string file = required_filename(node);
  FileLoc loc = node.loc_of("filename");
  std::string path = ctx.resolve_path(file, loc);
  ObjOptions opt;
  opt.face_normals = node.get_bool("face_normals", false);
  opt.flip_tex_coords = node.get_bool("flip_tex_coords", true);
  bool flip = node.get_bool("flip_normals", false);
  // flip_normals is applied by the shape, so it does not split the cache.
  std::string key = "obj|" + path + "|fn=" + std::to_string(opt.face_normals) +
                    "|ftc=" + std::to_string(opt.flip_tex_coords);
  auto mesh = cached(ctx, key, loc, file, [&](MeshLoadStats* s) { return load_obj(path, opt, s); });
  return mesh_geometry(std::move(mesh), opt.face_normals, flip);
}

ShapeGeometry make_ply(const SceneNode& node, LoadContext& ctx) {
  std::string file = required_filename(node);
  FileLoc loc = node.loc_of("filename");
  std::string path = ctx.resolve_path(file, loc);
  bool fn = node.get_bool("face_normals", false);
  bool flip = node.get_bool("flip_normals", false);
  std::string key = "ply|" + path + "|fn=" + std::to_string(fn);
  auto mesh = cached(ctx, key, loc, file, [&](MeshLoadStats* s) { return load_ply(path, fn, s); });
  return mesh_geometry(std::move(mesh), fn, flip);
}

ShapeGeometry make_serialized(const SceneNode& node, LoadContext& ctx) {
  std::string file = required_filename(node);
  FileLoc loc = node.loc_of("filename");
  std::string path = ctx.resolve_path(file, loc);
  int64_t index = node.get_int("shape_index", 0);
  if (index < 0 || index > 0x7FFFFFFF)
    throw SceneError(node.loc_of("shape_index"),
                     "shape_index must be non-negative, got " + std::to_string(index));
  bool fn = node.get_bool("face_normals", false);
  bool flip = node.get_bool("flip_normals", false);
  std::string key = "serialized|" + path + "|" + std::to_string(index) + "|fn=" + std::to_string(fn);
  std::string what = file + " (shape " + std::to_string(index) + ")";
  auto mesh = cached(ctx, key, loc, what, [&](MeshLoadStats* s) {
    return load_serialized(path, int(index), fn, s);
  });
  return mesh_geometry(std::move(mesh), fn, flip);
}

ShapeGeometry make_rectangle(const SceneNode& node, LoadContext& ctx) {
  return analytic(node, ctx, "rectangle", [] { return make_rectangle_mesh(); });
}

ShapeGeometry make_cube(const SceneNode& node, LoadContext& ctx) {
  return analytic(node, ctx, "cube", [] { return make_cube_mesh(); });
}

ShapeGeometry make_disk(const SceneNode& node, LoadContext& ctx) {
  return analytic(node, ctx, "disk", [] { return make_disk_mesh(); });
}

ShapeGeometry make_sphere(const SceneNode& node, LoadContext& ctx) {
  ShapeGeometry g;
  g.is_sphere = true;
  g.center = node.get_vector("center", Vec3(0.f));
  g.radius = node.get_float("radius", 1.f);
  g.flip_normals = node.get_bool("flip_normals", false);
  if (!(g.radius > 0.f) || !std::isfinite(g.radius))
    throw SceneError(node.loc_of("radius"),
                     "sphere radius must be positive and finite, got " + std::to_string(g.radius));
  if (!is_finite(g.center)) throw SceneError(node.loc_of("center"), "sphere center is not finite");
  return g;
}

}  // namespace tessera

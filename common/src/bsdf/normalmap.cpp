// Mitsuba 3's `normalmap`: an RGB texture gives the shading normal 2 rgb - 1 in the tangent
// space (dp/du, bitangent, shading normal); the nested BSDF is evaluated in the frame built on it.
//
// The texture is evaluated as loaded. Mitsuba 3 applies no decoding of its own either: its
// documentation asks for `raw` bitmaps, and an sRGB-decoded one gives the same bent normals in
// both renderers.
#include "perturbed_frame.h"
#include "tessera/bsdf/bumpmap.h"

#include "tessera/core/check.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

/// Normals are stored as 2 rgb - 1 so that an ordinary [0, 1] image can hold them (Mitsuba 3).
struct NormalMapFrame {
  std::shared_ptr<const Texture> normals;
  Frame operator()(const SurfaceInteraction& si) const {
    Rgb c = normals->eval(si);
    Vec3 n(2.f * c.r - 1.f, 2.f * c.g - 1.f, 2.f * c.b - 1.f);
    return normal_mapped_frame(si, n);
  }
};

}  // namespace

std::shared_ptr<Bsdf> make_normalmap_bsdf(const Bsdf* nested, std::shared_ptr<const Texture> normals) {
  TESSERA_CHECK(nested != nullptr && normals != nullptr);
  return std::make_shared<PerturbedBsdf<NormalMapFrame>>(nested, NormalMapFrame{std::move(normals)});
}

std::shared_ptr<Bsdf> make_normalmap(const SceneNode& node, LoadContext& ctx) {
  // Mitsuba 3: the texture must be named `normalmap`; the one nested BSDF may have any name.
  auto nested = node.children_with_tag("bsdf");
  if (nested.size() != 1)
    throw SceneError(node.loc, node.describe() + ": expected one nested BSDF, found " + std::to_string(nested.size()));
  if (!node.named_child("normalmap"))
    throw SceneError(node.loc, node.describe() + " needs a texture named 'normalmap'");
  std::shared_ptr<Texture> normals = ctx.texture(node, "normalmap", Rgb(0.5f, 0.5f, 1.f));
  return make_normalmap_bsdf(ctx.bsdf(nested[0]), std::move(normals));
}

}  // namespace tessera

// Mitsuba 0.6's `bumpmap`: a height-field texture tilts the shading frame of a nested BSDF
// (Blinn 1978). Only the height's derivatives matter (Texture::eval_1_gradient), so a constant
// offset changes nothing; a `scale` texture around the map sets the strength.
#include "perturbed_frame.h"
#include "tessera/bsdf/bumpmap.h"

#include "tessera/core/check.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

/// Shared ownership: the loader's texture cache may hand the same height map to other BSDFs.
struct BumpFrame {
  std::shared_ptr<const Texture> height;
  Frame operator()(const SurfaceInteraction& si) const { return bumped_frame(si, height->eval_1_gradient(si)); }
};

/// The i-th child of `node` as a texture. Through ctx.texture when its name finds it (shared
/// per node); an unnamed texture beside an unnamed BSDF shares the empty name, so it is built
/// directly. An unknown type is reported by the loader's final walk; a flat map stands in.
std::shared_ptr<Texture> nested_texture(const SceneNode& node, size_t i, LoadContext& ctx) {
  const auto& child = node.children[i];
  if (node.named_child(node.child_names[i]) == child) return ctx.texture(node, node.child_names[i], Rgb(0.f));
  child->used = true;
  if (TextureFactory f = find_texture_factory(child->type)) {
    if (auto tex = f(*child, ctx)) return tex;
    throw SceneError(child->loc, child->describe() + ": the texture plugin returned nothing");
  }
  return std::make_shared<ConstantTexture>(Rgb(0.f));
}

}  // namespace

std::shared_ptr<Bsdf> make_bumpmap_bsdf(const Bsdf* nested, std::shared_ptr<const Texture> height) {
  TESSERA_CHECK(nested != nullptr && height != nullptr);
  return std::make_shared<PerturbedBsdf<BumpFrame>>(nested, BumpFrame{std::move(height)});
}

std::shared_ptr<Bsdf> make_bumpmap(const SceneNode& node, LoadContext& ctx) {
  // Mitsuba 0.6 takes one nested BSDF and one texture, whatever their names (scenes use "map").
  std::shared_ptr<SceneNode> nested;
  std::shared_ptr<Texture> height;
  for (size_t i = 0; i < node.children.size() && i < node.child_names.size(); ++i) {
    const auto& child = node.children[i];
    if (child->tag == "bsdf") {
      if (nested) throw SceneError(child->loc, node.describe() + " takes a single nested BSDF");
      nested = child;
    } else if (child->tag == "texture") {
      if (height) throw SceneError(child->loc, node.describe() + " takes a single height texture");
      height = nested_texture(node, i, ctx);
    }
  }
  if (!nested) throw SceneError(node.loc, node.describe() + " needs a nested BSDF");
  if (!height) throw SceneError(node.loc, node.describe() + " needs a height texture");
  return make_bumpmap_bsdf(ctx.bsdf(nested), std::move(height));
}

}  // namespace tessera

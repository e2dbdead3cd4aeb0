// Mitsuba 0.6's `bumpmap`: a height-field texture tilts the shading frame of a nested BSDF
// (Blinn 1978). Only the height's derivatives matter (Texture::eval_1_gradient), so a constant
// offset changes nothing; a `scale` texture around the map sets the strength.
#include "perturbed_frame.h"
#include "tessera/bsdf/bumpmap.h"

#include "tessera/core/check.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

class BumpMapBsdf final : public Bsdf {
 public:
  BumpMapBsdf(const Bsdf* nested, std::shared_ptr<const Texture> height)
      : nested_(nested), height_(std::move(height)) {
    TESSERA_CHECK(nested_ != nullptr && height_ != nullptr);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    return query(si).eval(*nested_, wo, wi);
  }
  float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    return query(si).pdf(*nested_, wo, wi);
  }
  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    return query(si).sample(*nested_, wo, u1, u2, out);
  }

  bool is_delta() const override { return nested_->is_delta(); }
  bool has_opacity() const override { return nested_->has_opacity(); }
  float opacity(const SurfaceInteraction& si) const override { return nested_->opacity(si); }

 private:
  PerturbedQuery query(const SurfaceInteraction& si) const {
    return PerturbedQuery(si, bumped_frame(si, height_->eval_1_gradient(si)));
  }

  const Bsdf* nested_;
  std::shared_ptr<const Texture> height_;
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
  return std::make_shared<BumpMapBsdf>(nested, std::move(height));
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

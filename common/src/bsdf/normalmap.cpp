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

class NormalMapBsdf final : public Bsdf {
 public:
  NormalMapBsdf(const Bsdf* nested, std::shared_ptr<const Texture> normals)
      : nested_(nested), normals_(std::move(normals)) {
    TESSERA_CHECK(nested_ != nullptr && normals_ != nullptr);
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
    Rgb c = normals_->eval(si);
    Vec3 n(2.f * c.r - 1.f, 2.f * c.g - 1.f, 2.f * c.b - 1.f);
    return PerturbedQuery(si, normal_mapped_frame(si, n));
  }

  const Bsdf* nested_;
  std::shared_ptr<const Texture> normals_;
};

}  // namespace

std::shared_ptr<Bsdf> make_normalmap_bsdf(const Bsdf* nested, std::shared_ptr<const Texture> normals) {
  return std::make_shared<NormalMapBsdf>(nested, std::move(normals));
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

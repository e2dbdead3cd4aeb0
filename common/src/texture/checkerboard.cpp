// Mitsuba's `checkerboard` texture: two colours alternating on a 2x2 grid per unit of uv.
#include "tessera/scene/load_context.h"
#include "tessera/texture/bitmap.h"

#include <cmath>

namespace tessera {

namespace {

class CheckerboardTexture final : public Texture {
 public:
  CheckerboardTexture(std::shared_ptr<Texture> color0, std::shared_ptr<Texture> color1, UvMapping to_uv)
      : color0_(std::move(color0)), color1_(std::move(color1)), to_uv_(to_uv) {}

  Rgb eval(const SurfaceInteraction& si) const override {
    return first_colour(si) ? color0_->eval(si) : color1_->eval(si);
  }
  float eval_1(const SurfaceInteraction& si) const override {
    return first_colour(si) ? color0_->eval_1(si) : color1_->eval_1(si);
  }
  Rgb mean() const override { return (color0_->mean() + color1_->mean()) * 0.5f; }
  // Zero: the cells' step edges have no finite derivative, and a bump map must not spike there.
  // Textured colours are not differentiated either, so a checkerboard height field is flat.
  Vec2 eval_1_gradient(const SurfaceInteraction&) const override { return {}; }

 private:
  // Mitsuba 0.6: color0 where the cells' parities in u and v agree, i.e. on [0,.5)^2. Cells are
  // found with floor (0.6 truncated towards zero, which merges the two cells around 0 for
  // negative coordinates; Mitsuba 3 uses floor too).
  bool first_colour(const SurfaceInteraction& si) const {
    Vec2 uv = to_uv_.apply(si.uv);
    float cu = std::floor(uv.x * 2.f), cv = std::floor(uv.y * 2.f);
    bool odd_u = std::fmod(std::abs(cu), 2.f) == 1.f, odd_v = std::fmod(std::abs(cv), 2.f) == 1.f;
    return odd_u == odd_v;
  }

  std::shared_ptr<Texture> color0_, color1_;
  UvMapping to_uv_;
};

}  // namespace

std::shared_ptr<Texture> make_checkerboard(const SceneNode& node, LoadContext& ctx) {
  // Colours may themselves be textures (Mitsuba 3); evaluated at the same surface point.
  std::shared_ptr<Texture> c0 = ctx.texture(node, "color0", Rgb(0.4f));
  std::shared_ptr<Texture> c1 = ctx.texture(node, "color1", Rgb(0.2f));
  UvMapping to_uv(node.get_transform("to_uv", Transform()));
  return std::make_shared<CheckerboardTexture>(std::move(c0), std::move(c1), to_uv);
}

}  // namespace tessera

// Texture interface: a spatially varying colour or scalar looked up at a surface point.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/render/interaction.h"

#include <cstddef>
#include <unordered_set>

namespace tessera {

class Texture {
 public:
  virtual ~Texture() = default;
  virtual Rgb eval(const SurfaceInteraction& si) const = 0;
  virtual float eval_1(const SurfaceInteraction& si) const { return eval(si).average(); }
  /// (d/du, d/dv) of eval_1 at si, per unit of si.uv: what bump mapping differentiates (Mitsuba
  /// 0.6's evalGradient). Zero by default, which is exact for constant textures.
  virtual Vec2 eval_1_gradient(const SurfaceInteraction&) const { return {}; }
  /// Mean value over the texture; used to estimate light power and for fallbacks.
  virtual Rgb mean() const = 0;
  /// Bytes of the data it holds (an image's texels) not yet in `counted`, whose keys it adds, so
  /// data shared by several textures counts once (Scene::memory).
  virtual size_t memory_bytes(std::unordered_set<const void*>& counted) const { return 0; }
};

class ConstantTexture final : public Texture {
 public:
  explicit ConstantTexture(Rgb value) : value_(value) {}
  Rgb eval(const SurfaceInteraction&) const override { return value_; }
  Rgb mean() const override { return value_; }

 private:
  Rgb value_;
};

}  // namespace tessera

// Image textures (Mitsuba's `bitmap`) and the uv mapping shared by 2D textures.
//
// Conventions follow Mitsuba 0.6's MIPMap: texel (x, y) with row 0 the file's top row covers
// uv in [x/w, (x+1)/w] x [y/h, (y+1)/h], i.e. v = 0 is the top of the image (mesh loaders already
// flip OBJ texture coordinates as Mitsuba does). Bilinear lookups sample at u*w - 0.5, v*h - 0.5.
#pragma once

#include "tessera/core/transform.h"
#include "tessera/image/image.h"
#include "tessera/render/texture.h"
#include "tessera/texture/bitmap_decode.h"
#include "tessera/texture/texel_storage.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

/// Mitsuba's boundary conditions for lookups outside [0,1]^2. Zero/One return that constant in
/// every channel, alpha included.
enum class WrapMode { Repeat, Mirror, Clamp, Zero, One };
/// Mitsuba 0.6 names: repeat, mirror, clamp, zero|black, one|white. Empty when unknown.
std::optional<WrapMode> parse_wrap_mode(const std::string& name);

enum class TextureFilter { Bilinear, Nearest };

/// The affine part of a `to_uv` transform (uv' = A uv + t), applied before a lookup.
class UvMapping {
 public:
  UvMapping() = default;
  explicit UvMapping(const Transform& to_uv);
  Vec2 apply(Vec2 uv) const {
    return {m_[0] * uv.x + m_[1] * uv.y + m_[2], m_[3] * uv.x + m_[4] * uv.y + m_[5]};
  }
  /// Chain rule: a gradient with respect to the mapped uv' -> the gradient with respect to uv
  /// (multiplied by the transposed linear part).
  Vec2 pull_back(Vec2 g) const { return {m_[0] * g.x + m_[3] * g.y, m_[1] * g.x + m_[4] * g.y}; }

 private:
  float m_[6] = {1, 0, 0, 0, 1, 0};
};

class BitmapTexture final : public Texture {
 public:
  /// `texels` hold linear values (decoding already done), 1, 3 or 4 channels.
  BitmapTexture(std::shared_ptr<const TexelStorage> texels, WrapMode wrap_u, WrapMode wrap_v,
                TextureFilter filter = TextureFilter::Bilinear, UvMapping to_uv = {});
  /// Float texels, copied from an image of linear values.
  BitmapTexture(const std::shared_ptr<const Image>& image, WrapMode wrap_u, WrapMode wrap_v,
                TextureFilter filter = TextureFilter::Bilinear, UvMapping to_uv = {});

  Rgb eval(const SurfaceInteraction& si) const override { return lookup(to_uv_.apply(si.uv)); }
  size_t memory_bytes(std::unordered_set<const void*>& counted) const override {
    return counted.insert(texels_.get()).second ? texels_->bytes() : 0;
  }
  float eval_1(const SurfaceInteraction& si) const override;
  /// Derivative of the bilinear interpolation (Mitsuba 0.6's evalGradientBilinear at the finest
  /// level), through to_uv; zero for the nearest filter, as in Mitsuba.
  Vec2 eval_1_gradient(const SurfaceInteraction& si) const override;
  /// Alpha channel at the surface point (1 for images without alpha); for masks.
  float alpha(const SurfaceInteraction& si) const { return lookup_channel(to_uv_.apply(si.uv), 3); }
  Rgb mean() const override { return texels_->mean(); }

  /// Colour at texture coordinates already mapped by to_uv.
  Rgb lookup(Vec2 uv) const;
  /// One channel (0..3; 3 = alpha, 1 when absent) at mapped texture coordinates.
  float lookup_channel(Vec2 uv, int channel) const;

  /// The texels, shared by every texture of the scene that decodes the same file the same way.
  const std::shared_ptr<const TexelStorage>& texels() const { return texels_; }
  WrapMode wrap_u() const { return wrap_u_; }
  WrapMode wrap_v() const { return wrap_v_; }

 private:
  /// Resolves a texel index against the wrap mode; -1 = outside (Zero/One).
  static int wrap(int i, int n, WrapMode mode);
  /// Texel value with Mitsuba's boundary handling; `fetch` reads an in-range texel.
  template <typename T, typename Fetch>
  T texel(int x, int y, Fetch fetch) const;
  template <typename Fetch>
  auto filtered(Vec2 uv, Fetch fetch) const;
  /// Gradient of the scalar bilinear interpolant at mapped coordinates.
  template <TexelStorage::Format F>
  Vec2 lookup_gradient_1(Vec2 uv) const;

  std::shared_ptr<const TexelStorage> texels_;
  WrapMode wrap_u_, wrap_v_;
  TextureFilter filter_;
  UvMapping to_uv_;
};

/// Texel memory of the distinct bitmap images among `textures` (an image shared by several
/// textures counted once): as stored, and as the same texels would take in float.
struct TextureMemory {
  size_t bytes = 0, float_bytes = 0, images = 0;
};
TextureMemory texture_memory(const std::vector<std::shared_ptr<Texture>>& textures);

}  // namespace tessera

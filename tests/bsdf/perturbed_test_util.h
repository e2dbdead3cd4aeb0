// Helpers shared by the bumpmap and normalmap tests: in-memory textures with known derivatives
// and a flat surface point whose frames are the identity.
#pragma once

#include "tessera/bsdf/bumpmap.h"
#include "tessera/bsdf/conductor.h"
#include "tessera/bsdf/diffuse.h"
#include "tessera/core/hash.h"
#include "tessera/texture/bitmap.h"

#include <cmath>
#include <memory>

namespace tessera::test {

/// A grey bitmap whose bilinear interpolation is exactly slope_u * u + slope_v * v away from the
/// outermost half texel (texel centres carry the plane's values; clamp beyond).
inline std::shared_ptr<BitmapTexture> ramp_texture(float slope_u, float slope_v, int w = 64, int h = 64,
                                                   UvMapping to_uv = {}) {
  Image im(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im.at(x, y, 0) = slope_u * (x + 0.5f) / float(w) + slope_v * (y + 0.5f) / float(h);
  return std::make_shared<BitmapTexture>(std::make_shared<const Image>(std::move(im)), WrapMode::Clamp,
                                         WrapMode::Clamp, TextureFilter::Bilinear, to_uv);
}

/// An RGB bitmap of one colour everywhere (a constant normal map).
inline std::shared_ptr<BitmapTexture> solid_rgb_texture(Rgb c, int w = 4, int h = 4) {
  Image im(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im.set_rgb(x, y, c);
  return std::make_shared<BitmapTexture>(std::make_shared<const Image>(std::move(im)), WrapMode::Repeat,
                                         WrapMode::Repeat);
}

/// A point of the plane z = 0 parameterised by (u, v) = (x, y): every frame is the identity.
inline SurfaceInteraction flat_si(Vec2 uv = {0.4f, 0.6f}) {
  SurfaceInteraction si;
  si.ng = Vec3(0.f, 0.f, 1.f);
  si.uv = uv;
  si.wo = Vec3(0.f, 0.f, 1.f);
  return si;
}

inline std::shared_ptr<Bsdf> white_diffuse(float albedo = 1.f) {
  return make_diffuse_bsdf(std::make_shared<ConstantTexture>(Rgb(albedo)));
}

inline std::shared_ptr<Bsdf> rough_gold(float alpha = 0.3f) {
  auto a = std::make_shared<ConstantTexture>(Rgb(alpha));
  return make_roughconductor_bsdf(MicrofacetType::Ggx, a, nullptr, *lookup_metal("Au"),
                                  std::make_shared<ConstantTexture>(Rgb(1.f)));
}

/// Mean sample weight (failed samples count as 0) and its standard error: directional albedo.
inline void directional_albedo(const Bsdf& b, const SurfaceInteraction& si, Vec3 wo, int n, uint64_t seed,
                               double& mean, double& stderr_out) {
  Pcg32 rng(seed);
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample bs;
    double w = 0;
    if (b.sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) w = bs.weight.g;
    sum += w;
    sum2 += w * w;
  }
  mean = sum / n;
  stderr_out = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
}

}  // namespace tessera::test

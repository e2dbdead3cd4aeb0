// Bump and normal mapping wrappers, constructible without a scene file (tests, tools).
#pragma once

#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// Mitsuba 0.6's `bumpmap`: `nested` evaluated in the shading frame tilted by the gradient of
/// `height` (Texture::eval_1_gradient, per uv unit, over si.dpdu/si.dpdv). `nested` must outlive
/// the result.
std::shared_ptr<Bsdf> make_bumpmap_bsdf(const Bsdf* nested, std::shared_ptr<const Texture> height);

/// Mitsuba 3's `normalmap`: `nested` evaluated in the frame whose normal is 2 rgb - 1 of
/// `normals`, given in the tangent space (dp/du, bitangent, shading normal). The texture's values
/// are used as they come: load the bitmap with `raw` (Mitsuba 3 does no decoding of its own).
/// `nested` must outlive the result.
std::shared_ptr<Bsdf> make_normalmap_bsdf(const Bsdf* nested, std::shared_ptr<const Texture> normals);

}  // namespace tessera

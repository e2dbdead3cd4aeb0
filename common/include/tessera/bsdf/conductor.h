// Smooth and rough conductors (Mitsuba 0.6's `conductor`, `roughconductor`) and the named-metal
// table they share, constructible without a scene file (tests, tools).
#pragma once

#include "tessera/bsdf/microfacet.h"
#include "tessera/core/rgb.h"
#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace tessera {

struct SceneNode;

/// Complex index of refraction eta + i k, per RGB channel.
struct ConductorIor {
  Rgb eta;
  Rgb k;
};

/// Mitsuba's named conductors (data/ior/<name>.{eta,k}.spd, reduced to linear sRGB; see
/// metal_table.cpp), case-sensitive as in Mitsuba. "none" is the perfect mirror (eta 0, k 1: F = 1).
std::optional<ConductorIor> lookup_metal(std::string_view name);
/// The known names, comma separated (for error messages).
std::string known_metal_names();

/// The conductor parameters of Mitsuba 0.6: `material` (default "Cu"), overridden by `eta` / `k`
/// when given, both divided by `ext_eta` (number or IOR name, default "air"). An unknown material
/// throws SceneError at the parameter's line.
ConductorIor read_conductor_ior(const SceneNode& node);

/// Delta reflection with weight fresnel_conductor(cos, eta, k) * specular_reflectance.
std::shared_ptr<Bsdf> make_conductor_bsdf(ConductorIor ior, std::shared_ptr<const Texture> specular_reflectance);

/// Cook-Torrance reflection: F(wo.m) D(m) G(wi, wo, m) / (4 cos_o) (eval includes cos_i).
/// `alpha_v` may be null (isotropic: alpha_u is used). Alphas are evaluated at each hit (eval_1).
std::shared_ptr<Bsdf> make_roughconductor_bsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha_u,
                                               std::shared_ptr<const Texture> alpha_v, ConductorIor ior,
                                               std::shared_ptr<const Texture> specular_reflectance);

}  // namespace tessera

// BSDFs in the other transport direction: importance, carried by light subpaths (bdpt.h).
//
// Every Bsdf evaluates and samples radiance transport (bsdf.h). Importance transport needs the
// adjoint BSDF f*(wo, wi) = f(wi, wo), which for a reciprocal BSDF is f itself and for a
// refraction differs by the 1/eta^2 radiance scaling (Veach 1997, 5.2), and, with shading
// normals, Veach's correction |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|) (5.3). Both follow from
// evaluating the BSDF with its arguments swapped, so no BSDF needs a mode of its own:
//   adjoint_eval(si, bsdf, w_prev, w_next) = eval(si, next, prev) |ng.next| / |ng.prev|
// where light arrives from w_prev (world, towards the previous light vertex) and leaves along
// w_next. Like eval() it includes the cosine of w_next.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/render/bsdf.h"

namespace tessera {

/// The adjoint BSDF with the shading-normal correction, times |cos| of w_next (world directions).
/// Zero when either direction is on different sides of the geometric and the shading surface.
Rgb adjoint_eval(const SurfaceInteraction& si, const Bsdf& bsdf, Vec3 w_prev, Vec3 w_next);
/// The importance weight of a sampled delta lobe: bs.weight (radiance) times eta^2 for a
/// refraction (undoing the radiance scaling) and the shading-normal correction.
Rgb adjoint_weight(const SurfaceInteraction& si, const BsdfSample& bs, Vec3 w_prev, Vec3 w_next);

}  // namespace tessera

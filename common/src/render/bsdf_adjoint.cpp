// BSDFs in importance transport (bsdf_adjoint.h).
#include "tessera/render/bsdf_adjoint.h"

#include <cmath>

namespace tessera {

Rgb adjoint_eval(const SurfaceInteraction& si, const Bsdf& bsdf, Vec3 w_prev, Vec3 w_next) {
  const Vec3 prev = si.to_local(w_prev), next = si.to_local(w_next);
  if (!consistent_side(si, w_prev, prev) || !consistent_side(si, w_next, next)) return {};
  const float cos_prev = std::abs(dot(si.ng, w_prev));
  if (!(cos_prev > 0.f)) return {};
  // eval(next, prev) = f(next, prev) |cos_s prev|; the adjoint with Veach's correction is
  // f(next, prev) |cos_s prev| |cos_g next| / |cos_g prev|.
  return bsdf.eval(si, next, prev) * (std::abs(dot(si.ng, w_next)) / cos_prev);
}

Rgb adjoint_weight(const SurfaceInteraction& si, const BsdfSample& bs, Vec3 w_prev, Vec3 w_next) {
  const float num = std::abs(dot(w_prev, si.shading.n)) * std::abs(dot(w_next, si.ng));
  const float den = std::abs(dot(w_prev, si.ng)) * std::abs(dot(w_next, si.shading.n));
  if (!(den > 0.f)) return {};
  return bs.weight * (bs.eta * bs.eta * num / den);
}

}  // namespace tessera

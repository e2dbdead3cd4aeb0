// The frame change shared by `bumpmap` and `normalmap`: both evaluate a nested BSDF in a shading
// frame of their own (world space) instead of the shape's.
//
// Directions arrive in the local frame of `si.shading`, are taken to world space and into the
// perturbed frame; the nested BSDF sees a copy of `si` whose shading frame is the perturbed one.
// As in Mitsuba (0.6 bump.cpp, 3's normalmap.cpp), a wi that lies on different sides of the
// original and the perturbed shading normals gets zero (eval, pdf) or fails (sample): such light
// would cross the surface by the wrong side, which a perturbed normal alone cannot make
// consistent. wo is not tested, as in Mitsuba: the nested BSDF decides what a wo below its normal
// means.
#pragma once

#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/render/bsdf.h"

#include <utility>

namespace tessera {

/// Unit normal `n` (world) with the tangent dp/du projected into its plane, as Mitsuba does; when
/// dp/du is (nearly) parallel to `n`, the old shading tangent, then any tangent. `n` must be unit.
Frame frame_from_normal(const SurfaceInteraction& si, Vec3 n);

/// Mitsuba 0.6's perturbIntersection: the shading frame of a height field whose derivatives
/// (dh/du, dh/dv) are `grad`, over the tangent plane of si.shading.n. A zero gradient returns
/// si.shading exactly; a gradient or frame that is not finite falls back to it as well.
Frame bumped_frame(const SurfaceInteraction& si, Vec2 grad);

/// Mitsuba 3's normalmap frame: `tangent_normal` (2 rgb - 1, not necessarily unit) is given in the
/// tangent space (dp/du projected, n x that, shading normal). Degenerate input -> si.shading.
Frame normal_mapped_frame(const SurfaceInteraction& si, Vec3 tangent_normal);

/// The nested BSDF's methods evaluated in `frame` (world space) instead of si.shading.
class PerturbedQuery {
 public:
  PerturbedQuery(const SurfaceInteraction& si, const Frame& frame) : si_(si), perturbed_(si) {
    perturbed_.shading = frame;
    // An unperturbed frame passes directions through untouched, so a flat map is exactly the
    // nested BSDF (a round trip through world space would not be).
    same_ = frame.s == si.shading.s && frame.t == si.shading.t && frame.n == si.shading.n;
  }

  Rgb eval(const Bsdf& nested, Vec3 wo, Vec3 wi) const;
  float pdf(const Bsdf& nested, Vec3 wo, Vec3 wi) const;
  bool sample(const Bsdf& nested, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const;

 private:
  /// Local frame of si.shading -> local frame of the perturbed one.
  Vec3 to_perturbed(Vec3 w) const {
    return same_ ? w : perturbed_.shading.to_local(si_.shading.to_world(w));
  }
  Vec3 from_perturbed(Vec3 w) const {
    return same_ ? w : si_.shading.to_local(perturbed_.shading.to_world(w));
  }

  const SurfaceInteraction& si_;
  SurfaceInteraction perturbed_;
  bool same_ = false;
};

/// `nested` evaluated in the frame that `FrameFn` (a callable `Frame(const SurfaceInteraction&)
/// const`) gives at each point: bumpmap and normalmap differ only in where that frame comes from.
/// A template rather than a virtual frame hook, so the frame computation inlines into the hot path.
/// Delta-ness and opacity are the nested BSDF's: tilting the frame changes neither.
template <class FrameFn>
class PerturbedBsdf final : public Bsdf {
 public:
  PerturbedBsdf(const Bsdf* nested, FrameFn frame) : nested_(nested), frame_(std::move(frame)) {
    TESSERA_CHECK(nested_ != nullptr);
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
  float roughness(const SurfaceInteraction& si) const override { return nested_->roughness(si); }
  bool has_opacity() const override { return nested_->has_opacity(); }
  float opacity(const SurfaceInteraction& si) const override { return nested_->opacity(si); }

 private:
  PerturbedQuery query(const SurfaceInteraction& si) const { return PerturbedQuery(si, frame_(si)); }

  const Bsdf* nested_;
  FrameFn frame_;
};

}  // namespace tessera

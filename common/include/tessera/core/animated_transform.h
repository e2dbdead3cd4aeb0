// A transform that changes with time (motion blur): keyframes interpolated as Mitsuba 0.6 does.
//
// Each keyframe's affine matrix is split into translation T, rotation R and a symmetric stretch S
// (polar decomposition M = T R S; a mirror is folded into S so R stays a proper rotation). Between
// two keyframes T and S are interpolated linearly and R by quaternion slerp (shortest arc); before
// the first and after the last keyframe the transform is clamped to that keyframe. At a keyframe's
// own time the keyframe matrix is returned exactly (not its recomposition).
// Optional fixed transforms on either side compose the animation with static ones:
// at(t) = pre * interpolate(t) * post (a moving shape inside a static instance, or a static shape
// inside a moving instance).
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/transform.h"

#include <array>
#include <vector>

namespace tessera {

class AnimatedTransform {
 public:
  struct Keyframe {
    float time = 0.f;
    Transform xf;
  };

  AnimatedTransform() : AnimatedTransform(Transform()) {}
  explicit AnimatedTransform(const Transform& xf);
  /// Keyframe times must be strictly increasing and the matrices affine (TESSERA_CHECK: the parser
  /// reports bad input with file and line before this).
  explicit AnimatedTransform(std::vector<Keyframe> keys);

  /// The transform at scene time `time`. Never throws or allocates.
  Transform at(float time) const;
  /// True when every time gives the same transform (one keyframe, or all keyframes equal).
  bool is_static() const { return static_; }
  const std::vector<Keyframe>& keyframes() const { return keys_; }

  /// pre * this * post.
  AnimatedTransform composed(const Transform& pre, const Transform& post) const;

  /// A box containing `object_bounds` transformed by at(t) for every t in [t0, t1]: the union of
  /// boxes at the keyframe times inside the interval, at its ends and at 64 times per keyframe
  /// segment, each padded by the largest distance a box corner moves between neighbouring sample
  /// times (which bounds how far a point's path strays from the sampled positions).
  Bounds3 motion_bounds(const Bounds3& object_bounds, float t0, float t1) const;

 private:
  struct Decomposed {
    std::array<double, 3> t{};
    std::array<double, 4> q{0, 0, 0, 1};  // x, y, z, w
    std::array<std::array<double, 3>, 3> s{};
  };
  std::vector<Keyframe> keys_;
  std::vector<Decomposed> parts_;
  Transform pre_, post_;
  bool has_pre_ = false, has_post_ = false;
  bool static_ = true;

  Transform interpolate(float time) const;
};

}  // namespace tessera

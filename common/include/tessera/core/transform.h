// Affine/projective transforms as 4x4 matrices with their inverse. Names follow the spaces they
// map between: `world_from_object` takes object-space points to world space.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/vec.h"

#include <array>
#include <optional>

namespace tessera {

struct Matrix4 {
  std::array<std::array<double, 4>, 4> m{};  // row-major, m[row][col]; double so composition is exact enough

  static Matrix4 identity();
  /// Row-major values, as Mitsuba's `<matrix value="...">` lists them.
  static Matrix4 from_row_major(const std::array<double, 16>& v);
  Matrix4 operator*(const Matrix4& o) const;
  Matrix4 transposed() const;
  /// Empty when the matrix is singular (determinant ~ 0) or not finite.
  std::optional<Matrix4> inverse() const;
  bool is_identity() const;
  bool operator==(const Matrix4&) const = default;
};

class Transform {
 public:
  Transform() : m_(Matrix4::identity()), inv_(Matrix4::identity()) {}
  Transform(const Matrix4& m, const Matrix4& inv) : m_(m), inv_(inv) {}
  /// Empty when `m` is not invertible.
  static std::optional<Transform> from_matrix(const Matrix4& m);

  static Transform translate(Vec3 d);
  static Transform scale(Vec3 s);
  /// Rotation by `degrees` about `axis` (right-handed, as Mitsuba's <rotate>).
  static Transform rotate(Vec3 axis, float degrees);
  /// Camera-to-world for an eye at `origin` looking at `target` (Mitsuba's <lookat>: +z forward).
  static std::optional<Transform> look_at(Vec3 origin, Vec3 target, Vec3 up);
  /// Perspective projection in Mitsuba/pbrt convention (maps camera space to [-1,1]^2 x [0,1] depth).
  static Transform perspective(float fov_degrees, float near_clip, float far_clip);

  Transform operator*(const Transform& o) const { return {m_ * o.m_, o.inv_ * inv_}; }
  Transform inverse() const { return {inv_, m_}; }
  const Matrix4& matrix() const { return m_; }
  const Matrix4& inverse_matrix() const { return inv_; }
  bool is_identity() const { return m_.is_identity(); }
  /// True when the transform flips orientation (negative determinant of the linear part).
  bool swaps_handedness() const;

  Vec3 apply_point(Vec3 p) const;
  /// Error bound per axis of apply_point(p) for a `p` itself within `p_error` of the exact point
  /// (pbrt-v4's Transform of a Point3fi): the input error carried through the matrix plus the
  /// rounding of the result. Affine transforms (the last row 0 0 0 1).
  Vec3 apply_point_error(Vec3 p, Vec3 p_error) const;
  Vec3 apply_vector(Vec3 v) const;
  /// Normals transform by the inverse transpose, so non-uniform scales keep them perpendicular.
  Vec3 apply_normal(Vec3 n) const;
  Bounds3 apply(const Bounds3& b) const;

 private:
  Matrix4 m_, inv_;
};

}  // namespace tessera

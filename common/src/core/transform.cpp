#include "tessera/core/transform.h"

#include <cmath>

namespace tessera {

Matrix4 Matrix4::identity() {
  Matrix4 r;
  for (int i = 0; i < 4; ++i) r.m[i][i] = 1.0;
  return r;
}

Matrix4 Matrix4::from_row_major(const std::array<double, 16>& v) {
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = v[i * 4 + j];
  return r;
}

Matrix4 Matrix4::operator*(const Matrix4& o) const {
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += m[i][k] * o.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

Matrix4 Matrix4::transposed() const {
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = m[j][i];
  return r;
}

bool Matrix4::is_identity() const { return *this == identity(); }

std::optional<Matrix4> Matrix4::inverse() const {
  // Gauss-Jordan elimination with partial pivoting, in double.
  double a[4][8];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      if (!std::isfinite(m[i][j])) return std::nullopt;
      a[i][j] = m[i][j];
      a[i][j + 4] = (i == j) ? 1.0 : 0.0;
    }
  double scale = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) scale = std::max(scale, std::abs(m[i][j]));
  if (scale == 0) return std::nullopt;
  for (int col = 0; col < 4; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 4; ++r)
      if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
    if (std::abs(a[pivot][col]) <= 1e-14 * scale) return std::nullopt;
    if (pivot != col)
      for (int j = 0; j < 8; ++j) std::swap(a[col][j], a[pivot][j]);
    double inv_p = 1.0 / a[col][col];
    for (int j = 0; j < 8; ++j) a[col][j] *= inv_p;
    for (int r = 0; r < 4; ++r) {
      if (r == col || a[r][col] == 0.0) continue;
      double f = a[r][col];
      for (int j = 0; j < 8; ++j) a[r][j] -= f * a[col][j];
    }
  }
  Matrix4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = a[i][j + 4];
  return r;
}

std::optional<Transform> Transform::from_matrix(const Matrix4& m) {
  auto inv = m.inverse();
  if (!inv) return std::nullopt;
  return Transform(m, *inv);
}

Transform Transform::translate(Vec3 d) {
  Matrix4 m = Matrix4::identity(), inv = Matrix4::identity();
  for (int i = 0; i < 3; ++i) {
    m.m[i][3] = d[i];
    inv.m[i][3] = -double(d[i]);
  }
  return {m, inv};
}

Transform Transform::scale(Vec3 s) {
  Matrix4 m = Matrix4::identity(), inv = Matrix4::identity();
  for (int i = 0; i < 3; ++i) {
    m.m[i][i] = s[i];
    inv.m[i][i] = 1.0 / double(s[i]);
  }
  return {m, inv};
}

Transform Transform::rotate(Vec3 axis, float degrees) {
  double len = std::sqrt(double(axis.x) * axis.x + double(axis.y) * axis.y + double(axis.z) * axis.z);
  double x = axis.x / len, y = axis.y / len, z = axis.z / len;
  double theta = double(degrees) * 3.14159265358979323846 / 180.0;
  double s = std::sin(theta), c = std::cos(theta), t = 1.0 - c;
  Matrix4 m = Matrix4::identity();
  m.m[0][0] = x * x * t + c;     m.m[0][1] = x * y * t - z * s; m.m[0][2] = x * z * t + y * s;
  m.m[1][0] = y * x * t + z * s; m.m[1][1] = y * y * t + c;     m.m[1][2] = y * z * t - x * s;
  m.m[2][0] = z * x * t - y * s; m.m[2][1] = z * y * t + x * s; m.m[2][2] = z * z * t + c;
  return {m, m.transposed()};
}

std::optional<Transform> Transform::look_at(Vec3 origin, Vec3 target, Vec3 up) {
  Vec3 dir = target - origin;
  if (length(dir) == 0.f) return std::nullopt;
  dir = normalize(dir);
  Vec3 left = cross(normalize(up), dir);
  if (!(length(left) > 1e-7f)) return std::nullopt;
  left = normalize(left);
  Vec3 new_up = cross(dir, left);
  Matrix4 m = Matrix4::identity();
  for (int i = 0; i < 3; ++i) {
    m.m[i][0] = left[i];
    m.m[i][1] = new_up[i];
    m.m[i][2] = dir[i];
    m.m[i][3] = origin[i];
  }
  return from_matrix(m);
}

Transform Transform::perspective(float fov_degrees, float n, float f) {
  double recip = 1.0 / (double(f) - n);
  double cot = 1.0 / std::tan(double(fov_degrees) * 3.14159265358979323846 / 360.0);
  Matrix4 m = Matrix4::identity();
  m.m[0][0] = cot;
  m.m[1][1] = cot;
  m.m[2][2] = f * recip;
  m.m[2][3] = -double(n) * f * recip;
  m.m[3][2] = 1;
  m.m[3][3] = 0;
  return *from_matrix(m);
}

bool Transform::swaps_handedness() const {
  const auto& a = m_.m;
  double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
               a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  return det < 0;
}

Vec3 Transform::apply_point(Vec3 p) const {
  const auto& a = m_.m;
  double r[4];
  for (int i = 0; i < 4; ++i) r[i] = a[i][0] * p.x + a[i][1] * p.y + a[i][2] * p.z + a[i][3];
  if (r[3] == 1.0) return Vec3(float(r[0]), float(r[1]), float(r[2]));
  return Vec3(float(r[0] / r[3]), float(r[1] / r[3]), float(r[2] / r[3]));
}

Vec3 Transform::apply_point_error(Vec3 p, Vec3 p_error) const {
  const auto& a = m_.m;
  // apply_point sums in double and rounds once to float: a relative 2^-24 of the result plus a
  // few double roundings of the terms; gamma(3) (float) of the terms' magnitude bounds both. The
  // carried error is widened by the same factor for the rounding of its own evaluation.
  constexpr float eps = 0.5f * 1.1920928955078125e-7f;
  constexpr float g3 = (3.f * eps) / (1.f - 3.f * eps);
  float out[3];
  for (int i = 0; i < 3; ++i) {
    const double terms = std::abs(a[i][0] * p.x) + std::abs(a[i][1] * p.y) + std::abs(a[i][2] * p.z) + std::abs(a[i][3]);
    const double carried = std::abs(a[i][0]) * p_error.x + std::abs(a[i][1]) * p_error.y + std::abs(a[i][2]) * p_error.z;
    out[i] = float(g3 * terms + (1.0 + g3) * carried);
  }
  return Vec3(out[0], out[1], out[2]);
}

Vec3 Transform::apply_vector(Vec3 v) const {
  const auto& a = m_.m;
  return Vec3(float(a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z),
              float(a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z),
              float(a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z));
}

Vec3 Transform::apply_normal(Vec3 n) const {
  const auto& b = inv_.m;  // (M^-1)^T n
  return Vec3(float(b[0][0] * n.x + b[1][0] * n.y + b[2][0] * n.z),
              float(b[0][1] * n.x + b[1][1] * n.y + b[2][1] * n.z),
              float(b[0][2] * n.x + b[1][2] * n.y + b[2][2] * n.z));
}

Bounds3 Transform::apply(const Bounds3& b) const {
  Bounds3 r;
  if (b.empty()) return r;
  for (int i = 0; i < 8; ++i)
    r.extend(apply_point(Vec3((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y,
                              (i & 4) ? b.hi.z : b.lo.z)));
  return r;
}

}  // namespace tessera

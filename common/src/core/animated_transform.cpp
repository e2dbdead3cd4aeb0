#include "tessera/core/animated_transform.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

using Mat3 = std::array<std::array<double, 3>, 3>;

Mat3 linear_part(const Matrix4& m) {
  Mat3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[i][j] = m.m[i][j];
  return r;
}

double det3(const Mat3& a) {
  return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
         a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

// Inverse transpose via the cofactor matrix (the caller guarantees det != 0).
Mat3 inverse_transpose3(const Mat3& a) {
  double d = det3(a);
  Mat3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      c[i][j] = (a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]) / d;
    }
  return c;
}

// Rotation factor of the polar decomposition by Higham's iteration R <- (R + R^-T) / 2.
Mat3 polar_rotation(const Mat3& m) {
  Mat3 r = m;
  for (int it = 0; it < 100; ++it) {
    Mat3 it_r = inverse_transpose3(r);
    double change = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double n = 0.5 * (r[i][j] + it_r[i][j]);
        change = std::max(change, std::abs(n - r[i][j]));
        r[i][j] = n;
      }
    if (change < 1e-15) break;
  }
  return r;
}

std::array<double, 4> quat_from_rotation(const Mat3& r) {
  std::array<double, 4> q{};  // x, y, z, w for column vectors: v' = R v
  double tr = r[0][0] + r[1][1] + r[2][2];
  if (tr > 0) {
    double s = std::sqrt(tr + 1.0) * 2;
    q = {(r[2][1] - r[1][2]) / s, (r[0][2] - r[2][0]) / s, (r[1][0] - r[0][1]) / s, 0.25 * s};
  } else if (r[0][0] > r[1][1] && r[0][0] > r[2][2]) {
    double s = std::sqrt(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2;
    q = {0.25 * s, (r[0][1] + r[1][0]) / s, (r[0][2] + r[2][0]) / s, (r[2][1] - r[1][2]) / s};
  } else if (r[1][1] > r[2][2]) {
    double s = std::sqrt(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2;
    q = {(r[0][1] + r[1][0]) / s, 0.25 * s, (r[1][2] + r[2][1]) / s, (r[0][2] - r[2][0]) / s};
  } else {
    double s = std::sqrt(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2;
    q = {(r[0][2] + r[2][0]) / s, (r[1][2] + r[2][1]) / s, 0.25 * s, (r[1][0] - r[0][1]) / s};
  }
  double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& c : q) c /= n;
  return q;
}

Mat3 rotation_from_quat(const std::array<double, 4>& q) {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
           {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
           {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}}};
}

std::array<double, 4> slerp(const std::array<double, 4>& a, const std::array<double, 4>& b, double u) {
  double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];  // >= 0: hemispheres aligned at build
  std::array<double, 4> q{};
  if (d > 0.9995) {
    for (int i = 0; i < 4; ++i) q[i] = a[i] + (b[i] - a[i]) * u;
  } else {
    double theta = std::acos(std::clamp(d, -1.0, 1.0));
    double wa = std::sin((1 - u) * theta) / std::sin(theta), wb = std::sin(u * theta) / std::sin(theta);
    for (int i = 0; i < 4; ++i) q[i] = wa * a[i] + wb * b[i];
  }
  double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& c : q) c /= n;
  return q;
}

bool is_affine(const Matrix4& m) { return m.m[3][0] == 0 && m.m[3][1] == 0 && m.m[3][2] == 0 && m.m[3][3] == 1; }

}  // namespace

AnimatedTransform::AnimatedTransform(const Transform& xf) : keys_{Keyframe{0.f, xf}} {}

AnimatedTransform::AnimatedTransform(std::vector<Keyframe> keys) : keys_(std::move(keys)) {
  TESSERA_CHECK(!keys_.empty());
  for (size_t i = 1; i < keys_.size(); ++i) {
    TESSERA_CHECK(keys_[i].time > keys_[i - 1].time);
    if (!(keys_[i].xf.matrix() == keys_[0].xf.matrix())) static_ = false;
  }
  if (static_) {
    keys_.resize(1);
    return;
  }
  parts_.resize(keys_.size());
  for (size_t k = 0; k < keys_.size(); ++k) {
    const Matrix4& m = keys_[k].xf.matrix();
    TESSERA_CHECK(is_affine(m));
    Decomposed& d = parts_[k];
    for (int i = 0; i < 3; ++i) d.t[i] = m.m[i][3];
    Mat3 a = linear_part(m);
    Mat3 r = polar_rotation(a);
    if (det3(r) < 0)  // a mirror: keep R proper and let the stretch carry the reflection
      for (auto& row : r)
        for (double& v : row) v = -v;
    // S = R^T A
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double s = 0;
        for (int l = 0; l < 3; ++l) s += r[l][i] * a[l][j];
        d.s[i][j] = s;
      }
    d.q = quat_from_rotation(r);
    if (k > 0) {  // shortest arc: consecutive quaternions in the same hemisphere
      const auto& p = parts_[k - 1].q;
      if (p[0] * d.q[0] + p[1] * d.q[1] + p[2] * d.q[2] + p[3] * d.q[3] < 0)
        for (double& c : d.q) c = -c;
    }
  }
}

AnimatedTransform AnimatedTransform::composed(const Transform& pre, const Transform& post) const {
  // Identity factors are skipped rather than multiplied, so a static result is bit for bit the
  // product a static scene computes.
  AnimatedTransform r = *this;
  if (!pre.is_identity()) {
    r.pre_ = r.has_pre_ ? pre * r.pre_ : pre;
    r.has_pre_ = true;
  }
  if (!post.is_identity()) {
    r.post_ = r.has_post_ ? r.post_ * post : post;
    r.has_post_ = true;
  }
  if (r.static_) {  // fold into the single keyframe
    r.keys_[0].xf = r.at(r.keys_[0].time);
    r.pre_ = r.post_ = Transform();
    r.has_pre_ = r.has_post_ = false;
  }
  return r;
}

Transform AnimatedTransform::interpolate(float time) const {
  if (static_ || time <= keys_.front().time) return keys_.front().xf;
  if (time >= keys_.back().time) return keys_.back().xf;
  size_t i = size_t(std::upper_bound(keys_.begin(), keys_.end(), time,
                                     [](float t, const Keyframe& k) { return t < k.time; }) -
                    keys_.begin()) - 1;
  if (time == keys_[i].time) return keys_[i].xf;
  const double u = (double(time) - keys_[i].time) / (double(keys_[i + 1].time) - keys_[i].time);
  const Decomposed &a = parts_[i], &b = parts_[i + 1];
  Mat3 r = rotation_from_quat(slerp(a.q, b.q, u));
  Mat3 s{};
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y) s[x][y] = a.s[x][y] + (b.s[x][y] - a.s[x][y]) * u;
  Matrix4 m = Matrix4::identity();
  for (int x = 0; x < 3; ++x) {
    for (int y = 0; y < 3; ++y) {
      double v = 0;
      for (int l = 0; l < 3; ++l) v += r[x][l] * s[l][y];
      m.m[x][y] = v;
    }
    m.m[x][3] = a.t[x] + (b.t[x] - a.t[x]) * u;
  }
  auto xf = Transform::from_matrix(m);
  if (!xf) return u < 0.5 ? keys_[i].xf : keys_[i + 1].xf;  // a stretch through zero: degenerate instant
  return *xf;
}

Transform AnimatedTransform::at(float time) const {
  Transform x = interpolate(time);
  if (has_pre_) x = pre_ * x;
  if (has_post_) x = x * post_;
  return x;
}

Bounds3 AnimatedTransform::motion_bounds(const Bounds3& b, float t0, float t1) const {
  if (b.empty()) return b;
  if (static_ || !(t1 > t0)) return at(t0).apply(b);
  std::vector<float> marks{t0};
  for (const Keyframe& k : keys_)
    if (k.time > t0 && k.time < t1) marks.push_back(k.time);
  marks.push_back(t1);
  constexpr int kStepsPerSegment = 64;
  auto corners = [&](float t, std::array<Vec3, 8>& c) {
    Transform x = at(t);
    for (int i = 0; i < 8; ++i)
      c[size_t(i)] = x.apply_point(Vec3((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z));
  };
  Bounds3 out;
  std::array<Vec3, 8> prev{}, cur{};
  corners(t0, prev);
  for (size_t seg = 0; seg + 1 < marks.size(); ++seg) {
    for (int s = 1; s <= kStepsPerSegment; ++s) {
      float t = s == kStepsPerSegment ? marks[seg + 1]
                                      : float(double(marks[seg]) + (double(marks[seg + 1]) - marks[seg]) * s / kStepsPerSegment);
      corners(t, cur);
      float pad = 0.f;
      Bounds3 step;
      for (size_t i = 0; i < 8; ++i) {
        pad = std::max(pad, length(cur[i] - prev[i]));
        step.extend(cur[i]);
        step.extend(prev[i]);
      }
      // Relative slack for the float rounding of the corners themselves.
      pad += 1e-5f * std::max(max_component(vmax(vabs(step.lo), vabs(step.hi))), 1e-6f);
      out.extend(step.lo - Vec3(pad));
      out.extend(step.hi + Vec3(pad));
      prev = cur;
    }
  }
  return out;
}

}  // namespace tessera

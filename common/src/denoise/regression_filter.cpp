#include "denoise/regression_filter.h"

#include "tessera/core/check.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdint>
#include <cstring>

namespace tessera::denoise_detail {
namespace {

constexpr int kBandRows = 16;
constexpr float kEpsilon = 1e-10f;
// Weights below e^-kCutoff (about 2e-9) count as 0.
constexpr float kCutoff = 20.f;

// e^-x for x >= 0 to about 2e-5 relative: 2^(-x log2 e) as an exponent and a degree-6 Taylor polynomial
// of the fraction. Plain float arithmetic (no libm call), so the weight loop vectorises and gives the
// same bits on every machine.
inline float exp_neg(float x) {
  if (!(x < kCutoff)) return 0.f;
  const float t = -x * 1.44269504f;
  const float fi = std::floor(t);
  const float f = t - fi;  // [0, 1)
  float p = 1.5403530e-4f;
  p = p * f + 1.3333558e-3f;
  p = p * f + 9.6181291e-3f;
  p = p * f + 5.5504109e-2f;
  p = p * f + 2.4022651e-1f;
  p = p * f + 6.9314718e-1f;
  p = p * f + 1.f;
  const int32_t bits = (int32_t(fi) + 127) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

// One band of rows: its normal equations, accumulated over the window's offsets in a fixed order.
class BandFilter {
 public:
  BandFilter(const Planes& guide, const Planes& guide_var, const Planes& value, const Planes& features,
             const RegressionParams& params, int y0, int y1)
      : g_(guide), v_(guide_var), val_(value), feat_(features), p_(params), w_(guide.width), h_(guide.height),
        y0_(y0), y1_(y1), n_(features.channels() + 1), ty0_(std::max(0, y0 - params.patch)),
        ty1_(std::min(h_, y1 + params.patch)) {
    const size_t px = size_t(y1 - y0) * size_t(w_);
    sym_.assign(size_t(n_ * (n_ + 1) / 2), std::vector<float>(px, 0.f));
    rhs_.assign(size_t(3 * n_), std::vector<float>(px, 0.f));
    t_.resize(size_t(ty1_ - ty0_) * size_t(w_));
    hsum_.resize(t_.size());
    weight_.resize(size_t(w_));
    x_.assign(size_t(n_), std::vector<float>(size_t(w_), 1.f));
    wx_.assign(size_t(n_), std::vector<float>(size_t(w_), 0.f));
  }

  void run(Planes& out) {
    for (int dy = -p_.radius; dy <= p_.radius; ++dy)
      for (int dx = -p_.radius; dx <= p_.radius; ++dx) add_offset(dx, dy);
    solve(out);
  }

 private:
  // Patch distances of every pixel of the band to its neighbour at (dx, dy), then their weights
  // and the weighted outer products.
  void add_offset(int dx, int dy) {
    pixel_terms(dx, dy);
    const int f = p_.patch;
    for (int y = ty0_; y < ty1_; ++y) {
      const float* t = &t_[size_t(y - ty0_) * size_t(w_)];
      float* hs = &hsum_[size_t(y - ty0_) * size_t(w_)];
      for (int x = 0; x < w_; ++x) {
        float s = 0.f;
        for (int o = -f; o <= f; ++o) s += t[clamp_coord(x + o, w_)];
        hs[x] = s;
      }
    }
    const float norm = 1.f / float(3 * (2 * f + 1) * (2 * f + 1));
    for (int y = y0_; y < y1_; ++y) {
      const int yq = y + dy;
      if (yq < 0 || yq >= h_) continue;
      const int x_begin = std::max(0, -dx), x_end = std::min(w_, w_ - dx);
      for (int x = x_begin; x < x_end; ++x) {
        float d = 0.f;
        for (int o = -f; o <= f; ++o) d += hsum_[size_t(clamp_coord(y + o, h_) - ty0_) * size_t(w_) + size_t(x)];
        weight_[size_t(x)] = exp_neg(std::max(0.f, d * norm));
      }
      accumulate(y, yq, dx, x_begin, x_end);
    }
  }

  // Per pixel of the rows the patches reach: the variance-discounted colour distance to the pixel
  // at (dx, dy) (clamped at the border), summed over channels.
  void pixel_terms(int dx, int dy) {
    const float k2 = p_.k * p_.k;
    for (int y = ty0_; y < ty1_; ++y) {
      const int yq = clamp_coord(y + dy, h_);
      float* t = &t_[size_t(y - ty0_) * size_t(w_)];
      for (int x = 0; x < w_; ++x) t[x] = 0.f;
      for (int c = 0; c < 3; ++c) {
        const float* ga = &g_.c[size_t(c)][g_.index(0, y)];
        const float* gb = &g_.c[size_t(c)][g_.index(0, yq)];
        const float* va = &v_.c[size_t(c)][v_.index(0, y)];
        const float* vb = &v_.c[size_t(c)][v_.index(0, yq)];
        for (int x = 0; x < w_; ++x) {
          const int xq = clamp_coord(x + dx, w_);
          const float diff = ga[x] - gb[xq];
          const float num = diff * diff - p_.alpha * (va[x] + std::min(va[x], vb[xq]));
          t[x] += num / (kEpsilon + k2 * (va[x] + vb[xq]));
        }
      }
    }
  }

  void accumulate(int y, int yq, int dx, int x_begin, int x_end) {
    for (int j = 1; j < n_; ++j) {
      const float* fp = &feat_.c[size_t(j - 1)][feat_.index(0, y)];
      const float* fq = &feat_.c[size_t(j - 1)][feat_.index(0, yq)];
      float* xj = x_[size_t(j)].data();
      for (int x = x_begin; x < x_end; ++x) xj[x] = fq[x + dx] - fp[x];
    }
    const size_t row = size_t(y - y0_) * size_t(w_);
    const float* w = weight_.data();
    for (int i = 0; i < n_; ++i) {
      const float* xi = x_[size_t(i)].data();
      float* wxi = wx_[size_t(i)].data();
      for (int x = x_begin; x < x_end; ++x) wxi[x] = w[x] * xi[x];
    }
    size_t s = 0;
    for (int i = 0; i < n_; ++i)
      for (int j = i; j < n_; ++j, ++s) {
        const float* wxi = wx_[size_t(i)].data();
        const float* xj = x_[size_t(j)].data();
        float* acc = &sym_[s][row];
        for (int x = x_begin; x < x_end; ++x) acc[x] += wxi[x] * xj[x];
      }
    for (int c = 0; c < 3; ++c) {
      const float* vq = &val_.c[size_t(c)][val_.index(0, yq)];
      for (int i = 0; i < n_; ++i) {
        const float* wxi = wx_[size_t(i)].data();
        float* acc = &rhs_[size_t(c * n_ + i)][row];
        for (int x = x_begin; x < x_end; ++x) acc[x] += wxi[x] * vq[x + dx];
      }
    }
  }

  // Per pixel: ridge-regularised Cholesky solve of the normal equations; the intercept is the
  // filtered value. A singular system falls back to the weighted mean.
  void solve(Planes& out) const {
    double a[9][9], l[9][9], b[9], z[9];
    for (int y = y0_; y < y1_; ++y)
      for (int x = 0; x < w_; ++x) {
        const size_t p = size_t(y - y0_) * size_t(w_) + size_t(x);
        size_t s = 0;
        for (int i = 0; i < n_; ++i)
          for (int j = i; j < n_; ++j, ++s) a[i][j] = a[j][i] = double(sym_[s][p]);
        for (int i = 1; i < n_; ++i) a[i][i] += 1e-3 * a[i][i] + 1e-6 * a[0][0];
        const bool ok = cholesky(a, l);
        for (int c = 0; c < 3; ++c) {
          for (int i = 0; i < n_; ++i) b[i] = double(rhs_[size_t(c * n_ + i)][p]);
          double v = a[0][0] > 0 ? b[0] / a[0][0] : double(val_.at(c, x, y));
          if (ok) v = intercept(l, b, z);
          out.c[size_t(c)][out.index(x, y)] = float(v);
        }
      }
  }

  bool cholesky(const double (&a)[9][9], double (&l)[9][9]) const {
    for (int i = 0; i < n_; ++i)
      for (int j = 0; j <= i; ++j) {
        double s = a[i][j];
        for (int k = 0; k < j; ++k) s -= l[i][k] * l[j][k];
        if (i == j) {
          if (!(s > 1e-12 * a[0][0])) return false;
          l[i][i] = std::sqrt(s);
        } else {
          l[i][j] = s / l[j][j];
        }
      }
    return true;
  }

  // Solves L Lᵀ β = b and returns β₀.
  double intercept(const double (&l)[9][9], const double (&b)[9], double (&z)[9]) const {
    for (int i = 0; i < n_; ++i) {
      double s = b[i];
      for (int k = 0; k < i; ++k) s -= l[i][k] * z[k];
      z[i] = s / l[i][i];
    }
    for (int i = n_ - 1; i >= 0; --i) {
      double s = z[i];
      for (int k = i + 1; k < n_; ++k) s -= l[k][i] * z[k];
      z[i] = s / l[i][i];
    }
    return z[0];
  }

  const Planes &g_, &v_, &val_, &feat_;
  const RegressionParams p_;
  const int w_, h_, y0_, y1_, n_, ty0_, ty1_;
  std::vector<std::vector<float>> sym_, rhs_, x_, wx_;  // x_: [1, features(q) - features(p)]; wx_ = weight × x_
  std::vector<float> t_, hsum_, weight_;
};

}  // namespace

Planes regression_filter(const Planes& guide, const Planes& guide_var, const Planes& value, const Planes& features,
                         const RegressionParams& params) {
  TESSERA_CHECK(guide.channels() == 3 && guide_var.channels() == 3 && value.channels() == 3);
  TESSERA_CHECK(features.channels() <= 8);
  Planes out(guide.width, guide.height, 3);
  const int bands = (guide.height + kBandRows - 1) / kBandRows;
  tbb::parallel_for(0, bands, [&](int b) {
    const int y0 = b * kBandRows;
    BandFilter(guide, guide_var, value, features, params, y0, std::min(guide.height, y0 + kBandRows)).run(out);
  });
  return out;
}

}  // namespace tessera::denoise_detail

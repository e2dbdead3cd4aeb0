#include "tessera/denoise/denoiser.h"

#include "denoise/planes.h"
#include "denoise/regression_filter.h"
#include "tessera/core/check.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <limits>

namespace tessera {

using denoise_detail::clamp_coord;
using denoise_detail::Planes;
using denoise_detail::RegressionParams;
using denoise_detail::to_planes;

namespace {

// The error map is smoothed over (2 kErrorRadius + 1)² pixels before the candidates are compared.
constexpr int kErrorRadius = 3;

struct Candidate {
  Planes a, b;  // half A filtered with B's weights, and the reverse
  std::vector<float> error;
};

std::vector<RegressionParams> candidate_params(DenoiseMode mode) {
  if (mode == DenoiseMode::Preview) return {{3, 2, 0.7f, 1.f}};
  return {{7, 3, 0.45f, 1.f}, {7, 3, 1.f, 1.f}};
}

// Per pixel, over channels: the candidate's estimated squared error over its squared colour + 0.01
// (as relMSE weighs it). A half filtered with the other's weights is compared with that other raw
// half, whose variance (var_half) is then removed: E[(F_a - B)²] = MSE(F_a) + Var(B).
std::vector<float> estimate_error(const Candidate& cand, const Planes& half_a, const Planes& half_b,
                                  const Planes& var_half, const Planes& level) {
  const size_t n = size_t(half_a.width) * size_t(half_a.height);
  std::vector<float> error(n, 0.f);
  for (size_t c = 0; c < 3; ++c)
    for (size_t i = 0; i < n; ++i) {
      const float da = cand.a.c[c][i] - half_b.c[c][i], db = cand.b.c[c][i] - half_a.c[c][i];
      const float l = level.c[c][i];
      error[i] += (0.5f * (da * da + db * db) - var_half.c[c][i]) / (l * l + 0.01f);
    }
  return error;
}

std::vector<float> smoothed(const std::vector<float>& e, int w, int h) {
  std::vector<float> out(e.size());
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      float s = 0.f;
      for (int oy = -kErrorRadius; oy <= kErrorRadius; ++oy)
        for (int ox = -kErrorRadius; ox <= kErrorRadius; ++ox)
          s += e[size_t(clamp_coord(y + oy, h)) * size_t(w) + size_t(clamp_coord(x + ox, w))];
      out[size_t(y) * size_t(w) + size_t(x)] = s;
    }
  });
  return out;
}

// Features of the regression: albedo, normal, depth.
Planes feature_planes(const DenoiseInput& in) {
  const Planes albedo = to_planes(in.albedo), normal = to_planes(in.normal), depth = to_planes(in.depth);
  Planes f(in.color.width(), in.color.height(), 7);
  for (size_t c = 0; c < 3; ++c) {
    f.c[c] = albedo.c[c];
    f.c[3 + c] = normal.c[c];
  }
  f.c[6] = depth.c[0];
  return f;
}

Image denoise_in_arena(const DenoiseInput& in, DenoiseMode mode) {
  const int w = in.color.width(), h = in.color.height();
  const size_t n = size_t(w) * size_t(h);
  const Planes color = to_planes(in.color), half_a = to_planes(in.half_a), half_b = to_planes(in.half_b);
  const Planes features = feature_planes(in);
  // A half's mean has half the samples: twice the variance of the pixel's mean.
  Planes var_half = to_planes(in.variance);
  for (auto& ch : var_half.c)
    for (float& v : ch) v *= 2.f;

  std::vector<Candidate> cands;
  for (const RegressionParams& p : candidate_params(mode))
    cands.push_back({denoise_detail::regression_filter(half_b, var_half, half_a, features, p),
                     denoise_detail::regression_filter(half_a, var_half, half_b, features, p),
                     {}});
  // Errors are relative to the first candidate's colour, the least smoothed one.
  Planes level(w, h, 3);
  for (size_t c = 0; c < 3; ++c)
    for (size_t i = 0; i < n; ++i) level.c[c][i] = 0.5f * (cands[0].a.c[c][i] + cands[0].b.c[c][i]);
  std::vector<std::vector<float>> errors;
  for (const Candidate& cand : cands) errors.push_back(smoothed(estimate_error(cand, half_a, half_b, var_half, level), w, h));
  // The raw pixel's error is its variance.
  std::vector<float> raw_error(n, 0.f);
  for (size_t c = 0; c < 3; ++c)
    for (size_t i = 0; i < n; ++i) raw_error[i] += 0.5f * var_half.c[c][i] / (level.c[c][i] * level.c[c][i] + 0.01f);
  errors.push_back(smoothed(raw_error, w, h));

  Image out(w, h, 3);
  for (size_t i = 0; i < n; ++i) {
    size_t best = cands.size();  // raw
    for (size_t k = 0; k < cands.size(); ++k)
      if (errors[k][i] < errors[best][i]) best = k;
    for (size_t c = 0; c < 3; ++c) {
      float v = color.c[c][i];
      if (best < cands.size()) {
        const float f = 0.5f * (cands[best].a.c[c][i] + cands[best].b.c[c][i]);
        if (std::isfinite(f)) v = std::max(f, 0.f);
      }
      out.data()[i * 3 + c] = std::isfinite(v) ? v : 0.f;
    }
  }
  return out;
}

}  // namespace

std::vector<AovLayer> denoise_layers() {
  return {AovLayer::Albedo, AovLayer::Normal, AovLayer::Depth, AovLayer::Variance, AovLayer::HalfA, AovLayer::HalfB};
}

Image denoise(const DenoiseInput& in, const DenoiseSettings& settings) {
  const int w = in.color.width(), h = in.color.height();
  for (const Image* img : {&in.albedo, &in.normal, &in.depth, &in.variance, &in.half_a, &in.half_b})
    TESSERA_CHECK(img->width() == w && img->height() == h);
  TESSERA_CHECK(in.color.channels() == 3 && in.depth.channels() == 1);
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  Image out;
  arena.execute([&] { out = denoise_in_arena(in, settings.mode); });
  return out;
}

}  // namespace tessera

// The denoiser (denoise/denoiser.h) on synthetic inputs with known answers: a converged image comes
// back unchanged, a noisy constant converges to the constant, a noisy step edge keeps its edge, the
// same bits for any thread count, nothing non-finite out; and its input checks.
#include "tessera/denoise/denoiser.h"
#include "tessera/scene/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>
#include <stdexcept>

namespace tessera {
namespace {

constexpr int kW = 64, kH = 48;

// An input whose true image is `truth(x, y)`, features flat unless `albedo` says otherwise, and
// each half the truth plus Gaussian noise of standard deviation `sigma` (the pixel's mean then has
// variance sigma² / 2).
DenoiseInput synthetic(const std::function<float(int, int)>& truth, float sigma, uint32_t seed,
                       const std::function<float(int, int)>& albedo = [](int, int) { return 0.5f; }) {
  DenoiseInput in;
  in.color = Image(kW, kH, 3);
  in.albedo = Image(kW, kH, 3);
  in.normal = Image(kW, kH, 3);
  in.depth = Image(kW, kH, 1);
  in.variance = Image(kW, kH, 3);
  in.half_a = Image(kW, kH, 3);
  in.half_b = Image(kW, kH, 3);
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, sigma);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      in.normal.at(x, y, 2) = 1.f;
      in.depth.at(x, y, 0) = 3.f;
      for (int c = 0; c < 3; ++c) {
        const float a = truth(x, y) + noise(rng), b = truth(x, y) + noise(rng);
        in.half_a.at(x, y, c) = a;
        in.half_b.at(x, y, c) = b;
        in.color.at(x, y, c) = 0.5f * (a + b);
        in.variance.at(x, y, c) = 0.5f * sigma * sigma;
        in.albedo.at(x, y, c) = albedo(x, y);
      }
    }
  return in;
}

double mse(const Image& img, const std::function<float(int, int)>& truth) {
  double s = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c) s += std::pow(img.at(x, y, c) - truth(x, y), 2);
  return s / (kW * kH * 3);
}

TEST(Denoiser, ConvergedImageComesBackUnchanged) {
  // Smooth shading and a texture; no noise: both halves are the image, the variance 0.
  const auto truth = [](int x, int y) { return 0.2f + 0.01f * float(x) + 0.3f * float((x / 5 + y / 7) % 2); };
  const DenoiseInput in = synthetic(truth, 0.f, 1);
  const Image out = denoise(in);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(out.at(x, y, c), in.color.at(x, y, c), 1e-6f) << x << "," << y;
}

TEST(Denoiser, NoisyConstantConvergesToTheConstant) {
  const auto truth = [](int, int) { return 0.5f; };
  for (float sigma : {0.05f, 0.2f}) {
    const DenoiseInput in = synthetic(truth, sigma, 2);
    const Image out = denoise(in);
    const double raw = mse(in.color, truth), denoised = mse(out, truth);
    EXPECT_LT(denoised, raw / 20) << "sigma " << sigma;
    double mean = 0;
    for (float v : out.values()) mean += v;
    EXPECT_NEAR(mean / double(out.values().size()), 0.5, 0.01);
  }
}

TEST(Denoiser, NoisyStepEdgeKeepsItsEdge) {
  // A step of the colour alone (features flat) and one the albedo also has.
  const auto truth = [](int x, int) { return x < kW / 2 ? 0.2f : 0.8f; };
  for (bool in_albedo : {false, true}) {
    const auto albedo = [&](int x, int y) { return in_albedo ? truth(x, y) : 0.5f; };
    const DenoiseInput in = synthetic(truth, 0.1f, 3, albedo);
    const Image out = denoise(in);
    EXPECT_LT(mse(out, truth), mse(in.color, truth) / 4) << "albedo step " << in_albedo;
    // The two columns beside the edge: their mean error stays well below the step (0.6).
    for (int x : {kW / 2 - 1, kW / 2}) {
      double err = 0;
      for (int y = 0; y < kH; ++y) err += std::abs(out.at(x, y, 1) - truth(x, y));
      EXPECT_LT(err / kH, 0.05) << "column " << x << ", albedo step " << in_albedo;
    }
  }
}

TEST(Denoiser, SameBitsForAnyThreadCountAndModes) {
  const auto truth = [](int x, int y) { return 0.3f + 0.2f * std::sin(0.2f * float(x)) * std::cos(0.3f * float(y)); };
  const DenoiseInput in = synthetic(truth, 0.1f, 4);
  for (DenoiseMode mode : {DenoiseMode::Full, DenoiseMode::Preview}) {
    DenoiseSettings one{mode, 1}, two{mode, 2};
    const Image a = denoise(in, one), b = denoise(in, two);
    EXPECT_EQ(a.values(), b.values());
    EXPECT_LT(mse(a, truth), mse(in.color, truth) / 4);
  }
}

TEST(Denoiser, NonFiniteInputGivesFiniteOutput) {
  const auto truth = [](int, int) { return 0.5f; };
  DenoiseInput in = synthetic(truth, 0.1f, 5);
  in.color.at(10, 10, 0) = std::nanf("");
  in.half_a.at(10, 10, 0) = std::numeric_limits<float>::infinity();
  in.variance.at(20, 20, 1) = std::nanf("");
  in.depth.at(30, 30, 0) = std::numeric_limits<float>::infinity();
  const Image out = denoise(in);
  for (float v : out.values()) ASSERT_TRUE(std::isfinite(v));
  // The damaged pixel does not spoil its neighbours.
  EXPECT_NEAR(out.at(12, 10, 0), 0.5f, 0.1f);
}

TEST(Denoiser, InputNamesMissingLayersAndRefusesOtherSizes) {
  const DenoiseInput in = synthetic([](int, int) { return 0.5f; }, 0.1f, 6);
  const std::string path = (std::filesystem::temp_directory_path() / "tessera_denoise_missing.exr").string();
  write_exr_layers(path, in.color, {{"albedo", {"R", "G", "B"}, in.albedo}, {"depth", {"Z"}, in.depth}});
  try {
    read_denoise_input(path);
    FAIL() << "no error";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("missing: normal, variance, half_a, half_b"), std::string::npos) << msg;
  }
  std::filesystem::remove(path);

  std::vector<ImageLayer> layers;
  for (AovLayer l : denoise_layers()) {
    Image img(kW, l == AovLayer::HalfB ? kH - 1 : kH, l == AovLayer::Depth ? 1 : 3);
    layers.push_back({aov_layer_name(l), aov_channel_names(l), img});
  }
  try {
    make_denoise_input(in.color, layers);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'half_b' is 64x47, the image 64x48"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera

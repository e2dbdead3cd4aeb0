// The denoiser on shared scenes at 16 spp, their references' resolution: the relMSE against
// ../shared/references/ falls several-fold and the channel means stay within max(1%, 3 standard
// errors) of the raw image's (a denoiser must not shift energy).
#include "test_support.h"
#include "tessera/denoise/denoiser.h"
#include "tessera/image/image_compare.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

void expect_denoised_better(const std::string& name, int width, int height, double min_gain) {
  const std::string scene_path = test::shared_path("scenes/" + name + "/scene.xml");
  const std::string ref_path = test::shared_path("references/" + name + "/reference.exr");
  TESSERA_REQUIRE_FILE(scene_path);
  TESSERA_REQUIRE_FILE(ref_path);
  LoadOptions options;
  options.width = width;
  options.height = height;
  options.spp = 16;
  auto scene = load_scene(parse_scene_file(scene_path, {}), options).scene;
  RenderSettings s;
  s.spp = 16;
  s.seed = 1;
  s.aovs = true;
  const Film film = render(*scene, s);
  const Image raw = film.to_image();
  const Image denoised = denoise(make_denoise_input(raw, film.aov_layers(denoise_layers())));
  const Image ref = read_image(ref_path).to_rgb();
  const double e_raw = rel_mse(raw, ref), e_denoised = rel_mse(denoised, ref);
  std::printf("%s 16 spp: relMSE raw %.5g, denoised %.5g (%.1fx)\n", name.c_str(), e_raw, e_denoised, e_raw / e_denoised);
  EXPECT_LT(e_denoised * min_gain, e_raw) << name;

  // Channel means: the raw mean's standard error from the pixels' variances.
  const auto m_raw = channel_means(raw), m_denoised = channel_means(denoised);
  const Image var = film.variance_image();
  const double n = double(raw.num_pixels());
  for (int c = 0; c < 3; ++c) {
    double v = 0;
    for (size_t i = 0; i < raw.num_pixels(); ++i) v += var.values()[i * 3 + size_t(c)];
    const double se = std::sqrt(v) / n;
    EXPECT_LE(std::abs(m_denoised[size_t(c)] - m_raw[size_t(c)]), std::max(0.01 * m_raw[size_t(c)], 3 * se))
        << name << " channel " << c;
  }
}

TEST(DenoiseScenes, CornellBox) { expect_denoised_better("cornell-box", 256, 256, 8); }
TEST(DenoiseScenes, LivingRoom) { expect_denoised_better("living-room", 320, 180, 4); }

}  // namespace
}  // namespace tessera

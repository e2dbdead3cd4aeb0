// Every shared scene rendered at its reference's resolution with 16 spp, with the integrator its
// reference was rendered with (path; volpath for staircase2's medium): nothing unsupported, no
// NaN/Inf, and channel means close to Mitsuba 3's references (../shared/references/NAME). A missing
// reference fails the test.
//
// A channel mean passes when it is within 4 standard errors (from the film's own per-pixel
// variance: at 16 spp the mean is still noisy where rare paths carry much energy, as the kitchenette's
// sunlight through glass) plus a stated systematic allowance per scene: the references were rendered
// by Mitsuba 3, which had to substitute some models (APPROX items in each reference's README).
#include "tessera/image/image.h"
#include "tessera/image/image_compare.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

namespace tessera {
namespace {

struct ReferenceCase {
  const char* name;
  double systematic;  // relative allowance per channel, beyond the noise
  const char* why;
  const char* integrator = "path";  // as in the reference's README ("Integrator as rendered")
};

void PrintTo(const ReferenceCase& c, std::ostream* os) { *os << c.name; }

class ReferenceScene : public ::testing::TestWithParam<ReferenceCase> {};

TEST_P(ReferenceScene, ChannelMeansMatchAt16spp) {
  const ReferenceCase& c = GetParam();
  const std::string scene_path = test::shared_path(std::string("scenes/") + c.name + "/scene.xml");
  const std::string ref_path = test::shared_path(std::string("references/") + c.name + "/reference.exr");
  TESSERA_REQUIRE_FILE(scene_path);
  if (!std::filesystem::exists(ref_path)) FAIL() << "reference missing: " << ref_path;
  Image ref = read_exr(ref_path).to_rgb();

  LoadOptions options;
  options.width = ref.width();
  options.height = ref.height();
  options.spp = 16;
  options.integrator = c.integrator;
  auto t0 = std::chrono::steady_clock::now();
  LoadResult loaded;
  try {
    loaded = load_scene(parse_scene_file(scene_path), options);
  } catch (const UnsupportedError& e) {
    FAIL() << e.what();
  }
  ASSERT_TRUE(loaded.scene);

  RenderSettings settings;
  settings.spp = 16;
  settings.seed = 1;
  RenderStats stats;
  Film film = render(*loaded.scene, settings, {}, &stats);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Image ours = film.to_image();
  EXPECT_EQ(stats.counters.nonfinite, 0u);
  EXPECT_EQ(count_non_finite(ours), 0u);

  // Standard error of the image mean: sqrt(sum of per-pixel variances of the mean) / pixels.
  double var_sum[3] = {0, 0, 0};
  const auto w = film.window();
  for (int y = w.y0; y < w.y1; ++y)
    for (int x = w.x0; x < w.x1; ++x) {
      Rgb v = film.sample_variance({x, y});
      double n = double(film.pixel({x, y}).count);
      for (int ch = 0; ch < 3; ++ch) var_sum[ch] += double(v[ch]) / n;
    }
  const double pixels = double(ours.width()) * double(ours.height());
  auto m = channel_means(ours);
  auto r = channel_means(ref);
  double se[3];
  for (int ch = 0; ch < 3; ++ch) {
    se[ch] = std::sqrt(var_sum[ch]) / pixels;
    EXPECT_NEAR(m[size_t(ch)], r[size_t(ch)], 4.0 * se[ch] + c.systematic * r[size_t(ch)])
        << "channel " << ch << " (standard error " << se[ch] << "; " << c.why << ")";
  }
  std::printf("%s %dx%d 16spp: %.2f s load+render, relMSE %.4f, means %.4f %.4f %.4f +- %.4f %.4f %.4f "
              "(ref %.4f %.4f %.4f)\n",
              c.name, ref.width(), ref.height(), seconds, rel_mse(ours, ref), m[0], m[1], m[2], se[0], se[1], se[2],
              r[0], r[1], r[2]);
}

INSTANTIATE_TEST_SUITE_P(
    All, ReferenceScene,
    ::testing::Values(
        ReferenceCase{"cornell-box", 0.005, "same models"},
        ReferenceCase{"veach-mis", 0.005, "same models"},
        ReferenceCase{"veach-bidir", 0.005, "same models"},
        ReferenceCase{"living-room", 0.02, "reference: Oren-Nayar replaced by Lambert, MIP maps by bilinear"},
        ReferenceCase{"bathroom", 0.01, "reference: MIP maps replaced by bilinear lookups"},
        ReferenceCase{"kitchenette", 0.03, "reference: phong replaced by roughplastic"},
        ReferenceCase{"staircase2", 0.01, "reference: MIP maps replaced by bilinear lookups", "volpath"}),
    [](const auto& info) {
      std::string n = info.param.name;
      for (char& ch : n)
        if (ch == '-') ch = '_';
      return n;
    });

}  // namespace
}  // namespace tessera

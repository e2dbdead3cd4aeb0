// The Cornell box from ../shared/scenes rendered at the reference's 256x256 must match Mitsuba 3's
// reference (../shared/references/cornell-box): relMSE, channel means and a per-pixel z test.
#include "tessera/image/image.h"
#include "tessera/image/image_compare.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

TEST(CornellBox, MatchesMitsubaReferenceAt256spp) {
  const std::string scene_path = test::shared_path("scenes/cornell-box/scene.xml");
  const std::string ref_dir = test::shared_path("references/cornell-box/");
  TESSERA_REQUIRE_FILE(scene_path);
  TESSERA_REQUIRE_FILE(ref_dir + "reference.exr");
  TESSERA_REQUIRE_FILE(ref_dir + "variance.exr");

  LoadOptions options;  // no allow_unsupported: the Cornell box must load cleanly
  options.width = 256;
  options.height = 256;
  options.spp = 256;
  LoadResult loaded = load_scene(parse_scene_file(scene_path), options);
  ASSERT_TRUE(loaded.unsupported.empty());

  RenderSettings settings;
  settings.spp = 256;
  settings.seed = 1;
  RenderStats stats;
  Film film = render(*loaded.scene, settings, {}, &stats);
  EXPECT_EQ(stats.counters.nonfinite, 0u);

  Image ours = film.to_image();
  Image ref = read_exr(ref_dir + "reference.exr").to_rgb();
  Image ref_var = read_exr(ref_dir + "variance.exr").to_rgb();
  ASSERT_EQ(ours.width(), ref.width());
  ASSERT_EQ(ours.height(), ref.height());

  double err = rel_mse(ours, ref);
  EXPECT_LT(err, 0.003) << "relMSE against the Mitsuba 3 reference";

  auto ours_mean = channel_means(ours);
  auto ref_mean = channel_means(ref);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(ours_mean[size_t(c)], ref_mean[size_t(c)], 0.01 * ref_mean[size_t(c)]) << "channel " << c;

  // Per pixel: our own per-pixel variance of the mean plus the reference's. Averaging 4x4 blocks
  // makes the z scores close to normal; a bias anywhere (wrong light, mirrored image, a leak)
  // gives |z| >> 4 over whole regions.
  Image var = downsample_variance(film.variance_image(), 4);
  ZScoreStats z = z_score_stats(downsample(ours, 4), downsample(ref, 4), downsample_variance(ref_var, 4), &var);
  EXPECT_LT(std::abs(z.mean_z), 0.2);
  EXPECT_LT(z.mean_z2, 2.0);
  EXPECT_LT(z.frac_above_4, 0.01);
  std::printf("cornell-box 256spp: relMSE %.5f, means %.5f %.5f %.5f (ref %.5f %.5f %.5f), z: mean %.3f "
              "mean2 %.3f >4: %.4f, %.2f s\n",
              err, ours_mean[0], ours_mean[1], ours_mean[2], ref_mean[0], ref_mean[1], ref_mean[2], z.mean_z,
              z.mean_z2, z.frac_above_4, stats.seconds);
}

}  // namespace
}  // namespace tessera

// Adaptive sampling on the farm: passes that adapt open at their barriers with counts decided from
// the coordinator's film, leases carry each tile's counts, and the stitched image is bit for bit
// render()'s with adaptive sampling, for any order of results and across restarts.
#include "coordinator_fixture.h"
#include "job_state.h"
#include "tessera/image/image.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <random>

namespace tessera::test {
namespace {

using nlohmann::json;
using server::Coordinator;
using server::JobState;

// 40 spp: passes 1, 2, 4, 8, 16, 9 beginning at 0, 1, 3, 7, 15, 31; those beginning at a quarter
// of the budget or later (15, 31) adapt.
constexpr int kSpp = 40;

LoadResult load_fixture_scene() { return load_scene(parse_scene_string(kXml, "scene.xml"), LoadOptions{}); }

Film local_adaptive_render(const Scene& scene, uint32_t seed) {
  RenderSettings rs;
  rs.spp = kSpp;
  rs.seed = seed;
  rs.tile_size = 5;  // not the job's
  rs.adaptive = true;
  return render(scene, rs);
}

FilmTile render_job_unit(const Scene& scene, const JobState& job, size_t u, uint32_t seed) {
  FilmTile tile;
  if (std::optional<PassSamples> s = job.lease_samples(u)) render_tile(scene, job.rect(u), *s, seed, tile);
  else render_tile(scene, job.rect(u), job.sample_begin(u), job.sample_end(u), seed, tile);
  return tile;
}

TEST(AdaptiveJob, UnitsInAnyOrderStitchToTheLocalAdaptiveRender) {
  LoadResult loaded = load_fixture_scene();
  const Scene& scene = *loaded.scene;
  JobPlan plan = plan_for(scene, kSpp, 8, 6);
  plan.settings.adaptive = true;
  JobState job(1, plan, "adaptive", 0, 0);
  ASSERT_EQ(job.num_passes(), 6u);

  std::mt19937 rng(3);
  std::vector<uint32_t> decided;
  uint64_t samples = 0;
  while (true) {
    // Everything leasable now, delivered in a random order.
    std::vector<size_t> open;
    while (std::optional<size_t> u = job.next_unit()) {
      open.push_back(*u);
      job.lease_started(*u);
    }
    if (open.empty()) break;
    const uint32_t newest = job.pass_of(open.back());
    for (size_t u : open) EXPECT_EQ(job.pass_of(u) < 4, newest < 4) << "an adaptive pass opened before its barrier";
    std::shuffle(open.begin(), open.end(), rng);
    for (size_t u : open) {
      FilmTile tile = render_job_unit(scene, job, u, 6);
      if (job.pass_of(u) >= 4) {
        EXPECT_TRUE(job.lease_samples(u).has_value());
        FilmTile uniform;
        render_tile(scene, job.rect(u), job.sample_begin(u), job.sample_end(u), 6, uniform);
        EXPECT_FALSE(job.result_fits(u, uniform)) << "a uniform result of an adaptive pass must not fit";
      }
      ASSERT_TRUE(job.result_fits(u, tile));
      samples += tile.counters.samples;
      job.lease_ended(u);
      ASSERT_TRUE(job.add_result(u, std::move(tile), 1));
      EXPECT_EQ(job.done_samples(), samples) << "progress counts the samples taken";
    }
    for (const PassSequencer::DecidedPass& d : job.take_new_plans()) decided.push_back(d.pass);
  }
  EXPECT_EQ(decided, (std::vector<uint32_t>{4, 5}));
  ASSERT_TRUE(job.complete());
  EXPECT_EQ(samples, uint64_t(scene.film.width) * uint64_t(scene.film.height) * kSpp) << "--spp is the total";
  EXPECT_EQ(differing(job.film(), local_adaptive_render(scene, 6)), 0);
}

// A coordinator stopped and started again every few results (its film rebuilt from checkpoints
// that may hold passes after a barrier) still decides the same counts.
TEST(AdaptiveJob, RestartsAtAnyPointGiveTheLocalAdaptiveImage) {
  TempDir dir;
  LoadResult loaded = load_fixture_scene();
  const json settings = {{"tile_size", 8}, {"seed", 9}, {"spp", kSpp}, {"adaptive", true}};
  int restarts = 0, adaptive_leases = 0;
  const uint64_t id = render_with_restarts(dir, settings, bundle(), [&](Coordinator&, const json& l) {
    adaptive_leases += l.contains("count");
    return render_unit(l, *loaded.scene, 9);
  }, restarts);
  Coordinator c(options(dir));
  ASSERT_EQ(c.job_status(id).value.state, "done");
  EXPECT_GT(restarts, 5);
  EXPECT_EQ(adaptive_leases, 2 * 2 * 3) << "the two adaptive passes of 2 x 3 tiles carry their counts";
  const Image farm = pfm_image(c.job_image(id, "pfm").value.bytes);
  const Image local = local_adaptive_render(*loaded.scene, 9).to_image();
  ASSERT_EQ(farm.values().size(), local.values().size());
  EXPECT_TRUE(std::memcmp(farm.values().data(), local.values().data(), local.values().size() * sizeof(float)) == 0);
}

TEST(AdaptiveJob, AResultWithOtherCountsIsRefused) {
  TempDir dir;
  LoadResult loaded = load_fixture_scene();
  Coordinator c(options(dir));
  const uint64_t worker = add_worker(c, "w");
  ASSERT_TRUE(submit(c, json{{"tile_size", 8}, {"seed", 1}, {"spp", kSpp}, {"adaptive", true}}, bundle()).ok());
  for (;;) {
    json l = lease_json(c.lease(worker, 0));
    ASSERT_TRUE(l.is_object()) << "the job ended without an adaptive lease";
    if (l.contains("count")) {
      json uniform = l;  // the same unit rendered without its counts
      uniform.erase("first");
      uniform.erase("count");
      auto up = c.upload_result(worker, l["id"], render_unit(uniform, *loaded.scene, 1));
      EXPECT_EQ(up.status.code, server::Code::BadRequest);
      EXPECT_NE(up.status.detail.find("sample counts"), std::string::npos) << up.status.detail;
      EXPECT_TRUE(c.upload_result(worker, l["id"], render_unit(l, *loaded.scene, 1)).ok());
      return;
    }
    ASSERT_TRUE(c.upload_result(worker, l["id"], render_unit(l, *loaded.scene, 1)).ok());
  }
}

}  // namespace
}  // namespace tessera::test

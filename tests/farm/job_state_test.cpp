// The coordinator's stitching: tile passes delivered in any order, duplicated, from any worker,
// give the film `render()` gives, bit for bit.
#include "job_state.h"
#include "tessera/farm/job_scene.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

namespace tessera::server {
namespace {

constexpr const char* kScene = R"(<scene version="0.6.0">
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="toWorld"><lookat origin="0,1,-3" target="0,0.5,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="13"/></sampler>
    <film type="hdrfilm"><integer name="width" value="29"/><integer name="height" value="17"/></film>
  </sensor>
  <shape type="sphere"><point name="center" x="0" y="0.5" z="0"/><float name="radius" value="0.5"/></shape>
  <shape type="rectangle"><transform name="toWorld"><rotate x="1" angle="-90"/><scale value="4"/></transform></shape>
  <emitter type="constant"><rgb name="radiance" value="1,0.9,0.8"/></emitter>
</scene>)";

TEST(JobState, OutOfOrderDuplicatedPassesStitchToTheLocalRender) {
  LoadResult loaded = load_scene(parse_scene_string(kScene, "job_state_test.xml"), LoadOptions{});
  const Scene& scene = *loaded.scene;
  JobPlan plan;
  plan.settings.spp = 13;  // passes 1, 2, 4, 6
  plan.settings.tile_size = 8;
  plan.settings.seed = 5;
  plan.window = film_window(scene.film);
  plan.full_width = scene.film.width;
  plan.full_height = scene.film.height;
  JobState job(1, plan, "test", 0, 0);
  EXPECT_FALSE(job.film_allocated()) << "a queued job holds no film";
  EXPECT_EQ(job.image().width(), 29) << "its image is black until results arrive";
  ASSERT_EQ(job.num_passes(), 4u);
  ASSERT_EQ(job.num_tiles(), 4u * 3u);

  // Pass-major leasing: the first units are every tile's first pass.
  for (size_t u = 0; u < job.num_tiles(); ++u) {
    std::optional<size_t> next = job.next_unit();
    ASSERT_TRUE(next);
    EXPECT_EQ(job.pass_of(*next), 0u);
    job.lease_started(*next);
  }
  EXPECT_EQ(job.pass_of(*job.next_unit()), 1u);

  std::vector<size_t> order(job.num_units());
  for (size_t u = 0; u < order.size(); ++u) order[u] = u;
  std::shuffle(order.begin(), order.end(), std::mt19937(17));
  order.insert(order.begin() + 5, order[9]);  // a late duplicate of a unit delivered later
  order.push_back(order[2]);                  // and one of a unit delivered earlier
  int duplicates = 0;
  for (size_t u : order) {
    FilmTile tile;
    render_tile(scene, job.rect(u), job.sample_begin(u), job.sample_end(u), plan.settings.seed, tile);
    duplicates += !job.add_result(u, std::move(tile), u % 3);
    EXPECT_TRUE(job.film_allocated());
  }
  EXPECT_EQ(duplicates, 2);
  EXPECT_EQ(job.duplicates, 2u);
  EXPECT_EQ(job.done_units(), job.num_units());
  EXPECT_FALSE(job.next_unit());

  RenderSettings rs;
  rs.spp = 13;
  rs.seed = 5;
  rs.tile_size = 5;
  Film local = render(scene, rs);
  int64_t differing = 0;
  for (int y = 0; y < scene.film.height; ++y)
    for (int x = 0; x < scene.film.width; ++x)
      differing += std::memcmp(&local.pixel({x, y}), &job.film().pixel({x, y}), sizeof(PixelSums)) != 0;
  EXPECT_EQ(differing, 0);
  uint64_t by_workers = 0;
  for (auto& [w, s] : job.samples_by_worker()) by_workers += s;
  EXPECT_EQ(by_workers, job.total_samples());
  EXPECT_EQ(job.done_samples(), uint64_t(29 * 17 * 13));
}

TEST(JobState, PhaseNamesRoundTrip) {
  for (JobPhase p : {JobPhase::Queued, JobPhase::Running, JobPhase::Done, JobPhase::Failed, JobPhase::Cancelled}) {
    JobPhase back;
    ASSERT_TRUE(parse_phase(phase_name(p), back));
    EXPECT_EQ(back, p);
  }
  JobPhase x;
  EXPECT_FALSE(parse_phase("paused", x));
}

}  // namespace
}  // namespace tessera::server

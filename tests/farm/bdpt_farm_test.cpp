// Bidirectional path tracing and light tracing on the farm: a job's Tile units and its light
// paths' units (ranges of paths whose splats come back sparse) give `tessera render`'s image bit
// for bit, also when a worker is killed mid-job and when the coordinator is restarted.
#include "farm_harness.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <thread>

namespace tessera::test {
namespace {

JobSettings bdpt_settings(const std::string& integrator) {
  JobSettings s;
  s.integrator = integrator;
  s.spp = 16;
  s.width = 48;
  s.height = 48;
  s.tile_size = 16;
  s.seed = 5;
  return s;
}

TEST(BdptFarm, TwoWorkersGiveTheLocalImage) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  farm.add_worker(1);
  farm.add_worker(1);
  for (const char* integrator : {"bdpt", "ptracer"}) {
    const JobSettings s = bdpt_settings(integrator);
    const uint64_t id = farm.submit(cornell(), s);
    ASSERT_GT(id, 0u) << integrator;
    const nlohmann::json st = farm.wait_job(id, 200);
    ASSERT_EQ(st.value("state", ""), "done") << st.dump();
    EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), s)), 0) << integrator;
  }
}

// A distant light's light subpaths start through the emission portal that each worker finds for
// itself (render/emission_portal.h): the same boxes everywhere, so the same bits.
TEST(BdptFarm, AnEnvironmentThroughAnEmissionPortalGivesTheLocalImage) {
  const std::string scene = shared_path("scenes/living-room/scene.xml");
  TESSERA_REQUIRE_FILE(scene);
  const JobSettings s = bdpt_settings("bdpt");
  {
    const auto abs = std::filesystem::absolute(scene);
    const LoadedJobScene local = load_job_scene(abs.parent_path().string(), abs.filename().string(), s, false);
    ASSERT_GT(local.loaded.scene->emission_portal().box_count(), 0) << "the scene's env light starts through a portal";
  }
  Farm farm;
  farm.start_server();
  farm.add_worker(1);
  farm.add_worker(1);
  const uint64_t id = farm.submit(scene, s);
  ASSERT_GT(id, 0u);
  const nlohmann::json st = farm.wait_job(id, 200);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump();
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(scene, s)), 0);
}

TEST(BdptFarm, KilledWorkerAndRestartedCoordinatorKeepTheBits) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  farm.add_worker(1);
  JobSettings s = bdpt_settings("bdpt");
  s.spp = 256;
  const uint64_t id = farm.submit(cornell(), s);
  ASSERT_GT(id, 0u);
  const nlohmann::json running =
      farm.wait_until(id, [](const nlohmann::json& j) { return j.value("progress", 0.0) > 0.2; }, 120);
  ASSERT_EQ(running.value("state", ""), "running") << "killed in the middle of the job: " << running.dump();
  farm.worker(0).kill_now();
  farm.kill_server();
  farm.start_server();
  farm.add_worker(1);
  const nlohmann::json st = farm.wait_job(id, 200);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump();
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), s)), 0);
}

TEST(BdptFarm, ARenderThatNeedsAPixelsOwnNoiseIsRefused) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  JobSettings s = bdpt_settings("bdpt");
  s.adaptive = true;
  client::HttpReply reply;
  EXPECT_EQ(farm.submit(cornell(), s, &reply), 0u);
  EXPECT_NE(reply.body.find("adaptive"), std::string::npos) << reply.body;
}

}  // namespace
}  // namespace tessera::test

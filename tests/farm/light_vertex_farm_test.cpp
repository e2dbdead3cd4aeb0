// Photon mapping (sppm) and vertex connection and merging (vcm) on the farm: photon and light
// vertex passes in units whose records the coordinator joins into each pass's map (a hashed
// artifact), sppm's per-pixel state carried from gather to gather in leases, results and
// checkpoints. The image is `tessera render`'s bit for bit, with two workers and after kill -9
// of a worker and the coordinator between photon passes.
#include "farm_harness.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace tessera::test {
namespace {

// A closed box lit by a small sphere, with a glass ball whose caustic needs the photons.
constexpr const char* kCausticBox = R"(<scene version="0.6.0">
  <integrator type="sppm"><integer name="maxDepth" value="6"/><integer name="photonCount" value="6000"/></integrator>
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="toWorld"><lookat origin="0,1.1,1.4" target="0,0.6,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="40"/><integer name="height" value="36"/></film></sensor>
  <shape type="cube"><transform name="toWorld"><scale x="1.5" y="1.2" z="1.5"/><translate y="1.1"/></transform>
    <bsdf type="twosided"><bsdf type="diffuse"><rgb name="reflectance" value="0.6,0.5,0.4"/></bsdf></bsdf></shape>
  <shape type="sphere"><point name="center" x="0" y="0.45" z="0"/><float name="radius" value="0.35"/>
    <bsdf type="dielectric"/></shape>
  <shape type="sphere"><point name="center" x="0.3" y="2.0" z="-0.2"/><float name="radius" value="0.06"/>
    <emitter type="area"><rgb name="radiance" value="300,280,250"/></emitter></shape>
</scene>)";

std::string write_scene(const TempDir& dir) {
  const std::string path = (dir.path / "scene.xml").string();
  std::ofstream(path) << kCausticBox;
  return path;
}

JobSettings light_vertex_settings(const std::string& integrator, int spp) {
  JobSettings s;
  s.integrator = integrator;  // ("" keeps the scene's sppm)
  s.spp = spp;
  s.tile_size = 16;
  s.seed = 9;
  return s;
}

TEST(LightVertexFarm, TwoWorkersGiveTheLocalImage) {
  TempDir dir;
  const std::string scene = write_scene(dir);
  Farm farm;
  farm.start_server();
  farm.add_worker(1);
  farm.add_worker(1);
  for (const char* integrator : {"", "vcm"}) {
    const JobSettings s = light_vertex_settings(integrator, 5);
    const uint64_t id = farm.submit(scene, s);
    ASSERT_GT(id, 0u) << integrator;
    const nlohmann::json st = farm.wait_job(id, 200);
    ASSERT_EQ(st.value("state", ""), "done") << st.dump();
    ASSERT_TRUE(st["point_map"].is_object()) << st.dump();
    EXPECT_EQ(st["point_map"].value("iterations", 0), 5) << "a map per pass";
    EXPECT_GT(st["point_map"].value("bytes", 0), 0);
    const Image local = local_render(scene, s);
    EXPECT_EQ(differing_pixels(farm.image(id), local), 0) << (*integrator ? integrator : "sppm");
    double sum = 0;
    for (float v : local.values()) sum += v;
    EXPECT_GT(sum, 0.0) << "a lit image";
  }
}

TEST(LightVertexFarm, KilledWorkerAndCoordinatorBetweenPhotonPassesKeepTheBits) {
  TempDir dir;
  const std::string scene = write_scene(dir);
  Farm farm;
  farm.start_server();
  farm.add_worker(1);
  const JobSettings s = light_vertex_settings("", 40);
  const uint64_t id = farm.submit(scene, s);
  ASSERT_GT(id, 0u);
  const nlohmann::json running =
      farm.wait_until(id, [](const nlohmann::json& j) { return j.value("progress", 0.0) > 0.3; }, 200);
  ASSERT_EQ(running.value("state", ""), "running") << "killed in the middle of the job: " << running.dump();
  farm.worker(0).kill_now();
  farm.kill_server();
  farm.start_server();
  farm.add_worker(1);
  const nlohmann::json st = farm.wait_job(id, 300);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump();
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(scene, s)), 0);
  // A photon map no pass gathers from any more is deleted (those spent before the restart, whose
  // write times went with it, wait for retention).
  size_t maps = 0;
  for (const auto& entry : std::filesystem::directory_iterator(farm.data_dir() / "guides")) maps += entry.is_regular_file();
  EXPECT_LT(maps, 30u) << "of 40 photon maps";
}

TEST(LightVertexFarm, SettingsOnlyThePathTracerHasAreRefused) {
  TempDir dir;
  const std::string scene = write_scene(dir);
  Farm farm;
  farm.start_server();
  JobSettings s = light_vertex_settings("", 4);
  s.adaptive = true;
  client::HttpReply reply;
  EXPECT_EQ(farm.submit(scene, s, &reply), 0u);
  EXPECT_NE(reply.body.find("adaptive sampling needs the path tracer"), std::string::npos) << reply.body;
}

}  // namespace
}  // namespace tessera::test

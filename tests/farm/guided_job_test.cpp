// Path guiding on the farm: the coordinator makes each training pass's tree from every tile's
// training records, hands it out as a hashed guide, and the stitched image is bit for bit
// render()'s with guiding, for any order of results and across restarts.
#include "coordinator_fixture.h"
#include "job_state.h"
#include "tessera/sequence/guide_artifact.h"
#include "tessera/farm/sha256.h"
#include "tessera/image/image.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <map>
#include <random>

namespace tessera::test {
namespace {

using nlohmann::json;
using server::Coordinator;
using server::JobState;

// 24 spp: iterations of 1, 2, 4 and 17 samples (passes 1, 2, 4, 17); the first three train.
constexpr int kSpp = 24;

// A room lit by a small sphere and the sky through its open side, guided by its integrator with a
// fixed BSDF fraction (so every learned tree shows in the image).
constexpr const char* kGuidedXml = R"(<scene version="0.6.0">
  <integrator type="guided_path"><integer name="maxDepth" value="6"/>
    <string name="budgetType" value="spp"/><float name="budget" value="24"/>
    <string name="sampleCombination" value="discard"/><string name="bsdfSamplingFractionLoss" value="none"/>
  </integrator>
  <sensor type="perspective"><float name="fov" value="60"/>
    <transform name="toWorld"><lookat origin="0,1,-2.5" target="0,0.8,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="20"/><integer name="height" value="12"/></film>
  </sensor>
  <shape type="rectangle"><transform name="toWorld"><rotate x="1" angle="-90"/><scale value="3"/></transform></shape>
  <shape type="rectangle"><transform name="toWorld"><scale value="3"/><translate z="2"/></transform></shape>
  <shape type="sphere"><point name="center" x="0.6" y="0.5" z="0.5"/><float name="radius" value="0.4"/></shape>
  <shape type="sphere"><point name="center" x="-1" y="2" z="1.5"/><float name="radius" value="0.1"/>
    <emitter type="area"><rgb name="radiance" value="40,36,30"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.2,0.25,0.3"/></emitter>
</scene>)";

// The fixture with another sampleCombination ("inversevar": the last four iterations, a film each).
std::string guided_xml(const std::string& combination) {
  std::string xml = kGuidedXml;
  const std::string discard = "value=\"discard\"";
  return xml.replace(xml.find(discard), discard.size(), "value=\"" + combination + "\"");
}

// The fixture at 80 spp (iterations of 1, 2, 4, 8, 16 and 49 samples) with a least gain no guide
// reaches, decided by 100 paths: guiding steps aside after the iteration of 8, the iteration of 16
// trains nothing, and both render unguided.
constexpr int kAsideSpp = 80;
std::string stepping_aside_xml(const std::string& combination = "inversevar") {
  std::string xml = guided_xml(combination);
  const std::string budget = "<float name=\"budget\" value=\"24\"/>";
  return xml.replace(xml.find(budget), budget.size(),
                     "<float name=\"budget\" value=\"80\"/><float name=\"min_gain\" value=\"1000\"/>"
                     "<integer name=\"gain_paths\" value=\"100\"/>");
}

LoadResult load_fixture_scene(const std::string& xml = guided_xml("discard")) {
  return load_scene(parse_scene_string(xml, "scene.xml"), LoadOptions{});
}

std::string guided_bundle(const std::string& xml) {
  TempDir src;
  src.write("scene.xml", xml);
  return pack_bundle(src.path.string(), {"scene.xml"});
}

Film local_guided_render(const Scene& scene, uint32_t seed, bool adaptive = false, int spp = kSpp) {
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = seed;
  rs.tile_size = 7;  // not the job's
  rs.guiding = true;
  rs.guiding_settings = scene.integrator.guiding.value();
  rs.adaptive = adaptive;
  return render(scene, rs);
}

// What the coordinator and a worker do with a guide, in process: stored by its hash, decoded.
struct Guides {
  std::map<std::string, SpatialTree> by_hash;
  void store_new(JobState& job) {
    while (auto made = job.take_artifact()) {
      const auto& tree = static_cast<const GuideArtifact&>(*made->artifact).tree();
      const std::string bytes = made->artifact->encode(), hash = sha256_hex(bytes);
      std::string error;
      ASSERT_TRUE(decode_guide(bytes, by_hash[hash], error)) << error;
      EXPECT_TRUE(by_hash[hash] == tree) << "a guide decodes to the tree it encodes";
      job.artifact_stored(made->iteration, hash);
    }
  }
};

// Renders a guided job of `spp` as workers would, each pass's units in a shuffled order.
struct ShuffledJob {
  std::unique_ptr<JobState> job;
  int training_units = 0;
};
ShuffledJob render_shuffled(const Scene& scene, int spp) {
  JobPlan plan = plan_for(scene, spp, 8, 4);
  plan.guide = JobPlan::Guide{scene.bounds(), scene.integrator.guiding.value()};
  ShuffledJob out{std::make_unique<JobState>(1, plan, "guided", 0, 0)};
  JobState& job = *out.job;
  EXPECT_FALSE(job.next_unit()) << "nothing is leased before the first guide is stored";
  Guides guides;
  std::mt19937 rng(5);
  for (;;) {
    guides.store_new(job);
    std::vector<size_t> open;
    while (std::optional<size_t> u = job.next_unit()) {
      open.push_back(*u);
      job.lease_started(*u);
    }
    if (open.empty()) break;
    std::shuffle(open.begin(), open.end(), rng);
    for (size_t u : open) {
      Lease lease;
      lease.rect = job.rect(u);
      lease.sample_begin = job.sample_begin(u);
      lease.sample_end = job.sample_end(u);
      lease.settings.seed = 4;
      lease.guide = job.lease_guide(u);
      EXPECT_TRUE(lease.guide) << "every pass of a guided job samples or trains";
      if (!lease.guide) return out;
      TileResult r = render_lease(scene, lease, &guides.by_hash.at(lease.guide->hash));
      std::string error;
      EXPECT_FALSE(job.check_training(u, lease.guide->train ? "" : "junk", error)) << "pass " << job.pass_of(u);
      EXPECT_TRUE(job.check_training(u, r.training, error)) << error;
      out.training_units += lease.guide->train;
      job.lease_ended(u);
      EXPECT_TRUE(job.add_result(u, std::move(r.film), 1, r.training));
    }
  }
  EXPECT_TRUE(job.complete());
  return out;
}

TEST(GuidedJob, UnitsInAnyOrderStitchToTheLocalGuidedRender) {
  LoadResult loaded = load_fixture_scene();
  const Scene& scene = *loaded.scene;
  const ShuffledJob shuffled = render_shuffled(scene, kSpp);
  const JobState& job = *shuffled.job;
  ASSERT_TRUE(job.complete());
  EXPECT_EQ(job.guide_iterations(), 4u) << "the first tree and one after each of 3 training passes";
  EXPECT_EQ(shuffled.training_units, 3 * 6);
  const Film local = local_guided_render(scene, 4);
  EXPECT_EQ(differing(job.film(), local), 0);
  EXPECT_EQ(local.pixel({3, 3}).count, uint64_t(kSpp - 7)) << "the training passes are not in the image";
}

TEST(GuidedJob, AGuideThatStepsAsideStitchesToTheLocalRender) {
  LoadResult loaded = load_fixture_scene(stepping_aside_xml("discard"));
  const Scene& scene = *loaded.scene;
  const ShuffledJob shuffled = render_shuffled(scene, kAsideSpp);
  const JobState& job = *shuffled.job;
  ASSERT_TRUE(job.complete());
  ASSERT_TRUE(job.guide());
  EXPECT_TRUE(job.guide()->stepped_aside());
  EXPECT_GT(job.guide()->predicted_gain(), 0.f);
  EXPECT_EQ(differing(job.film(), local_guided_render(scene, 4, false, kAsideSpp)), 0);
}

// Renders a lease as a worker does, fetching its guide from the coordinator.
std::string render_guided_unit(Coordinator& c, const json& lease_json, const Scene& scene, uint32_t seed) {
  Lease lease;
  std::string error;
  EXPECT_TRUE(lease_from_json(lease_json, lease, error)) << error;
  lease.settings.seed = seed;
  SpatialTree guide;
  if (lease.guide) {
    server::Result<server::StoredFile> file = c.guide_file(lease.guide->hash);
    EXPECT_TRUE(file.ok()) << file.status.detail;
    std::ifstream in(file.value.path, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    EXPECT_EQ(bytes.size(), file.value.size);
    EXPECT_EQ(sha256_hex(bytes), lease.guide->hash);
    EXPECT_TRUE(decode_guide(bytes, guide, error)) << error;
  }
  return encode_tile_result(render_lease(scene, lease, lease.guide ? &guide : nullptr));
}

// A coordinator stopped and started again every few results, in the middle of training (its
// tree rebuilt from the stored guide and the training records of the pass in progress), with
// adaptive sampling too.
void expect_restarts_give_the_local_image(const std::string& xml, int spp = kSpp) {
  TempDir dir;
  LoadResult loaded = load_fixture_scene(xml);
  const json settings = {{"tile_size", 8}, {"seed", 7}, {"spp", spp}, {"adaptive", true}};  // (guided: the scene says)
  int restarts = 0;
  const uint64_t id = render_with_restarts(dir, settings, guided_bundle(xml), [&](Coordinator& c, const json& l) {
    return render_guided_unit(c, l, *loaded.scene, 7);
  }, restarts);
  EXPECT_GT(restarts, 5);
  Coordinator c(options(dir));
  EXPECT_EQ(c.job_status(id).value.spp, spp);
  const Image farm = pfm_image(c.job_image(id, "pfm").value.bytes);
  const Image local = local_guided_render(*loaded.scene, 7, /*adaptive=*/true, spp).to_image();
  ASSERT_EQ(farm.values().size(), local.values().size());
  EXPECT_TRUE(std::memcmp(farm.values().data(), local.values().data(), local.values().size() * sizeof(float)) == 0);
}

TEST(GuidedJob, RestartsDuringTrainingGiveTheLocalGuidedImage) { expect_restarts_give_the_local_image(guided_xml("discard")); }

// The same with the image made of the last iterations' films, combined by inverse variance: each
// tile's checkpoint holds its sums in every film.
TEST(GuidedJob, RestartsGiveTheLocalImageOfCombinedIterations) {
  expect_restarts_give_the_local_image(guided_xml("inversevar"));
}

// And a job whose guide steps aside (as AGuideThatStepsAsideStitchesToTheLocalRender shows): the
// coordinator keeps the scene's least gain through restarts, and a restarted one reads from its
// latest tree where the films of one estimator begin.
TEST(GuidedJob, RestartsGiveTheLocalImageOfAGuideThatSteppedAside) {
  expect_restarts_give_the_local_image(stepping_aside_xml(), kAsideSpp);
}

}  // namespace
}  // namespace tessera::test

// Retention in-process: finished jobs expire by age or by the data dir's size, oldest first, with
// their results and image; bundles go once no job uses them; nothing of a queued or running job
// is touched; an expired job's status says so, across a restart too. The clock is the `now`
// passed to apply_retention, so nothing sleeps.
#include "coordinator_fixture.h"
#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/bundle.h"
#include "tessera/farm/job_scene.h"
#include "tessera/farm/tile_result.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "tessera/server/coordinator.h"
#include "test_support.h"

#include <chrono>
#include <filesystem>
#include <thread>

namespace tessera::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using server::Coordinator;
using server::CoordinatorOptions;

std::string scene_xml(double z) {
  return R"(<scene version="0.6.0">
  <sensor type="perspective"><float name="fov" value="45"/>
    <sampler type="independent"><integer name="sampleCount" value="3"/></sampler>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="8"/></film>
  </sensor>
  <shape type="sphere"><point name="center" x="0" y="0" z=")" +
         std::to_string(z) + R"("/></shape>
  <emitter type="constant"/>
</scene>)";
}

struct TestScene {
  explicit TestScene(double z) : xml(scene_xml(z)) {
    loaded = load_scene(parse_scene_file(src.write("scene.xml", xml)), LoadOptions{});
    bundle = pack_bundle(src.path.string(), {"scene.xml"});
  }
  TempDir src;
  std::string xml, bundle;
  LoadResult loaded;
};

double wall_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

CoordinatorOptions options(const TempDir& dir, double days, uint64_t bytes) {
  CoordinatorOptions o;
  o.data_dir = (dir.path / "data").string();
  o.retain_days = days;
  o.retain_bytes = bytes;
  o.maintenance_interval = 0;  // passes only when the test asks
  return o;
}

uint64_t add_worker(Coordinator& c) {
  const BuildFingerprint& fp = build_fingerprint();
  auto r = c.register_worker(WorkerHello{"w", 1, 0, fp.version, fp.isa, fp.probe});
  EXPECT_TRUE(r.ok()) << r.status.detail;
  return r.value.id;
}

// Leases and delivers units of whatever job is first; false when there was nothing to lease.
bool deliver_one(Coordinator& c, uint64_t worker, const TestScene& scene) {
  auto l = c.lease(worker, 0);
  EXPECT_TRUE(l.ok()) << l.status.detail;
  if (!l.value) return false;
  auto up = c.upload_result(worker, l.value->id, encode_tile_result(render_lease(*scene.loaded.scene, *l.value)));
  EXPECT_TRUE(up.ok()) << up.status.detail;
  return true;
}

uint64_t finished_job(Coordinator& c, uint64_t worker, const TestScene& scene, int seed) {
  auto job = submit(c, json{{"tile_size", 8}, {"seed", seed}}, scene.bundle);
  EXPECT_TRUE(job.ok()) << job.status.detail;
  const uint64_t id = job.ok() ? job.value.jobs.at(0).id : 0;
  while (deliver_one(c, worker, scene)) {
  }
  EXPECT_EQ(c.job_status(id).value.state, "done");
  return id;
}

std::string image_file(const TempDir& dir, uint64_t id) {
  return (dir.path / "data" / "images" / (std::to_string(id) + ".exr")).string();
}
std::string bundle_file(const TempDir& dir, const std::string& hash) {
  return (dir.path / "data" / "bundles" / (hash + ".bundle")).string();
}
std::string scene_hash(Coordinator& c, uint64_t id) { return c.job_status(id).value.settings.scene; }

void expect_expired(Coordinator& c, uint64_t id) {
  auto st = c.job_status(id);
  EXPECT_EQ(st.status.code, server::Code::NotFound);
  EXPECT_NE(st.status.detail.find("expired by retention"), std::string::npos) << st.status.detail;
  EXPECT_EQ(c.job_image(id, "exr").status.code, server::Code::NotFound);
}

TEST(Retention, AgeLimitDeletesFinishedJobsButNotRunningOnesNorTheirBundle) {
  TempDir dir;
  TestScene a(4), unused(6);
  uint64_t done = 0, running = 0, running_units = 0;
  std::string hash, unused_hash;
  {
    Coordinator c(options(dir, /*days=*/1, 0));
    const uint64_t w = add_worker(c);
    done = finished_job(c, w, a, 1);
    running = submit(c, json{{"tile_size", 8}, {"seed", 2}}, a.bundle).value.jobs.at(0).id;
    ASSERT_TRUE(deliver_one(c, w, a));
    running_units = c.job_status(running).value.units_done;
    ASSERT_EQ(c.job_status(running).value.state, "running");
    hash = scene_hash(c, done);
    ASSERT_EQ(scene_hash(c, running), hash) << "the same bundle bytes are stored once";
    unused_hash = c.upload_scene(unused.bundle).value.hash;
    ASSERT_TRUE(fs::exists(image_file(dir, done)));

    auto young = c.apply_retention(wall_now() + 0.5 * 86400);
    ASSERT_TRUE(young.ok()) << young.status.detail;
    EXPECT_EQ(young.value.deleted_jobs, 0u);
    EXPECT_EQ(young.value.deleted_bundles, 0u);
    EXPECT_EQ(c.job_status(done).value.state, "done");

    auto old = c.apply_retention(wall_now() + 2 * 86400);
    ASSERT_TRUE(old.ok()) << old.status.detail;
    EXPECT_EQ(old.value.deleted_jobs, 1u);
    EXPECT_EQ(old.value.deleted_bundles, 1u) << "the bundle no job used, uploaded over a day ago";
    expect_expired(c, done);
    EXPECT_FALSE(fs::exists(image_file(dir, done)));
    EXPECT_FALSE(fs::exists(bundle_file(dir, unused_hash)));
    // The running job and its bundle (shared with the deleted job) are untouched.
    json st = to_json(c.job_status(running).value);
    EXPECT_EQ(st["state"], "running");
    EXPECT_EQ(st["units_done"], running_units);
    EXPECT_TRUE(fs::exists(bundle_file(dir, hash)));
    EXPECT_TRUE(fs::exists(dir.path / "data" / "scenes" / hash));
    EXPECT_NE(c.metrics().find("tessera_retention_deleted_total{what=\"jobs\"} 1"), std::string::npos);
    EXPECT_EQ(c.list_jobs().value.size(), 1u);
    // It still renders to the end.
    while (deliver_one(c, w, a)) {
    }
    EXPECT_EQ(c.job_status(running).value.state, "done");
    EXPECT_TRUE(c.job_image(running, "exr").ok());
  }
  // The tombstone survives a restart; the job that ended just now is kept until it is old too.
  Coordinator again(options(dir, 1, 0));
  expect_expired(again, done);
  EXPECT_EQ(again.job_status(running).value.state, "done");
  auto later = again.apply_retention(wall_now() + 3 * 86400);
  ASSERT_TRUE(later.ok());
  EXPECT_EQ(later.value.deleted_jobs, 1u);
  EXPECT_EQ(later.value.deleted_bundles, 1u);
  expect_expired(again, running);
  EXPECT_FALSE(fs::exists(bundle_file(dir, hash)));
  EXPECT_FALSE(fs::exists(dir.path / "data" / "scenes" / hash));
  EXPECT_EQ(again.job_status(999).status.detail, "no job 999") << "an id that never existed is plain 404";
}

TEST(Retention, SizeLimitDeletesTheOldestFinishedJobsFirst) {
  TempDir dir;
  TestScene a(4), b(5);
  uint64_t first = 0, second = 0, third = 0, running = 0, total = 0;
  std::string hash_a, hash_b;
  {
    Coordinator c(options(dir, 0, 0));
    const uint64_t w = add_worker(c);
    first = finished_job(c, w, b, 1);  // the only user of bundle b
    second = finished_job(c, w, a, 2);
    third = finished_job(c, w, a, 3);
    running = submit(c, json{{"tile_size", 8}, {"seed", 4}}, a.bundle).value.jobs.at(0).id;
    ASSERT_TRUE(deliver_one(c, w, a));
    hash_a = scene_hash(c, second);
    hash_b = scene_hash(c, first);
    auto measured = c.apply_retention();
    ASSERT_TRUE(measured.ok());
    EXPECT_EQ(measured.value.deleted_jobs, 0u) << "no limits: nothing goes";
    total = measured.value.data_bytes;
    EXPECT_GT(total, 0u);
    EXPECT_NE(c.metrics().find("tessera_data_bytes " + std::to_string(total)), std::string::npos);
  }
  const double later = wall_now() + 3600;  // past the grace of freshly used bundles
  {
    Coordinator c(options(dir, 0, total - 1));
    auto r = c.apply_retention(later);
    ASSERT_TRUE(r.ok()) << r.status.detail;
    EXPECT_EQ(r.value.deleted_jobs, 1u) << "one job is enough to get under";
    expect_expired(c, first);
    EXPECT_EQ(c.job_status(second).value.state, "done");
    EXPECT_EQ(c.job_status(third).value.state, "done");
    EXPECT_LT(r.value.data_bytes, total);
  }
  Coordinator c(options(dir, 0, 1));
  const uint64_t units = c.job_status(running).value.units_done;
  auto r = c.apply_retention(later);
  ASSERT_TRUE(r.ok()) << r.status.detail;
  EXPECT_EQ(r.value.deleted_jobs, 2u);
  EXPECT_EQ(r.value.deleted_bundles, 1u) << "bundle b, unused now; bundle a is the running job's";
  expect_expired(c, second);
  expect_expired(c, third);
  EXPECT_FALSE(fs::exists(image_file(dir, third)));
  EXPECT_FALSE(fs::exists(bundle_file(dir, hash_b)));
  EXPECT_TRUE(fs::exists(bundle_file(dir, hash_a)));
  json st = to_json(c.job_status(running).value);
  EXPECT_EQ(st["state"], "running");
  EXPECT_EQ(st["units_done"], units);
  // What is left is the running job's: a second pass deletes nothing more.
  auto again = c.apply_retention(later);
  EXPECT_EQ(again.value.deleted_jobs, 0u);
  EXPECT_EQ(again.value.deleted_bundles, 0u);
  EXPECT_EQ(c.job_status(running).value.state, "running");
}

TEST(Retention, ARetriedJobIsNotFinishedAndIsKept) {
  TempDir dir;
  TestScene a(4);
  Coordinator c(options(dir, 1, 0));
  const uint64_t w = add_worker(c);
  const uint64_t id = submit(c, json{{"tile_size", 8}}, a.bundle).value.jobs.at(0).id;
  ASSERT_TRUE(deliver_one(c, w, a));
  ASSERT_TRUE(c.cancel_job(id).ok());
  ASSERT_TRUE(c.retry_job(id).ok());
  auto r = c.apply_retention(wall_now() + 10 * 86400);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value.deleted_jobs, 0u);
  EXPECT_EQ(c.job_status(id).value.state, "queued");
  EXPECT_EQ(c.job_status(id).value.units_done, 1);
}

// A guided job's artifacts (its guides, stored by hash and shared: the first tree of a scene is
// the same for every job of it) are deleted once no job names them.
TEST(Retention, ArtifactsGoOnceNoJobNamesThem) {
  TempDir dir, src;
  src.write("scene.xml", R"(<scene version="0.6.0"><integrator type="path"/>
    <sensor type="perspective"><sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
      <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="8"/></film></sensor>
    <shape type="rectangle"><transform name="toWorld"><translate z="3"/></transform></shape>
    <emitter type="constant"/></scene>)");
  const std::string bundle = pack_bundle(src.path.string(), {"scene.xml"});
  Coordinator c(options(dir, 1, 0));
  const json guided = {{"tile_size", 8}, {"guiding", true}};
  const uint64_t first = submit(c, guided, bundle).value.jobs.at(0).id;
  const uint64_t second = submit(c, guided, bundle).value.jobs.at(0).id;
  // Each job's first guide is stored in the background, before any of its units is leased.
  for (int i = 0; i < 500 && (c.job_status(first).value.guide.value_or(JobStatus::Guide{}).iterations == 0 ||
                              c.job_status(second).value.guide.value_or(JobStatus::Guide{}).iterations == 0);
       ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::vector<fs::path> guides;
  for (const auto& e : fs::directory_iterator(dir.path / "data" / "guides")) guides.push_back(e.path());
  ASSERT_EQ(guides.size(), 1u) << "both jobs render with the same first tree";
  // (A guide file younger than an hour may be one whose row is still being committed: kept.)
  fs::last_write_time(guides[0], fs::file_time_type::clock::now() - std::chrono::hours(2));
  ASSERT_TRUE(c.cancel_job(first).ok());
  ASSERT_EQ(c.apply_retention(wall_now() + 2 * 86400).value.deleted_jobs, 1u);
  EXPECT_TRUE(fs::exists(guides[0])) << "the second job still names it";
  ASSERT_TRUE(c.cancel_job(second).ok());
  ASSERT_EQ(c.apply_retention(wall_now() + 4 * 86400).value.deleted_jobs, 1u);
  EXPECT_FALSE(fs::exists(guides[0])) << "no job names it any more";
}

}  // namespace
}  // namespace tessera::test

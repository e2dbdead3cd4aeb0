// The coordinator's services in-process (no HTTP): exclusion of failing workers, job failure with
// the reason, and state that survives a restart.
#include "coordinator_fixture.h"

namespace tessera::test {
namespace {

using nlohmann::json;
using server::Coordinator;

TEST(Coordinator, FailingWorkersAreKeptOffAndThenTheJobFails) {
  TempDir dir;
  Coordinator c(options(dir));
  const uint64_t a = add_worker(c, "a"), b = add_worker(c, "b"), d = add_worker(c, "d");
  auto job = submit(c, json{{"tile_size", 8}}, bundle());
  ASSERT_TRUE(job.ok()) << job.status.detail;
  const uint64_t id = job.value.jobs.at(0).id;

  auto fail = [&](uint64_t worker) {
    auto l = c.lease(worker, 0);
    EXPECT_TRUE(l.ok());
    if (!l.value) return false;
    EXPECT_TRUE(c.fail_lease(worker, l.value->id, "no GPU on " + std::to_string(worker)).ok());
    return true;
  };
  ASSERT_TRUE(fail(a));
  ASSERT_TRUE(fail(a));
  EXPECT_TRUE(!c.lease(a, 0).value) << "worker a failed twice: kept off the job";
  EXPECT_TRUE(c.lease(b, 0).value.has_value()) << "others still get its work";
  ASSERT_TRUE(fail(d));
  EXPECT_EQ(c.job_status(id).value.state, "running");
  ASSERT_TRUE(fail(b));  // the third distinct worker
  json st = to_json(c.job_status(id).value);
  EXPECT_EQ(st["state"], "failed");
  EXPECT_NE(st.value("error", "").find("failed on 3 worker(s)"), std::string::npos) << st.dump();
  EXPECT_NE(st.value("error", "").find("no GPU"), std::string::npos) << st.dump();
  EXPECT_TRUE(!c.lease(b, 0).value);
  EXPECT_EQ(c.cancel_job(id).code, server::Code::Conflict);
}

TEST(Coordinator, StateSurvivesARestart) {
  TempDir dir;
  uint64_t id = 0, worker = 0;
  json before;
  {
    Coordinator c(options(dir));
    worker = add_worker(c, "w");
    auto job = submit(c, json{{"tile_size", 8}, {"name", "persist"}, {"seed", 4}}, bundle());
    ASSERT_TRUE(job.ok()) << job.status.detail;
    id = job.value.jobs.at(0).id;
    // Render and deliver three units for real, and leave one lease hanging.
    TempDir src;
    src.write("scene.xml", kXml);
    LoadResult loaded = load_scene(parse_scene_file(src.write("scene.xml", kXml)), LoadOptions{});
    for (int i = 0; i < 3; ++i) {
      nlohmann::json l = lease_json(c.lease(worker, 0));
      ASSERT_TRUE(l.is_object());
      TileResult r;
      r.job_id = id;
      r.tile = l["tile"];
      r.pass = l["pass"];
      r.sample_begin = l["sample_begin"];
      r.sample_end = l["sample_end"];
      auto rect = l["rect"].get<std::vector<int>>();
      render_tile(*loaded.scene, {rect[0], rect[1], rect[2], rect[3]}, r.sample_begin, r.sample_end, 4, r.film);
      auto up = c.upload_result(worker, l["id"], encode_tile_result(r));
      ASSERT_TRUE(up.ok()) << up.status.detail;
    }
    ASSERT_TRUE(c.lease(worker, 0).value.has_value());
    before = to_json(c.job_status(id).value);
  }
  Coordinator again(options(dir));
  json after = to_json(again.job_status(id).value);
  EXPECT_EQ(after["state"], "running");
  EXPECT_EQ(after["name"], "persist");
  EXPECT_EQ(after["units_done"], 3);
  EXPECT_EQ(after["units_done"], before["units_done"]);
  EXPECT_EQ(after["samples_done"], before["samples_done"]);
  // The worker is known after the restart, and the hanging lease's unit is available again.
  auto l = again.lease(worker, 0);
  ASSERT_TRUE(l.ok()) << l.status.detail;
  EXPECT_TRUE(l.value.has_value());
  EXPECT_EQ(again.job_status(id).value.reissued_acknowledged_passes, 0);
  EXPECT_EQ(again.list_jobs().value.size(), 1u);
}

TEST(Coordinator, FinishedJobIsServedFromItsImageAfterARestart) {
  TempDir dir;
  TempDir src;
  LoadResult loaded = load_scene(parse_scene_file(src.write("scene.xml", kXml)), LoadOptions{});
  uint64_t id = 0;
  std::string exr_before;
  {
    Coordinator c(options(dir));
    const uint64_t w = add_worker(c, "w");
    auto job = submit(c, json{{"tile_size", 8}, {"seed", 2}}, bundle());
    ASSERT_TRUE(job.ok()) << job.status.detail;
    id = job.value.jobs.at(0).id;
    while (deliver_one(c, w, *loaded.scene, 2)) {
    }
    EXPECT_EQ(c.job_status(id).value.state, "done");
    exr_before = c.job_image(id, "pfm").value.bytes;
  }
  Coordinator again(options(dir));
  json st = to_json(again.job_status(id).value);
  EXPECT_EQ(st["state"], "done");
  EXPECT_EQ(st["units_done"], st["units_total"]);
  auto image = again.job_image(id, "pfm");
  ASSERT_TRUE(image.ok()) << image.status.detail;
  EXPECT_EQ(image.value.bytes, exr_before) << "the stored image is the image";
  EXPECT_FALSE(exr_before.empty());
}

TEST(Coordinator, PriorityCanChangeWhileJobsWait) {
  TempDir dir;
  Coordinator c(options(dir));
  const uint64_t w = add_worker(c, "w");
  const uint64_t a = submit(c, json{{"tile_size", 8}, {"name", "a"}}, bundle()).value.jobs.at(0).id;
  const uint64_t b = submit(c, json{{"tile_size", 8}, {"name", "b"}}, bundle()).value.jobs.at(0).id;
  EXPECT_EQ(lease_json(c.lease(w, 0))["job"], a) << "equal priorities: the older job first";
  EXPECT_TRUE(c.set_priority(b, 5).ok());
  EXPECT_EQ(lease_json(c.lease(w, 0))["job"], b);
  EXPECT_EQ(c.job_status(b).value.priority, 5);
  EXPECT_EQ(c.set_priority(99, 1).code, server::Code::NotFound);
}

TEST(Coordinator, RetriedJobKeepsItsPassesAndFinishesBitIdentical) {
  TempDir dir, src;
  LoadResult loaded = load_scene(parse_scene_file(src.write("scene.xml", kXml)), LoadOptions{});
  Coordinator c(options(dir));
  const uint64_t w = add_worker(c, "w");
  const uint64_t id = submit(c, json{{"tile_size", 8}, {"seed", 3}}, bundle()).value.jobs.at(0).id;
  ASSERT_TRUE(deliver_one(c, w, *loaded.scene, 3));
  ASSERT_TRUE(deliver_one(c, w, *loaded.scene, 3));
  EXPECT_EQ(c.retry_job(id).code, server::Code::Conflict) << "a running job is not retried";
  nlohmann::json l = lease_json(c.lease(w, 0));
  ASSERT_TRUE(c.fail_lease(w, l["id"], "disk full").ok());
  ASSERT_EQ(c.job_status(id).value.state, "failed");
  ASSERT_TRUE(c.retry_job(id).ok());
  json st = to_json(c.job_status(id).value);
  EXPECT_EQ(st["state"], "queued");
  EXPECT_EQ(st["units_done"], 2);
  EXPECT_EQ(st["error"], "");
  while (deliver_one(c, w, *loaded.scene, 3)) {
  }
  ASSERT_EQ(c.job_status(id).value.state, "done");
  // The same image as a job that never failed.
  const uint64_t clean = submit(c, json{{"tile_size", 8}, {"seed", 3}}, bundle()).value.jobs.at(0).id;
  while (deliver_one(c, w, *loaded.scene, 3)) {
  }
  EXPECT_EQ(c.job_image(id, "pfm").value.bytes, c.job_image(clean, "pfm").value.bytes);
}

TEST(Coordinator, DrainedWorkerGetsNoMoreWork) {
  TempDir dir;
  Coordinator c(options(dir));
  const uint64_t a = add_worker(c, "a"), b = add_worker(c, "b");
  ASSERT_TRUE(submit(c, json{{"tile_size", 8}}, bundle()).ok());
  ASSERT_TRUE(c.drain_worker(a).ok());
  EXPECT_EQ(c.lease(a, 0).status.code, server::Code::Gone);
  EXPECT_TRUE(c.lease(b, 0).value.has_value());
  EXPECT_NE(c.metrics().find("tessera_workers{state=\"draining\"} 1"), std::string::npos);
  EXPECT_EQ(c.drain_worker(77).code, server::Code::NotFound);
}

TEST(Coordinator, WorkersShowTheSceneMemoryTheirHeartbeatsReport) {
  TempDir dir;
  Coordinator c(options(dir));
  const uint64_t a = add_worker(c, "a");
  auto status = [&] { return to_json(c.list_workers().value.at(0)); };
  EXPECT_EQ(status()["scene_memory_bytes"], 0);
  ASSERT_TRUE(c.heartbeat(a, Heartbeat{{}, WorkerMemory{uint64_t(3) << 30, 2}}).ok());
  EXPECT_EQ(status()["scene_memory_bytes"], uint64_t(3) << 30);
  EXPECT_EQ(status()["scenes_loaded"], 2);
  // A heartbeat without the report (an older worker) keeps the last one.
  ASSERT_TRUE(c.heartbeat(a, Heartbeat{}).ok());
  EXPECT_EQ(status()["scenes_loaded"], 2);
  EXPECT_NE(c.metrics().find("tessera_worker_scene_memory_bytes{worker=\"" + std::to_string(a) + "\",name=\"a\"} 3221225472"),
            std::string::npos);
}

TEST(Coordinator, ABrokenDataDirectoryIsAClearError) {
  TempDir dir;
  std::filesystem::create_directories(dir.path / "data");
  dir.write("data/state.sqlite", "this is not a database");
  try {
    Coordinator c(options(dir));
    ADD_FAILURE() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("database"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera::test

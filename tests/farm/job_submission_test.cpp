// Submissions the coordinator names or refuses: an unnamed job takes its scene's folder as its name,
// and a bundle that came with a refused job (or frame range) is not left on disk, while one stored
// before, or used by an accepted job, stays.
#include "coordinator_fixture.h"

#include <filesystem>
#include <optional>
#include <thread>

namespace tessera::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using server::Coordinator;

// The bundle files and unpacked scenes in the data dir.
size_t stored_bundles(const TempDir& dir) {
  size_t n = 0;
  for (const char* sub : {"bundles", "scenes"})
    for (const auto& e : fs::directory_iterator(dir.path / "data" / sub))
      n += e.path().extension().string().rfind(".tmp", 0) != 0;  // (not a file being written)
  return n;
}

std::string bundle_in_folder(const std::string& folder, const std::string& xml) {
  TempDir src;
  src.write(folder + "/scene.xml", xml);
  return pack_bundle(src.path.string(), {folder + "/scene.xml"});
}

TEST(JobSubmission, AnUnnamedJobIsNamedAfterItsScenesFolder) {
  TempDir dir;
  Coordinator c(options(dir));
  auto job = submit(c, json{{"scene_file", "cornell-box/scene.xml"}}, bundle_in_folder("cornell-box", kXml));
  ASSERT_TRUE(job.ok()) << job.status.detail;
  EXPECT_EQ(job.value.jobs.at(0).name, "cornell-box");
  EXPECT_EQ(c.job_status(job.value.jobs.at(0).id).value.settings.name, "cornell-box");
  auto named = submit(c, json{{"scene_file", "cornell-box/scene.xml"}, {"name", "mine"}}, bundle_in_folder("cornell-box", kXml));
  ASSERT_TRUE(named.ok()) << named.status.detail;
  EXPECT_EQ(named.value.jobs.at(0).name, "mine");
}

TEST(JobSubmission, ABundleOfARefusedJobIsDeleted) {
  TempDir dir;
  Coordinator c(options(dir));
  // Refused after the bundle was written: by the limits, by a scene that does not load, as a frame
  // range whose first frame fails.
  auto too_many = submit(c, json{{"spp", 1 << 30}}, bundle());
  EXPECT_EQ(too_many.status.code, server::Code::Unprocessable) << too_many.status.detail;
  EXPECT_EQ(stored_bundles(dir), 0u);
  const std::string broken = bundle_in_folder("broken", "<scene version=\"0.6.0\"><shape type=\"nonsense\"/></scene>");
  auto unloadable = submit(c, json{{"scene_file", "broken/scene.xml"}}, broken);
  EXPECT_FALSE(unloadable.ok());
  EXPECT_EQ(stored_bundles(dir), 0u) << unloadable.status.detail;
  auto frames = submit(c, json{{"frames", "1-3"}, {"width", 1 << 20}}, bundle());
  EXPECT_FALSE(frames.ok());
  EXPECT_EQ(stored_bundles(dir), 0u) << frames.status.detail;

  // A bundle uploaded on its own stays when a job naming it is refused, and so does one an
  // accepted job uses when the same bundle comes again with a refused one.
  auto uploaded = c.upload_scene(broken);
  ASSERT_TRUE(uploaded.ok()) << uploaded.status.detail;
  EXPECT_FALSE(submit(c, json{{"scene", uploaded.value.hash}, {"scene_file", "broken/scene.xml"}}, "").ok());
  EXPECT_TRUE(fs::exists(dir.path / "data" / "bundles" / (uploaded.value.hash + ".bundle")));
  const std::string used = bundle();
  auto good = submit(c, json::object(), used);
  ASSERT_TRUE(good.ok()) << good.status.detail;
  EXPECT_FALSE(submit(c, json{{"spp", 1 << 30}}, used).ok());
  auto again = submit(c, json::object(), used);
  EXPECT_TRUE(again.ok()) << again.status.detail;
}

// Two submissions of one new bundle at once, one refused: the refused one never deletes the bundle
// while the other is still being stored, unpacked or planned, so the accepted job keeps its bundle.
TEST(JobSubmission, ARefusedSubmissionKeepsABundleAnotherIsUsing) {
  TempDir dir;
  Coordinator c(options(dir));
  for (int round = 0; round < 30; ++round) {
    std::string xml = kXml;
    xml.insert(xml.find("<emitter"), "<!-- round " + std::to_string(round) + " -->\n");
    const std::string bytes = bundle_in_folder("shared", xml);
    std::optional<server::Result<JobSubmission>> accepted, refused;
    std::thread a([&] { accepted.emplace(submit(c, json{{"scene_file", "shared/scene.xml"}}, bytes)); });
    std::thread b([&] { refused.emplace(submit(c, json{{"scene_file", "shared/scene.xml"}, {"spp", 1 << 30}}, bytes)); });
    a.join();
    b.join();
    ASSERT_TRUE(accepted->ok()) << "round " << round << ": " << accepted->status.detail;
    EXPECT_FALSE(refused->ok());
    const std::string hash = accepted->value.jobs.at(0).settings.scene;
    ASSERT_TRUE(fs::exists(dir.path / "data" / "bundles" / (hash + ".bundle"))) << "round " << round;
  }
}

// allow_unsupported, as `tessera render --allow-unsupported`: the coordinator loads the scene with
// the fallbacks, and so do the workers, whose leases carry it.
TEST(JobSubmission, AllowUnsupportedLoadsWithTheFallbacksEverywhere) {
  TempDir dir;
  Coordinator c(options(dir));
  std::string xml = kXml;
  xml.insert(xml.find("<emitter"), "<shape type=\"sphere\"><transform name=\"to_world\"><scale x=\"1\" y=\"2\" z=\"1\"/>"
                                   "</transform></shape>\n");
  const std::string squashed = bundle_in_folder("squashed", xml);
  auto refused = submit(c, json{{"scene_file", "squashed/scene.xml"}}, squashed);
  EXPECT_EQ(refused.status.code, server::Code::Unprocessable) << refused.status.detail;
  auto allowed = submit(c, json{{"scene_file", "squashed/scene.xml"}, {"allow_unsupported", true}}, squashed);
  ASSERT_TRUE(allowed.ok()) << allowed.status.detail;
  const json lease = lease_json(c.lease(add_worker(c, "w"), 0));
  ASSERT_TRUE(lease.is_object());
  EXPECT_EQ(lease["settings"]["allow_unsupported"], true);
  Lease parsed;
  std::string error;
  ASSERT_TRUE(lease_from_json(lease, parsed, error)) << error;
  TempDir worker_copy;  // (as a worker loads its unpacked bundle)
  worker_copy.write("scene.xml", xml);
  EXPECT_NO_THROW(load_job_scene(worker_copy.path.string(), "scene.xml", parsed.settings, /*confine=*/true));
  parsed.settings.allow_unsupported = false;
  EXPECT_THROW(load_job_scene(worker_copy.path.string(), "scene.xml", parsed.settings, /*confine=*/true), std::exception);
}

}  // namespace
}  // namespace tessera::test

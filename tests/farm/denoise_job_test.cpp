// Denoising on the farm (job field denoise): the units carry AOV sums, a running job's preview can
// be fetched denoised, the raw image (with its AOV layers) is bit for bit render()'s, the denoised image is bit for bit the denoiser's on that raw
// image, the job is done only once both are stored, also when the coordinator is stopped and
// started again while the units arrive and while it denoises.
#include "coordinator_fixture.h"
#include "tessera/denoise/denoiser.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

namespace tessera::test {
namespace {

using nlohmann::json;
using server::Coordinator;

constexpr int kSpp = 5;
constexpr uint32_t kSeed = 3;

LoadResult load_fixture_scene() { return load_scene(parse_scene_string(kXml, "scene.xml"), LoadOptions{}); }

json denoised_settings() { return {{"spp", kSpp}, {"tile_size", 8}, {"seed", kSeed}, {"denoise", true}}; }

// The job's image as stored (EXR, raw or denoised) read back as the denoiser's input.
DenoiseInput job_exr(Coordinator& c, uint64_t id, bool denoised, const TempDir& dir) {
  auto bytes = c.job_image(id, "exr", denoised);
  EXPECT_TRUE(bytes.ok()) << bytes.status.detail;
  const std::string path = (dir.path / (denoised ? "denoised.exr" : "raw.exr")).string();
  std::ofstream(path, std::ios::binary) << bytes.value.bytes;
  if (denoised) {
    DenoiseInput in;
    in.color = read_exr(path);
    return in;
  }
  return read_denoise_input(path);
}

// Waits (the coordinator denoises off its lock) until the job is done.
server::Result<JobStatus> wait_done(Coordinator& c, uint64_t id) {
  for (int i = 0; i < 500; ++i) {
    auto s = c.job_status(id);
    if (!s.ok() || s.value.state == "done") return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return c.job_status(id);
}

void expect_local_images(Coordinator& c, uint64_t id, const Scene& scene, const TempDir& dir) {
  RenderSettings rs;
  rs.spp = kSpp;
  rs.seed = kSeed;
  rs.tile_size = 5;  // not the job's
  rs.aovs = true;
  const Film film = render(scene, rs);
  const DenoiseInput local = make_denoise_input(film.to_image(), film.aov_layers(denoise_layers()));

  const DenoiseInput raw = job_exr(c, id, false, dir);
  EXPECT_EQ(raw.color.values(), local.color.values()) << "the raw image";
  EXPECT_EQ(raw.albedo.values(), local.albedo.values());
  EXPECT_EQ(raw.half_a.values(), local.half_a.values());
  EXPECT_EQ(raw.depth.values(), local.depth.values());
  EXPECT_EQ(job_exr(c, id, true, dir).color.values(), denoise(local).values()) << "the denoised image";
}

TEST(DenoiseJob, ImagesAreTheLocalRenderAndItsDenoisedImage) {
  TempDir dir;
  LoadResult loaded = load_fixture_scene();
  Coordinator c(options(dir));
  const uint64_t worker = add_worker(c, "w");
  auto job = submit(c, denoised_settings(), bundle());
  ASSERT_TRUE(job.ok()) << job.status.detail;
  const uint64_t id = job.value.jobs.at(0).id;
  EXPECT_EQ(c.job_status(id).value.denoise_state, "waiting");
  auto early = c.job_image(id, "exr", /*denoised=*/true);
  EXPECT_EQ(early.status.code, server::Code::NotYet);

  // A unit rendered without the AOV sums is refused.
  json l = lease_json(c.lease(worker, 0));
  ASSERT_TRUE(l.is_object());
  json plain = l;
  plain["settings"]["denoise"] = false;
  auto refused = c.upload_result(worker, l["id"], render_unit(plain, *loaded.scene, kSeed));
  EXPECT_EQ(refused.status.code, server::Code::BadRequest);
  EXPECT_NE(refused.status.detail.find("AOV"), std::string::npos) << refused.status.detail;
  ASSERT_TRUE(c.upload_result(worker, l["id"], render_unit(l, *loaded.scene, kSeed)).ok());
  // While it runs: 202 until a preview of its film is denoised, then that preview.
  server::Result<server::ImageBytes> preview = c.job_image(id, "pfm", /*denoised=*/true);
  for (int i = 0; i < 500 && preview.status.code == server::Code::NotYet; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    preview = c.job_image(id, "pfm", /*denoised=*/true);
  }
  ASSERT_TRUE(preview.ok()) << preview.status.detail;
  EXPECT_EQ(pfm_image(preview.value.bytes).width(), 20);

  while (deliver_one(c, worker, *loaded.scene, kSeed)) {
  }
  const auto status = wait_done(c, id);
  ASSERT_EQ(status.value.state, "done");
  EXPECT_EQ(status.value.denoise_state, "done");
  EXPECT_EQ(status.value.denoise_error, "");
  expect_local_images(c, id, *loaded.scene, dir);
}

TEST(DenoiseJob, SurvivesRestartsWhileRenderingAndDenoising) {
  TempDir dir;
  LoadResult loaded = load_fixture_scene();
  int restarts = 0;
  const uint64_t id = render_with_restarts(
      dir, denoised_settings(), bundle(),
      [&](Coordinator&, const json& l) { return render_unit(l, *loaded.scene, kSeed); }, restarts);
  EXPECT_GT(restarts, 2);
  Coordinator c(options(dir));
  ASSERT_EQ(wait_done(c, id).value.state, "done");
  expect_local_images(c, id, *loaded.scene, dir);
}

// A denoised image that cannot be stored (here: a folder in its place) leaves the job done with its
// raw image and the reason.
TEST(DenoiseJob, AFailedDenoiseLeavesTheRawImageAndSaysWhy) {
  TempDir dir;
  LoadResult loaded = load_fixture_scene();
  Coordinator c(options(dir));
  std::filesystem::create_directories(dir.path / "data" / "images" / "1.denoised.exr" / "in-the-way");
  const uint64_t worker = add_worker(c, "w");
  auto job = submit(c, denoised_settings(), bundle());
  ASSERT_TRUE(job.ok()) << job.status.detail;
  const uint64_t id = job.value.jobs.at(0).id;
  ASSERT_EQ(id, 1u);
  while (deliver_one(c, worker, *loaded.scene, kSeed)) {
  }
  const auto status = wait_done(c, id);
  ASSERT_EQ(status.value.state, "done");
  EXPECT_EQ(status.value.denoise_state, "failed");
  EXPECT_EQ(status.value.error, "");
  EXPECT_NE(status.value.denoise_error.find("denoising failed"), std::string::npos) << status.value.denoise_error;
  const auto denoised = c.job_image(id, "exr", /*denoised=*/true);
  EXPECT_EQ(denoised.status.code, server::Code::NotFound);
  EXPECT_NE(denoised.status.detail.find("denoising failed"), std::string::npos) << denoised.status.detail;
  EXPECT_EQ(job_exr(c, id, false, dir).color.width(), 20) << "the raw image is kept";
}

TEST(DenoiseJob, AJobWithoutDenoiseHasNoDenoisedImage) {
  TempDir dir;
  LoadResult loaded = load_fixture_scene();
  Coordinator c(options(dir));
  const uint64_t worker = add_worker(c, "w");
  auto job = submit(c, {{"spp", 2}, {"tile_size", 8}}, bundle());
  ASSERT_TRUE(job.ok()) << job.status.detail;
  const uint64_t id = job.value.jobs.at(0).id;
  while (deliver_one(c, worker, *loaded.scene, 0)) {
  }
  ASSERT_EQ(wait_done(c, id).value.state, "done");
  EXPECT_EQ(c.job_status(id).value.denoise_state, "");
  EXPECT_EQ(c.job_image(id, "exr", /*denoised=*/true).status.code, server::Code::NotFound);
  EXPECT_TRUE(c.job_image(id, "exr").ok());
}

// `aovs` and `denoise_mode`, as `tessera render --aovs/--denoise-mode`: the EXR carries exactly the
// layers asked for (render()'s, bit for bit), with or without denoising, read from the film while
// its image is being written and from disk after; the denoised image is the mode's.
TEST(DenoiseJob, AJobsAovLayersAndDenoiseModeAreRendersOwn) {
  TempDir dir;
  LoadResult loaded = load_fixture_scene();
  Coordinator c(options(dir));
  const uint64_t worker = add_worker(c, "w");
  RenderSettings rs;
  rs.spp = kSpp;
  rs.seed = kSeed;
  rs.aovs = true;
  const Film film = render(*loaded.scene, rs);
  const std::string path = (dir.path / "job.exr").string();
  for (const bool denoised : {false, true}) {
    json settings = {{"spp", kSpp}, {"tile_size", 8}, {"seed", kSeed}, {"aovs", "albedo,depth"}};
    if (denoised) settings.update(json{{"denoise", true}, {"denoise_mode", "preview"}});
    auto job = submit(c, settings, bundle());
    ASSERT_TRUE(job.ok()) << job.status.detail;
    const uint64_t id = job.value.jobs.at(0).id;
    while (deliver_one(c, worker, *loaded.scene, kSeed)) {
    }
    ASSERT_EQ(wait_done(c, id).value.state, "done");
    auto bytes = c.job_image(id, "exr");
    ASSERT_TRUE(bytes.ok()) << bytes.status.detail;
    std::ofstream(path, std::ios::binary) << bytes.value.bytes;
    EXPECT_EQ(read_exr(path).values(), film.to_image().values());
    for (AovLayer l : {AovLayer::Albedo, AovLayer::Depth})
      EXPECT_EQ(read_exr_layer(path, aov_layer_name(l), aov_channel_names(l)).values(),
                film.aov_layers({l}).at(0).image.values())
          << aov_layer_name(l);
    EXPECT_THROW(read_exr_layer(path, "normal", aov_channel_names(AovLayer::Normal)), std::exception) << "not asked for";
    if (!denoised) continue;
    DenoiseSettings preview;
    preview.mode = DenoiseMode::Preview;
    const Image expected = denoise(make_denoise_input(film.to_image(), film.aov_layers(denoise_layers())), preview);
    EXPECT_EQ(job_exr(c, id, true, dir).color.values(), expected.values()) << "the preview mode's denoised image";
  }
}

}  // namespace
}  // namespace tessera::test

// Units that are not tiles on the farm: a job whose program has a pass of light paths (its units
// ranges of paths, their results image-wide splats, farm/splat_result.h) besides Tile passes. Its
// results in any order, across coordinator restarts, give the image the same program gives on this
// machine (sequence/local_driver.h), bit for bit; a result of the wrong kind or range is refused,
// and an upload's size limit is its range's.
#include "coordinator_fixture.h"
#include "sequence/toy_technique.h"

#include "tessera/farm/splat_result.h"
#include "tessera/sequence/local_driver.h"
#include "tessera/server/store.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>

namespace tessera::test {
namespace {

using nlohmann::json;
using server::Coordinator;

constexpr uint32_t kSeed = 11;

// Tile passes around a pass of light paths (2 paths a pixel, in ranges of 37).
PassProgram tiles_and_paths() {
  PassProgram p;
  p.spp = 7;
  p.paths_per_unit = 37;
  auto pass = [](UnitKind kind, uint32_t begin, uint32_t samples) {
    PassSpec s;
    s.kind = kind;
    s.sample_begin = begin;
    s.samples = samples;
    return s;
  };
  p.passes = {pass(UnitKind::Tile, 0, 2), pass(UnitKind::Paths, 2, 2), pass(UnitKind::Tile, 4, 3)};
  return p;
}

// What a light tracer would splat for paths [begin, end): the toy's values, anywhere in the window.
SplatSums toy_splats(uint64_t begin, uint64_t end, const TileRect& window) {
  SplatSums s;
  s.reset(window);
  for (uint64_t k = begin; k < end; ++k) {
    const double v = toy_value(k, 5, kSeed);
    s.pixel.push_back(uint32_t(toy_mix(k) % uint64_t(window.area())));
    s.value.push_back({v, 0.5 * v, 0.25 * v});
  }
  s.counters.samples = end - begin;
  return s;
}

// The same units rendered here: the path tracer's tiles, the toy's splats.
class LocalUnits final : public UnitRenderer {
 public:
  explicit LocalUnits(const Scene& scene) : scene_(scene) {}
  void render(const PassSequencer& seq, const UnitWork& work, UnitResult& result) override {
    if (work.kind == UnitKind::Paths) {
      result.splats = toy_splats(work.path_begin, work.path_end, seq.frame().window);
      return;
    }
    render_tile(scene_, work.rect, work.sample_begin, work.sample_end, kSeed, result.tile);
  }

 private:
  const Scene& scene_;
};

std::string render_lease_bytes(const Lease& lease, const Scene& scene) {
  if (!lease.paths) {
    Lease seeded = lease;
    seeded.settings.seed = kSeed;
    return encode_tile_result(render_lease(scene, seeded));
  }
  SplatResult r;
  r.job_id = lease.job_id;
  r.pass = lease.pass;
  r.unit = lease.tile;
  std::tie(r.path_begin, r.path_end) = *lease.paths;
  r.splats = toy_splats(r.path_begin, r.path_end, lease.rect);
  return encode_splat_result(r);
}

// A job with the program, as the coordinator stores it, put in its state database before it starts.
uint64_t store_job(const TempDir& dir, const Scene& scene) {
  JobPlan plan = plan_for(scene, 7, 8, kSeed);
  plan.program = tiles_and_paths();
  plan.settings.scene = std::string(64, 'a');
  plan.scene_file = "scene.xml";
  plan.files = {"scene.xml"};
  std::filesystem::create_directories(dir.path / "data");
  server::Store store((dir.path / "data" / "state.sqlite").string());
  return store.add_job("paths", to_json(plan).dump(), 0, 1.0);
}

Lease lease_of(const server::Result<std::optional<Lease>>& r) {
  EXPECT_TRUE(r.ok() && r.value) << r.status.detail;
  return r.ok() && r.value ? *r.value : Lease{};
}

TEST(PathsJob, SplatsInAnyOrderAcrossRestartsGiveTheLocalImage) {
  const LoadResult loaded = load_scene(parse_scene_string(kXml, "scene.xml"), LoadOptions{});
  const Scene& scene = *loaded.scene;
  PassSequencer local(tiles_and_paths(), SequenceFrame{film_window(scene.film), scene.film.width, scene.film.height, 8, false});
  LocalUnits units(scene);
  run_locally(local, units, 2);

  TempDir dir;
  const uint64_t id = store_job(dir, scene);
  int splats = 0, restarts = 0;
  for (bool done = false; !done && restarts < 100; ++restarts) {
    Coordinator c(options(dir));
    const uint64_t worker = add_worker(c, "w");
    std::vector<Lease> held;  // leased 3 at a time, delivered last first
    for (int i = 0; i < 3; ++i)
      if (auto r = c.lease(worker, 1); r.ok() && r.value) held.push_back(*r.value);
    std::reverse(held.begin(), held.end());
    for (const Lease& l : held) {
      splats += l.paths.has_value();
      auto up = c.upload_result(worker, l.id, render_lease_bytes(l, scene));
      ASSERT_TRUE(up.ok()) << up.status.detail;
    }
    done = c.job_status(id).value.state == "done";
    if (done) {
      auto image = c.job_image(id, "pfm");
      ASSERT_TRUE(image.ok()) << image.status.detail;
      const Image farm = pfm_image(image.value.bytes), here = local.films().image();
      int64_t differing_pixels = 0;
      for (int y = 0; y < here.height(); ++y)
        for (int x = 0; x < here.width(); ++x)
          for (int ch = 0; ch < 3; ++ch) differing_pixels += farm.at(x, y, ch) != here.at(x, y, ch);
      EXPECT_EQ(differing_pixels, 0);
    }
  }
  EXPECT_EQ(splats, int(local.units_in(1))) << "every range of paths leased once";
  EXPECT_GT(restarts, 3);
}

TEST(PathsJob, AResultOfTheWrongKindOrRangeIsRefused) {
  const LoadResult loaded = load_scene(parse_scene_string(kXml, "scene.xml"), LoadOptions{});
  const Scene& scene = *loaded.scene;
  TempDir dir;
  const uint64_t id = store_job(dir, scene);
  Coordinator c(options(dir));
  const uint64_t worker = add_worker(c, "w");
  Lease paths;
  for (int i = 0; i < 100 && !paths.paths; ++i) {  // (pass 0's tiles first, then the ranges)
    paths = lease_of(c.lease(worker, 1));
    if (!paths.paths) {
      ASSERT_TRUE(c.upload_result(worker, paths.id, render_lease_bytes(paths, scene)).ok());
    }
  }
  ASSERT_TRUE(paths.paths);
  EXPECT_EQ(paths.rect, film_window(scene.film)) << "a range's result covers the whole window";
  const server::BodyLimit limit = c.result_limit(worker, paths.id);
  EXPECT_EQ(limit.bytes, max_splat_result_bytes(paths.paths->second - paths.paths->first, kMaxTrainingBytes,
                                                uint64_t(film_window(scene.film).area())));
  EXPECT_NE(limit.what.find("light paths"), std::string::npos) << limit.what;

  Lease as_tile = paths;
  as_tile.paths.reset();
  as_tile.rect = {0, 0, 8, 8};
  auto wrong_kind = c.upload_result(worker, paths.id, encode_tile_result(render_lease(scene, as_tile)));
  EXPECT_EQ(wrong_kind.status.code, server::Code::BadRequest);
  EXPECT_NE(wrong_kind.status.detail.find("tile result for a unit of light paths"), std::string::npos)
      << wrong_kind.status.detail;
  Lease shifted = paths;
  shifted.paths->second += 1;
  auto wrong_range = c.upload_result(worker, paths.id, render_lease_bytes(shifted, scene));
  EXPECT_EQ(wrong_range.status.code, server::Code::BadRequest);
  EXPECT_NE(wrong_range.status.detail.find("light paths do not match"), std::string::npos) << wrong_range.status.detail;
  EXPECT_TRUE(c.upload_result(worker, paths.id, render_lease_bytes(paths, scene)).ok());
  EXPECT_EQ(c.job_status(id).value.state, "running");
}

}  // namespace
}  // namespace tessera::test

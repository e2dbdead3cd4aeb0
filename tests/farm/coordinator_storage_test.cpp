// The coordinator's storage is bounded by the image, not by the work: each tile's passes are folded
// into a checkpoint of the film's sums and their results' bytes dropped, keeping a small row per
// unit. A job rebuilt from checkpoints and rows (after a restart, or retried after a cancel) ends
// bit-identical to one that ran straight through.
#include "coordinator_fixture.h"

#include <filesystem>

namespace tessera::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using server::Coordinator;

// 320x320 in 32-pixel tiles (100 tiles) x 10 passes (319 spp) = 1000 units.
const json kJob = {{"width", 320}, {"height", 320}, {"tile_size", 32}, {"spp", 319}, {"seed", 3}};
constexpr double kFilmBytes = 320.0 * 320.0 * sizeof(PixelSums);

// Sums that depend on the unit alone (tile, pass, pixel) with the entropy of a real pass: any
// coordinator that adds them in the right order gets the same bits.
std::string synthetic_result(const json& lease_json) {
  Lease lease;
  std::string error;
  EXPECT_TRUE(lease_from_json(lease_json, lease, error)) << error;
  TileResult r;
  begin_tile_result(lease, r);
  uint64_t rng = 0x9E3779B97F4A7C15ull * (uint64_t(lease.tile) * 131 + lease.pass + 1);
  const uint32_t n = lease.sample_end - lease.sample_begin;
  for (PixelSums& p : r.film.mutable_pixels()) {
    for (int c = 0; c < 3; ++c) {
      rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
      const double v = double(rng >> 11) * 0x1p-53;
      p.sum[c] = v * n;
      p.sum_sq[c] = v * v * n;
    }
    p.count = n;
  }
  r.film.counters.samples = uint64_t(lease.rect.area()) * n;
  return encode_tile_result(r);
}

// Delivers up to `units` units (with the next lease asked for each time); the units delivered.
int deliver(Coordinator& c, uint64_t worker, int units) {
  nlohmann::json lease = lease_json(c.lease(worker, 0));
  int done = 0;
  for (; done < units && lease.is_object(); ++done) {
    auto up = c.upload_result(worker, lease["id"], synthetic_result(lease), /*next=*/done + 1 < units);
    EXPECT_TRUE(up.ok()) << up.status.detail;
    lease = up.value.next ? to_json(*up.value.next) : json();
  }
  EXPECT_FALSE(lease.is_object() && done == units) << "a lease nobody asked for";
  return done;
}

// Bytes the job's storage takes: the state database (closed, so its log is folded in) and images.
// Bundles and unpacked scenes belong to the scene, shared by its jobs.
uint64_t job_storage(const TempDir& dir) {
  uint64_t bytes = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir.path / "data")) {
    const std::string rel = e.path().lexically_relative(dir.path / "data").generic_string();
    if (e.is_regular_file() && rel.rfind("bundles/", 0) != 0 && rel.rfind("scenes/", 0) != 0) bytes += e.file_size();
  }
  return bytes;
}

std::string image(Coordinator& c, uint64_t id) {
  auto img = c.job_image(id, "pfm");
  EXPECT_TRUE(img.ok()) << img.status.detail;
  return img.value.bytes;
}

TEST(CoordinatorStorage, AThousandUnitJobKeepsCheckpointsAndSmallRowsNotItsResults) {
  TempDir straight, interrupted;
  uint64_t empty = 0;
  {
    Coordinator c(options(straight));
    (void)add_worker(c, "w");
  }
  empty = job_storage(straight);
  std::string reference;
  uint64_t result_bytes = 0;
  {
    Coordinator c(options(straight));
    const uint64_t id = submit(c, kJob, bundle()).value.jobs.at(0).id;
    EXPECT_EQ(deliver(c, 1, 1000), 1000);
    const json st = to_json(c.job_status(id).value);
    ASSERT_EQ(st["state"], "done");
    result_bytes = st["result_bytes"];
    reference = image(c, id);
  }
  const double growth = double(job_storage(straight) - empty);
  const double bound = 2 * kFilmBytes + 64.0 * 1000;
  std::printf("storage after a 1000-unit job: %.0f bytes (bound %.0f: 2 x film %.0f + 64 B x 1000 units); "
              "its results were %ju bytes\n", growth, bound, kFilmBytes, uintmax_t(result_bytes));
  EXPECT_LE(growth, bound);
  EXPECT_GT(double(result_bytes), bound) << "the job's results alone would not fit: the bound says something";

  // The same job interrupted twice: a restart at 35%, a cancel and retry at 70%. Rebuilt from
  // checkpoints and rows each time, it ends with the same bits.
  uint64_t id = 0;
  {
    Coordinator c(options(interrupted));
    const uint64_t w = add_worker(c, "w");
    id = submit(c, kJob, bundle()).value.jobs.at(0).id;
    EXPECT_EQ(deliver(c, w, 350), 350);
  }
  Coordinator c(options(interrupted));
  EXPECT_EQ(c.job_status(id).value.units_done, 350);
  EXPECT_EQ(deliver(c, 1, 350), 350);
  ASSERT_TRUE(c.cancel_job(id).ok());
  ASSERT_TRUE(c.retry_job(id).ok());
  EXPECT_EQ(c.job_status(id).value.units_done, 700);
  EXPECT_EQ(deliver(c, 1, 1000), 300);
  ASSERT_EQ(c.job_status(id).value.state, "done");
  EXPECT_EQ(image(c, id), reference);
}

}  // namespace
}  // namespace tessera::test

// A full disk, for real: the coordinator's data dir on a 12 MB tmpfs (root only; skipped without
// root, failed under CI=true), filled to the last page while a job renders. Every write answers
// 507 with a clear message, the server stays healthy, the accepted job is not corrupted, and once
// the filler is deleted the job finishes bit-identical to a local render; a restart (on a full
// disk, then with space again) opens the database and serves the same image.
#include "farm_harness.h"

#include "tessera/farm/sha256.h"

#include <fcntl.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iterator>

namespace tessera::test {
namespace {

namespace fs = std::filesystem;

// Unmounts in every exit path (after the server using it is killed).
class Tmpfs {
 public:
  Tmpfs(Farm& farm, const fs::path& dir) : farm_(farm), dir_(dir) {
    fs::create_directories(dir);
    const std::string cmd = "mount -t tmpfs -o size=12m tmpfs '" + dir.string() + "'";
    mounted_ = std::system(cmd.c_str()) == 0;
  }
  ~Tmpfs() {
    farm_.kill_server();
    if (mounted_) (void)::umount2(dir_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }

 private:
  Farm& farm_;
  fs::path dir_;
  bool mounted_ = false;
};

// Writes `path` until the file system has no page left; returns the bytes written.
uint64_t fill(const fs::path& path) {
  int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return 0;
  std::string chunk(1 << 20, 'x');
  uint64_t total = 0;
  for (size_t size : {size_t(1) << 20, size_t(4096), size_t(512), size_t(1)})
    for (;;) {
      ssize_t n = ::write(fd, chunk.data(), size);
      if (n <= 0) break;
      total += uint64_t(n);
    }
  ::close(fd);
  return total;
}

JobSettings job() {
  JobSettings s;
  s.name = "cornell-disk";
  s.spp = 24;
  s.width = 48;
  s.height = 36;
  s.tile_size = 8;  // 36 tiles x 5 passes: far more result bytes than the WAL's free room
  s.seed = 5;
  return s;
}

bool mentions(const client::HttpReply& r, const std::string& text) { return r.body.find(text) != std::string::npos; }

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(FarmDisk, AFullDiskIsA507AndTheJobFinishesOnceSpaceIsFreed) {
  TESSERA_REQUIRE_FILE(cornell());
  if (::geteuid() != 0) {
    const char* ci = std::getenv("CI");
    if (ci && std::string(ci) == "true") FAIL() << "mounting a tmpfs needs root, and CI=true";
    GTEST_SKIP() << "mounting a tmpfs needs root";
  }
  Farm farm;
  const fs::path data = farm.dir().path / "data";
  Tmpfs disk(farm, data);
  ASSERT_TRUE(disk.mounted()) << "mount -t tmpfs failed";
  farm.start_server();
  const JobSettings settings = job();
  client::HttpReply reply;
  const uint64_t id = farm.submit(cornell(), settings, &reply);
  ASSERT_GT(id, 0u) << reply.describe();

  // A first worker delivers 20 passes and leaves; the disk fills up with the job half done; a
  // second worker's leases and results need new WAL pages, which there are not.
  farm.add_worker(1, {"--max-leases", "20"});
  EXPECT_EQ(farm.worker(0).wait_exit(60), 0);
  ASSERT_EQ(farm.status(id).value("units_done", 0), 20);
  const fs::path filler = farm.dir().path / "data" / "filler";
  ASSERT_GT(fill(filler), 0u);
  farm.add_worker(2);

  TempDir other;
  other.write("scene.xml", "<scene version=\"0.6.0\"><!-- another bundle --></scene>");
  const std::string bundle = pack_bundle(other.path.string(), {"scene.xml"});
  client::HttpReply up = farm.client().post_bytes("/api/v1/scenes", bundle, "application/gzip");
  EXPECT_EQ(up.status, 507) << up.describe();
  EXPECT_TRUE(mentions(up, "disk_full")) << up.body;
  EXPECT_TRUE(mentions(up, "the coordinator's disk is full")) << up.body;
  EXPECT_TRUE(mentions(up, "(data dir " + data.string() + ")")) << up.body;
  EXPECT_FALSE(fs::exists(data / "bundles" / (sha256_hex(bundle) + ".bundle")));

  // The worker's uploads (or leases) are refused with 507 and retried.
  const std::string worker_log = farm.log("worker1");
  for (int i = 0; i < 600 && read_text(worker_log).find("HTTP 507 disk_full") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_NE(read_text(worker_log).find("HTTP 507 disk_full: the coordinator's disk is full"), std::string::npos)
      << read_text(worker_log);
  EXPECT_TRUE(farm.client().get("/healthz").ok());
  std::printf("bundle upload on a full disk: %s\n", up.describe().c_str());
  nlohmann::json st = farm.status(id);
  ASSERT_TRUE(st.is_object()) << "the job's status still reads";
  EXPECT_NE(st.value("state", ""), "done") << "the disk filled up before the job could finish";
  EXPECT_NE(st.value("state", ""), "failed") << st.dump(2);
  EXPECT_LT(st.value("units_done", 0), st.value("units_total", 0));
  EXPECT_GE(st.value("units_done", 0), 20) << "acknowledged passes stay acknowledged";
  const int units_on_full_disk = st.value("units_done", 0);
  client::HttpReply metrics = farm.client().get("/metrics");
  EXPECT_NE(metrics.body.find("tessera_disk_full_errors_total"), std::string::npos);
  // A submission with a new bundle on the full disk: 507 too, not a broken bundle (400).
  client::HttpReply sub = farm.api().submit_job(nlohmann::json{{"spp", 1}}, bundle);
  EXPECT_EQ(sub.status, 507) << sub.describe();
  EXPECT_TRUE(farm.client().get("/healthz").ok());

  // Space again: the worker's retries go through and the job completes, bit for bit.
  fs::remove(filler);
  st = farm.wait_job(id, 180);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump(2);
  EXPECT_EQ(st["units_done"], st["units_total"]);
  EXPECT_EQ(st["reissued_acknowledged_passes"], 0);
  std::printf("units before space was freed: %d of %d\n", units_on_full_disk, st.value("units_total", 0));
  const Image local = local_render(cornell(), settings);
  EXPECT_EQ(differing_pixels(farm.image(id), local), 0);
  EXPECT_EQ(farm.client().post_bytes("/api/v1/scenes", bundle, "application/gzip").status, 201);

  // kill -9 and restart on a full disk: the database opens; the image is served or refused with
  // 507, never corrupt.
  farm.kill_server();
  ASSERT_GT(fill(filler), 0u);
  farm.start_server();
  EXPECT_EQ(farm.status(id).value("state", ""), "done");
  client::HttpReply image = farm.client().get("/api/v1/jobs/" + std::to_string(id) + "/image?format=exr", 60);
  EXPECT_TRUE(image.status == 507 || image.status == 200) << image.describe();
  std::printf("image after a restart on a full disk: %s\n", image.status == 200 ? "200" : image.describe().c_str());
  if (image.status == 200) {
    EXPECT_EQ(differing_pixels(farm.image(id), local), 0);
  }
  fs::remove(filler);
  farm.kill_server();
  farm.start_server();
  st = farm.status(id);
  EXPECT_EQ(st.value("state", ""), "done");
  EXPECT_EQ(st["units_done"], st["units_total"]);
  EXPECT_EQ(differing_pixels(farm.image(id), local), 0);
}

}  // namespace
}  // namespace tessera::test

// A coordinator's local workers (--local-workers) never outlive it, and a slot's cache folder (and
// name) is never run twice: a worker left holding it is stopped before the slot starts again.
#include "farm_harness.h"
#include "tessera/farm/cache_lock.h"

#include <chrono>
#include <filesystem>
#include <thread>

namespace tessera::test {
namespace {

std::string slot_cache(const Farm& farm, int slot) {
  return (farm.dir().path / "data" / "local-workers" / std::to_string(slot)).string();
}

// The pid holding the folder once one does (0 after `seconds`).
pid_t wait_holder(const std::string& cache, double seconds, pid_t other_than = 0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    const pid_t pid = farm::CacheLock::holder(cache);
    if ((pid > 0 && pid != other_than) || std::chrono::steady_clock::now() > end) return pid == other_than ? 0 : pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// Whether nothing holds the folder within `seconds` (a process's record locks go with it).
bool released(const std::string& cache, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (farm::CacheLock::holder(cache) != 0)
    if (std::chrono::steady_clock::now() > end) return false;
    else std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return true;
}

TEST(LocalWorkers, DieWithTheirCoordinatorKilledHard) {
  Farm farm({"--local-workers", "2", "--local-worker-threads", "1"});
  farm.start_server();
  ASSERT_TRUE(farm.wait_workers(2));
  const pid_t w0 = wait_holder(slot_cache(farm, 0), 10), w1 = wait_holder(slot_cache(farm, 1), 10);
  ASSERT_GT(w0, 0);
  ASSERT_GT(w1, 0);
  farm.kill_server();
  EXPECT_TRUE(released(slot_cache(farm, 0), 5)) << "local worker " << w0 << " outlived its coordinator";
  EXPECT_TRUE(released(slot_cache(farm, 1), 5)) << "local worker " << w1 << " outlived its coordinator";
}

TEST(LocalWorkers, ARestartedCoordinatorRunsEachSlotOnce) {
  Farm farm({"--local-workers", "1", "--local-worker-threads", "1"});
  // A worker already on slot 0's folder (as one left behind by a coordinator killed hard).
  std::filesystem::create_directories(slot_cache(farm, 0));
  Child left({TESSERA_WORKER_BIN, "--server", "http://127.0.0.1:9", "--name", "local-0", "--cache-dir",
              slot_cache(farm, 0)},
             farm.log("left"));
  const pid_t left_pid = wait_holder(slot_cache(farm, 0), 10);
  ASSERT_EQ(left_pid, left.pid());
  // A second worker on that folder is refused, naming it.
  Child second({TESSERA_WORKER_BIN, "--server", "http://127.0.0.1:9", "--cache-dir", slot_cache(farm, 0)},
               farm.log("second"));
  EXPECT_EQ(second.wait_exit(10), 2);
  std::ifstream log(farm.log("second"));
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("is in use by another worker (pid " + std::to_string(left_pid) + ")"), std::string::npos) << text;
  farm.start_server();
  EXPECT_EQ(left.wait_exit(10), 128 + SIGKILL) << "the leftover worker was not stopped";
  ASSERT_TRUE(farm.wait_workers(1));
  const pid_t now = wait_holder(slot_cache(farm, 0), 10, left_pid);
  EXPECT_GT(now, 0);
  EXPECT_NE(now, left_pid);
  nlohmann::json workers = farm.client().get("/api/v1/workers").json();
  int live = 0;
  for (auto& w : workers["workers"]) live += w["state"] == "idle" || w["state"] == "busy";
  EXPECT_EQ(live, 1);
}

}  // namespace
}  // namespace tessera::test

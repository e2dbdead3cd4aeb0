// The reaper's decision, once a second: which live workers have been silent too long (declared
// lost; their leases are re-issued at once) and which leases outlived their expiry. A pure
// function of the workers' and leases' clocks, unit-tested apart from locks and the store.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <vector>

namespace tessera::server {

struct ReapWorker {
  uint64_t id = 0;
  bool live = false;  // active or draining (a lost or signed-off worker is not reaped again)
  std::chrono::steady_clock::time_point last_seen;
};

struct ReapLease {
  uint64_t id = 0, worker = 0;
  std::chrono::steady_clock::time_point expires;
};

struct Reaping {
  std::vector<uint64_t> lost_workers;
  std::vector<uint64_t> expired_leases;  // past their expiry, not held by a worker declared lost now
  uint64_t leases_of_lost = 0;           // leases the lost workers held (they end with them)
};

/// Silent for longer than `dead_after` (heartbeats, polls and results all count as a sign of life).
Reaping decide_reaping(std::span<const ReapWorker> workers, std::span<const ReapLease> leases,
                       std::chrono::steady_clock::time_point now, std::chrono::steady_clock::duration dead_after);

}  // namespace tessera::server

// What /metrics reports: the farm's counters and latency histograms, which requests update without
// the coordinator's lock (atomics; the histograms lock themselves), and a snapshot of the rest
// (jobs, workers, leases, retention, the group commit) taken under the lock and rendered off it in
// Prometheus' text format.
#pragma once

#include "metrics.h"
#include "retention.h"

#include <atomic>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace tessera::server {

struct FarmCounters {
  std::atomic<uint64_t> leased{0}, done{0}, expired{0}, failed{0}, duplicates{0}, speculative{0}, mismatched{0};
  std::atomic<uint64_t> bytes_in{0}, bytes_out{0};
  // The most leases this process issued for one unit of any job (1: nothing leased twice).
  std::atomic<uint64_t> max_leases_per_unit{0};
};

/// The state /metrics shows beside the counters, copied under the coordinator's lock.
struct MetricsSnapshot {
  std::map<std::string, int> jobs_by_phase, workers_by_state;
  struct Worker {
    uint64_t id = 0;
    std::string name;
    double samples_per_second = 0;
    uint64_t scene_bytes = 0;
  };
  std::vector<Worker> workers;
  size_t leases_active = 0;
  RetentionState retention;
  uint64_t commits = 0, failed_commits = 0, committed_records = 0;
  uint64_t webhooks_delivered = 0, webhooks_failed = 0;
};

class FarmMetrics {
 public:
  FarmCounters counters;
  Histogram lease_wait{{0.001, 0.01, 0.1, 0.5, 1, 2.5, 5, 10, 20, 30}};
  Histogram upload_seconds{{0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 1}};

  void note_leases_per_unit(uint64_t n) {
    uint64_t seen = counters.max_leases_per_unit.load();
    while (n > seen && !counters.max_leases_per_unit.compare_exchange_weak(seen, n)) {
    }
  }
  /// The whole /metrics page.
  std::string render(const MetricsSnapshot& snapshot) const;
};

}  // namespace tessera::server

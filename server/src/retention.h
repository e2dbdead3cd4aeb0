// Retention: finished jobs (done, failed, cancelled) older than --retain-days, or the oldest of
// them while the data directory holds more than --retain-bytes, are deleted with their stored
// results, lease log and image; bundles (and their unpacked folders) that no remaining job
// references go too when they are older than the age limit or are needed to get under the size.
// Nothing of a queued or running job is ever touched.
//
// Size counted: stored checkpoints and result bytes (compressed tile sums in SQLite) + job images +
// bundle files + unpacked scene folders. The SQLite file itself does not shrink in databases created
// before retention existed: SQLite reuses the freed pages; new databases (auto_vacuum=INCREMENTAL)
// give them back at the end of each pass.
//
// The pass (Coordinator::Impl::run_retention) runs from the reaper thread at start-up and then
// every CoordinatorOptions::maintenance_interval seconds, and on Coordinator::apply_retention().
// It takes a snapshot of the jobs under `mu`, measures files off it, decides with a pure plan
// (retention_plan.h), deletes rows under `mu`, and deletes files outside it: bundle files and
// folders are renamed into data-dir/tmp under the lock (so a submission never sees half a bundle)
// and removed after.
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace tessera::server {

struct RetentionState {
  uint64_t deleted_jobs = 0, deleted_bundles = 0, freed_bytes = 0, passes = 0;
  uint64_t data_bytes = 0;  // as last measured
  // Stored result bytes of finished jobs (they no longer change): measured once.
  std::map<uint64_t, uint64_t> finished_result_bytes;
};

/// A bundle never used this recently is kept even under the size limit: it may have been uploaded
/// for a submission that is about to come.
constexpr double kBundleGraceSeconds = 600;

/// Marks a bundle as used now (its modification time is its last use); false if it is missing.
bool touch_bundle(const std::string& path);

/// /metrics series: tessera_retention_deleted_total{what}, tessera_retention_freed_bytes_total,
/// tessera_retention_passes_total, tessera_data_bytes, tessera_disk_full_errors_total.
std::string retention_metrics(const RetentionState& state);

}  // namespace tessera::server

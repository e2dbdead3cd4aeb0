// Retention's decision as a pure function: which finished jobs and which unused bundles a pass
// deletes, from a snapshot of the jobs and the bundles' sizes and last uses. The pass that takes
// the snapshot and carries the plan out is Coordinator::Impl::run_retention (retention.cpp).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace tessera::server {

struct RetentionJob {
  uint64_t id = 0;
  bool finished = false;  // done, failed or cancelled (queued and running jobs are never deleted)
  double ended = 0;       // when it ended (finished) or was created
  std::string scene;      // its bundle's hash
  uint64_t bytes = 0;     // stored checkpoints and results + image
};

struct RetentionBundle {
  uint64_t bytes = 0;     // bundle file + unpacked folder
  double last_use = 0;    // uploaded, submitted or downloaded (its file's time)
};

struct RetentionLimits {
  double max_age = 0;          // seconds since a finished job ended; 0: no age limit
  uint64_t max_bytes = 0;      // 0: no size limit
  double bundle_grace = 600;   // an unused bundle this recent is kept under the size limit
};

struct RetentionPlan {
  std::vector<uint64_t> jobs;         // to delete, oldest first
  std::vector<std::string> bundles;   // to delete
  uint64_t total = 0;                 // bytes before
  uint64_t remaining = 0;             // bytes after
};

/// The age limit first (finished jobs ended more than max_age ago; bundles no remaining job uses,
/// last used more than max_age ago), then, while over max_bytes, the oldest finished job or unused
/// bundle (a bundle's last use counts its finished jobs' ends), whichever is older. A bundle a
/// queued or running job uses is never deleted, nor one used within bundle_grace under the size
/// limit.
RetentionPlan plan_retention(const std::vector<RetentionJob>& jobs, const std::map<std::string, RetentionBundle>& bundles,
                             const RetentionLimits& limits, double now);

}  // namespace tessera::server

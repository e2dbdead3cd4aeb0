// What the coordinator answers about jobs (docs/api.md): a job's full status (GET /jobs/ID, the
// answer to a submission, the webhook's body) and the summary per job of GET /jobs.
#pragma once

#include "tessera/farm/protocol.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

/// One worker's part of a job's samples.
struct WorkerShare {
  uint64_t id = 0;
  std::string name;
  uint64_t samples = 0;
  double share = 0;  // of the job's samples done
};

struct JobStatus {
  uint64_t id = 0;
  std::string name, state, error;  // state: queued, running, done, failed, cancelled
  int priority = 0;
  JobSettings settings;            // as resolved from the scene
  std::string scene_file;
  int width = 0, height = 0, spp = 0;
  uint64_t tiles = 0, passes = 0, units_done = 0, units_total = 0;
  uint64_t samples_done = 0, samples_total = 0;
  double progress = 0, elapsed_seconds = 0, eta_seconds = 0, created = 0, samples_per_second = 0;
  std::vector<WorkerShare> workers;
  uint64_t duplicate_results = 0, mismatched_results = 0, result_bytes = 0, lease_bytes = 0;
  uint64_t nonfinite_samples = 0;
  std::optional<double> noise_estimate;  // relMSE of the image now; none until every pixel has 2 samples
  double target_error = 0;
  uint32_t spp_done = 0;  // complete passes' samples per pixel
  bool stopped_at_target = false;
  /// A guided job's learned tree: guides stored so far (the first, then one per training pass
  /// done), and the latest one's size in memory.
  struct Guide {
    uint32_t iterations = 0;
    uint64_t leaves = 0, bytes = 0;
    float predicted_gain = 0.f;  // 0 before the deciding iteration (guide_gain.h)
    bool stepped_aside = false;
  };
  std::optional<Guide> guide;
  /// An sppm or vcm job's point maps: maps stored so far (one per pass), and the latest one's
  /// records in bytes (what a worker holds of it, before its grid's index).
  struct PointMap {
    uint32_t iterations = 0;
    uint64_t bytes = 0;
  };
  std::optional<PointMap> point_map;
  /// A denoised job's images (settings.denoise): "waiting" for its units, "running" (the raw image
  /// and the denoised one being made), "done", or "failed" with the reason in denoise_error (the
  /// job is done with its raw image).
  std::string denoise_state, denoise_error;
  // From the lease log; absent when it could not be read.
  std::optional<uint64_t> leases_issued, max_leases_per_unit, reissued_acknowledged_passes;
};

nlohmann::json to_json(const JobStatus& s);

struct JobSummary {
  uint64_t id = 0;
  std::string name, state, error;
  int priority = 0;
  double progress = 0;
  int width = 0, height = 0, spp = 0;
};

nlohmann::json to_json(const JobSummary& s);

/// The answer to a submission: the job's status, or with "frames" A..B one per frame (as
/// {"jobs": [...], "frames": [A, B]}).
struct JobSubmission {
  std::vector<JobStatus> jobs;
  std::optional<std::pair<int, int>> frames;
};

nlohmann::json to_json(const JobSubmission& s);

}  // namespace tessera

// What the coordinator answers about itself, its workers and stored scenes (docs/api.md): GET
// /workers, GET /healthz and an uploaded bundle.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace tessera {

struct WorkerStatus {
  uint64_t id = 0;
  std::string name, state;  // state: idle, busy, draining, lost, gone
  int threads = 0;
  uint64_t units_done = 0, samples_done = 0;
  double samples_per_second = 0;  // over its render time
  uint64_t scene_memory_bytes = 0;  // scenes and guides loaded in its cache (heartbeat)
  uint32_t scenes_loaded = 0;
  uint64_t memory_budget_bytes = 0;  // what its cache may hold (registration)
};

nlohmann::json to_json(const WorkerStatus& w);

struct Health {
  std::string status;  // ok, stopping
  std::string version;
  uint64_t jobs_active = 0, leases = 0;
  double uptime_seconds = 0;
};

nlohmann::json to_json(const Health& h);

/// A scene bundle as stored: its SHA-256 (the scene's name in job settings), size and files.
struct SceneUpload {
  std::string hash;
  uint64_t bytes = 0;
  std::vector<std::string> files;
};

nlohmann::json to_json(const SceneUpload& s);

}  // namespace tessera

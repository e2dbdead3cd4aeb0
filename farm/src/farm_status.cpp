#include "tessera/farm/farm_status.h"

namespace tessera {

using json = nlohmann::json;

json to_json(const WorkerStatus& w) {
  return {{"id", w.id},
          {"name", w.name},
          {"threads", w.threads},
          {"state", w.state},
          {"units_done", w.units_done},
          {"samples_done", w.samples_done},
          {"samples_per_second", w.samples_per_second},
          {"scene_memory_bytes", w.scene_memory_bytes},
          {"scenes_loaded", w.scenes_loaded},
          {"memory_budget_bytes", w.memory_budget_bytes}};
}

json to_json(const Health& h) {
  return {{"status", h.status},
          {"version", h.version},
          {"jobs_active", h.jobs_active},
          {"leases", h.leases},
          {"uptime_seconds", h.uptime_seconds}};
}

json to_json(const SceneUpload& s) { return {{"hash", s.hash}, {"bytes", s.bytes}, {"files", s.files}}; }

}  // namespace tessera

#include "tessera/farm/job_status.h"

namespace tessera {

using json = nlohmann::json;

namespace {
json optional_json(const auto& v) { return v ? json(*v) : json(nullptr); }
}  // namespace

json to_json(const JobStatus& s) {
  json workers = json::array();
  for (const WorkerShare& w : s.workers)
    workers.push_back({{"id", w.id}, {"name", w.name}, {"samples", w.samples}, {"share", w.share}});
  json j = {{"id", s.id},
            {"name", s.name},
            {"state", s.state},
            {"priority", s.priority},
            {"error", s.error},
            {"settings", to_json(s.settings)},
            {"scene_file", s.scene_file},
            {"width", s.width},
            {"height", s.height},
            {"spp", s.spp},
            {"tiles", s.tiles},
            {"passes", s.passes},
            {"units_done", s.units_done},
            {"units_total", s.units_total},
            {"samples_done", s.samples_done},
            {"samples_total", s.samples_total},
            {"progress", s.progress},
            {"elapsed_seconds", s.elapsed_seconds},
            {"eta_seconds", s.eta_seconds},
            {"created", s.created},
            {"workers", workers},
            {"duplicate_results", s.duplicate_results},
            {"mismatched_results", s.mismatched_results},
            {"result_bytes", s.result_bytes},
            {"lease_bytes", s.lease_bytes},
            {"nonfinite_samples", s.nonfinite_samples},
            {"samples_per_second", s.samples_per_second},
            {"noise_estimate", optional_json(s.noise_estimate)},
            {"target_error", s.target_error},
            {"spp_done", s.spp_done},
            {"stopped_at_target", s.stopped_at_target}};
  j["denoise_state"] = s.denoise_state.empty() ? json(nullptr) : json(s.denoise_state);
  j["denoise_error"] = s.denoise_error.empty() ? json(nullptr) : json(s.denoise_error);
  j["guide"] = s.guide ? json{{"iterations", s.guide->iterations},
                              {"leaves", s.guide->leaves},
                              {"bytes", s.guide->bytes},
                              {"predicted_gain", s.guide->predicted_gain},
                              {"stepped_aside", s.guide->stepped_aside}}
                       : json(nullptr);
  j["point_map"] = s.point_map ? json{{"iterations", s.point_map->iterations}, {"bytes", s.point_map->bytes}} : json(nullptr);
  // (Left out rather than null when the lease log could not be read, as before.)
  if (s.leases_issued) j["leases_issued"] = *s.leases_issued;
  if (s.max_leases_per_unit) j["max_leases_per_unit"] = *s.max_leases_per_unit;
  if (s.reissued_acknowledged_passes) j["reissued_acknowledged_passes"] = *s.reissued_acknowledged_passes;
  return j;
}

json to_json(const JobSubmission& s) {
  if (!s.frames) return s.jobs.empty() ? json::object() : to_json(s.jobs.front());
  json jobs = json::array();
  for (const JobStatus& j : s.jobs) jobs.push_back(to_json(j));
  return {{"jobs", jobs}, {"frames", {s.frames->first, s.frames->second}}};
}

json to_json(const JobSummary& s) {
  return {{"id", s.id},       {"name", s.name},         {"state", s.state},   {"priority", s.priority},
          {"progress", s.progress}, {"width", s.width}, {"height", s.height}, {"spp", s.spp},
          {"error", s.error}};
}

}  // namespace tessera

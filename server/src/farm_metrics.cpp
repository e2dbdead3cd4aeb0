#include "farm_metrics.h"

namespace tessera::server {

namespace {

std::string labelled(const std::string& name, const std::string& label, const std::map<std::string, int>& counts) {
  std::string out;
  for (const auto& [key, n] : counts) out += name + "{" + label + "=\"" + key + "\"} " + std::to_string(n) + "\n";
  return out;
}

std::string passes(const FarmCounters& c) {
  std::string out = metric_header("tessera_passes_total", "counter",
                                  "Tile passes leased, done, expired, failed, duplicated, speculatively leased, mismatched.");
  for (auto [event, n] : {std::pair{"leased", c.leased.load()}, std::pair{"done", c.done.load()},
                          std::pair{"expired", c.expired.load()}, std::pair{"failed", c.failed.load()},
                          std::pair{"duplicate", c.duplicates.load()}, std::pair{"speculative", c.speculative.load()},
                          std::pair{"mismatched", c.mismatched.load()}})
    out += std::string("tessera_passes_total{event=\"") + event + "\"} " + std::to_string(n) + "\n";
  out += metric_header("tessera_max_leases_per_unit", "gauge",
                       "The most leases issued for one unit of any job since the coordinator started.");
  out += "tessera_max_leases_per_unit " + std::to_string(c.max_leases_per_unit.load()) + "\n";
  return out;
}

std::string workers(const MetricsSnapshot& s) {
  std::string out = metric_header("tessera_workers", "gauge", "Workers by state.");
  out += labelled("tessera_workers", "state", s.workers_by_state);
  out += metric_header("tessera_worker_samples_per_second", "gauge", "Pixel samples per second of render time, per worker.");
  for (const MetricsSnapshot::Worker& w : s.workers)
    out += "tessera_worker_samples_per_second{worker=\"" + std::to_string(w.id) + "\",name=\"" + escape_label(w.name) +
           "\"} " + std::to_string(w.samples_per_second) + "\n";
  out += metric_header("tessera_worker_scene_memory_bytes", "gauge", "Bytes of scenes loaded in a worker's cache, per worker.");
  for (const MetricsSnapshot::Worker& w : s.workers)
    out += "tessera_worker_scene_memory_bytes{worker=\"" + std::to_string(w.id) + "\",name=\"" + escape_label(w.name) +
           "\"} " + std::to_string(w.scene_bytes) + "\n";
  return out;
}

std::string store_and_hooks(const MetricsSnapshot& s) {
  std::string out = metric_header("tessera_webhooks_total", "counter", "Job webhooks delivered and given up on.");
  out += "tessera_webhooks_total{result=\"delivered\"} " + std::to_string(s.webhooks_delivered) + "\n";
  out += "tessera_webhooks_total{result=\"failed\"} " + std::to_string(s.webhooks_failed) + "\n";
  out += retention_metrics(s.retention);
  out += metric_header("tessera_store_commits_total", "counter",
                       "State database transactions committed by the group commit (one WAL fsync each), and failed.");
  out += "tessera_store_commits_total{result=\"committed\"} " + std::to_string(s.commits) + "\n";
  out += "tessera_store_commits_total{result=\"failed\"} " + std::to_string(s.failed_commits) + "\n";
  out += metric_header("tessera_store_records_total", "counter", "Leases, results and phase changes committed by the group commit.");
  out += "tessera_store_records_total " + std::to_string(s.committed_records) + "\n";
  return out;
}

}  // namespace

std::string FarmMetrics::render(const MetricsSnapshot& s) const {
  std::string out = metric_header("tessera_jobs", "gauge", "Jobs by state.");
  out += labelled("tessera_jobs", "state", s.jobs_by_phase);
  out += passes(counters);
  out += metric_header("tessera_leases_active", "gauge", "Leases in flight.");
  out += "tessera_leases_active " + std::to_string(s.leases_active) + "\n";
  out += workers(s);
  out += lease_wait.render("tessera_lease_wait_seconds", "Time a lease request waited (long poll) before its answer.");
  out += upload_seconds.render("tessera_upload_seconds", "Time to verify and commit an uploaded tile result.");
  out += metric_header("tessera_bytes_total", "counter", "Payload bytes received (bundles, results) and sent (leases, bundles, images).");
  out += "tessera_bytes_total{direction=\"in\"} " + std::to_string(counters.bytes_in.load()) + "\n";
  out += "tessera_bytes_total{direction=\"out\"} " + std::to_string(counters.bytes_out.load()) + "\n";
  out += store_and_hooks(s);
  return out;
}

}  // namespace tessera::server

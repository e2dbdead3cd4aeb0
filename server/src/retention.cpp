#include "retention.h"
#include "retention_plan.h"

#include "coordinator_impl.h"
#include "disk_full.h"
#include "event_log.h"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <ctime>
#include <filesystem>
#include <set>

namespace tessera::server {

namespace fs = std::filesystem;

namespace {

double to_wall(fs::file_time_type t) {
  return std::chrono::duration<double>(std::chrono::file_clock::to_sys(t).time_since_epoch()).count();
}

uint64_t tree_bytes(const fs::path& dir) {
  uint64_t n = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) n += it->file_size(ec);
  return n;
}

std::string utc(double t) {
  const std::time_t s = std::time_t(t);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace

bool touch_bundle(const std::string& path) {
  std::error_code ec;
  fs::last_write_time(path, fs::file_time_type::clock::now(), ec);
  return !ec;
}

Status Coordinator::Impl::missing_job(uint64_t id) {
  try {
    if (std::optional<double> when = store.expired_job(id))
      return make_error(Code::NotFound, "unknown_job",
                        "job " + std::to_string(id) + " expired by retention at " + utc(*when) +
                            " (--retain-days / --retain-bytes): its results and image are deleted");
  } catch (const std::exception&) {
  }
  return unknown_job(id);
}

std::optional<std::vector<RetentionJob>> Coordinator::Impl::retention_snapshot() {
  std::vector<uint64_t> unmeasured;
  std::set<uint64_t> ended;  // of those, the jobs that had ended (their stored bytes no longer change)
  bool every_job = false;
  {
    MutexLock lock(mu);
    // Images a full disk kept from being written: the job ended, its film is still in memory.
    for (const auto& [id, job] : jobs.all())
      if (is_terminal(job->phase()) && job->has_film()) finish_job(*job, /*notify=*/true);
    for (const auto& [id, job] : jobs.all())
      if (!is_terminal(job->phase()) || !retention.finished_result_bytes.count(id)) {
        unmeasured.push_back(id);
        if (is_terminal(job->phase())) ended.insert(id);
      }
    every_job = unmeasured.size() == jobs.size();
  }
  std::map<uint64_t, uint64_t> measured;
  try {  // (store reads: off the lock)
    // Once (at start-up) every job is unmeasured: one grouped query instead of one per job.
    for (const auto& [id, bytes] : every_job ? store.result_bytes() : store.result_bytes(unmeasured)) measured[id] = bytes;
  } catch (const std::exception& e) {
    spdlog::warn("retention: cannot measure stored results: {}", e.what());
    return std::nullopt;
  }
  MutexLock lock(mu);
  for (uint64_t id : unmeasured) {
    if (ended.count(id)) retention.finished_result_bytes[id] = measured[id];
    else retention.finished_result_bytes.erase(id);  // (retried: measured again when it ends)
  }
  std::vector<RetentionJob> snapshot;
  for (const auto& [id, job] : jobs.all()) {
    const bool finished = is_terminal(job->phase());
    auto known = retention.finished_result_bytes.find(id);
    snapshot.push_back({id, finished, job->finished > 0 ? job->finished : job->created(), job->plan().settings.scene,
                        finished && known != retention.finished_result_bytes.end() ? known->second : measured[id]});
  }
  return snapshot;
}

std::map<std::string, RetentionBundle> Coordinator::Impl::measure_retention_files(std::vector<RetentionJob>& snapshot) {
  std::error_code ec;
  for (RetentionJob& j : snapshot)
    for (const std::string& path : {image_path(j.id), denoised_path(j.id)}) {  // (a denoised job has both)
      const uintmax_t image = fs::file_size(path, ec);
      if (!ec) j.bytes += image;
    }
  std::map<std::string, RetentionBundle> bundles;
  for (auto it = fs::directory_iterator(fs::path(opt.data_dir) / "bundles", ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    if (it->path().extension() != ".bundle") continue;
    RetentionBundle& b = bundles[it->path().stem().string()];
    b.bytes += it->file_size(ec);
    b.last_use = std::max(b.last_use, to_wall(it->last_write_time(ec)));
  }
  for (auto it = fs::directory_iterator(fs::path(opt.data_dir) / "scenes", ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.find('.') != std::string::npos || !it->is_directory(ec)) continue;  // (.tmp-/.old- of an unpack in flight)
    bundles[name].bytes += tree_bytes(it->path());
  }
  return bundles;
}

std::optional<RetentionReport> Coordinator::Impl::run_retention(double now) {
  std::optional<std::vector<RetentionJob>> snapshot = retention_snapshot();
  if (!snapshot) return std::nullopt;
  const std::map<std::string, RetentionBundle> bundles = measure_retention_files(*snapshot);  // (off the lock)
  const RetentionPlan plan =
      plan_retention(*snapshot, bundles, {opt.retain_days * 86400.0, opt.retain_bytes, kBundleGraceSeconds}, now);
  if (opt.retain_bytes > 0 && plan.remaining > opt.retain_bytes)
    spdlog::warn("retention: the data dir holds {} bytes of queued, running or recent work, over --retain-bytes {}",
                 plan.remaining, opt.retain_bytes);
  return carry_out_retention(plan, *snapshot, bundles, now);
}

RetentionReport Coordinator::Impl::carry_out_retention(const RetentionPlan& plan, const std::vector<RetentionJob>& snapshot,
                                                       const std::map<std::string, RetentionBundle>& bundles, double now) {
  std::vector<fs::path> trash;  // removed after the lock: images (raw, denoised), renamed bundles and scene folders
  std::vector<const RetentionJob*> forgotten;
  std::vector<std::string> moved;
  {
    MutexLock lock(mu);
    std::map<uint64_t, const RetentionJob*> by_id;
    for (const RetentionJob& j : snapshot) by_id[j.id] = &j;
    for (uint64_t id : plan.jobs)
      if (forget_expired_job(*by_id.at(id))) forgotten.push_back(by_id.at(id));
    for (const std::string& hash : plan.bundles)
      if (move_expired_bundle(hash, bundles.at(hash), trash)) moved.push_back(hash);
  }
  RetentionReport report;
  for (const RetentionJob* j : delete_expired_rows(forgotten, moved, now)) {
    trash.push_back(image_path(j->id));
    trash.push_back(denoised_path(j->id));
    ++report.deleted_jobs;
    report.freed_bytes += j->bytes;
  }
  for (const std::string& hash : moved) report.freed_bytes += bundles.at(hash).bytes;
  report.deleted_bundles = moved.size();
  report.data_bytes = plan.total >= report.freed_bytes ? plan.total - report.freed_bytes : 0;
  if (report.deleted_jobs > 0) collect_unused_guides(trash);
  std::error_code ec;
  for (const fs::path& p : trash) fs::remove_all(p, ec);
  MutexLock lock(mu);
  retention.deleted_jobs += report.deleted_jobs;
  retention.deleted_bundles += report.deleted_bundles;
  retention.freed_bytes += report.freed_bytes;
  retention.data_bytes = report.data_bytes;
  ++retention.passes;
  return report;
}

// Guide files are shared by hash (the first tree of one scene is the same for every job of it), so
// a deleted job's are removed once no job names them. A file younger than an hour may belong to a
// guide whose row is still being committed.
void Coordinator::Impl::collect_unused_guides(std::vector<fs::path>& trash) {
  const std::set<std::string> used = store.guide_hashes();
  std::error_code ec;
  const auto hour_ago = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (const auto& entry : fs::directory_iterator(fs::path(opt.data_dir) / "guides", ec))
    if (entry.path().extension() == ".guide" && !used.count(entry.path().stem().string()) &&
        entry.last_write_time(ec) < hour_ago)
      trash.push_back(entry.path());
}

bool Coordinator::Impl::forget_expired_job(const RetentionJob& j) {
  const JobState* job = jobs.find(j.id);
  // Retried (queued again) since the snapshot: not finished any more.
  if (!job || !is_terminal(job->phase()) || (job->finished > 0 ? job->finished : job->created()) != j.ended)
    return false;
  end_leases(leases.of_job(j.id));
  jobs.erase(j.id);
  retention.finished_result_bytes.erase(j.id);
  return true;
}

std::vector<const RetentionJob*> Coordinator::Impl::delete_expired_rows(const std::vector<const RetentionJob*>& jobs,
                                                                        const std::vector<std::string>& bundles,
                                                                        double now) {
  std::vector<const RetentionJob*> deleted;
  for (const RetentionJob* j : jobs) try {
      store.delete_job(j->id, now);
      deleted.push_back(j);
      log_event(spdlog::level::info, "job.expired", {{"job", j->id}, {"bytes", j->bytes}});
    } catch (const std::exception& e) {
      spdlog::warn("retention: cannot delete job {}: {} (it is back after a restart)", j->id, e.what());
    }
  for (const std::string& hash : bundles) try {
      store.delete_scene(hash);
    } catch (const std::exception&) {
    }
  if (!deleted.empty()) try {
      store.incremental_vacuum();
    } catch (const std::exception& e) {
      spdlog::warn("retention: incremental vacuum failed: {}", e.what());
    }
  return deleted;
}

bool Coordinator::Impl::bundle_in_use(const std::string& hash, int own_holds) const {
  if (auto held = bundle_holds.find(hash); held != bundle_holds.end() && held->second > own_holds) return true;
  for (const auto& [id, job] : jobs.all())
    if (job->plan().settings.scene == hash) return true;
  return false;
}

void Coordinator::Impl::move_bundle_aside(const std::string& hash, const char* why, std::vector<fs::path>& trash) {
  static std::atomic<uint64_t> trash_counter{0};
  // Renamed away under the lock: a submission finds the bundle whole or not at all.
  std::error_code ec;
  const std::string tag = std::to_string(::getpid()) + "-" + std::to_string(++trash_counter);
  for (const fs::path& p : {fs::path(bundle_path(hash)), fs::path(scene_dir(hash))}) {
    if (!fs::exists(p, ec)) continue;
    const fs::path to = fs::path(opt.data_dir) / "tmp" / (std::string(why) + "-" + tag + "-" + p.filename().string());
    fs::rename(p, to, ec);
    if (!ec) trash.push_back(to);
  }
}

bool Coordinator::Impl::move_expired_bundle(const std::string& hash, const RetentionBundle& b, std::vector<fs::path>& trash) {
  std::error_code ec;
  const fs::path file = bundle_path(hash);
  // (Used by a job or a submission since the snapshot, or touched by one since.)
  if (bundle_in_use(hash, 0) || (fs::exists(file, ec) && to_wall(fs::last_write_time(file, ec)) > b.last_use))
    return false;
  move_bundle_aside(hash, "expired", trash);
  log_event(spdlog::level::info, "bundle.expired", {{"scene", hash}, {"bytes", b.bytes}});
  return true;
}

void Coordinator::Impl::BundleHold::take(const std::string& hash) {
  MutexLock lock(s_.mu);
  ++s_.bundle_holds[hash];
  hash_ = hash;
}

Coordinator::Impl::BundleHold::~BundleHold() {
  if (hash_.empty()) return;
  MutexLock lock(s_.mu);
  if (auto it = s_.bundle_holds.find(hash_); it != s_.bundle_holds.end() && --it->second == 0) s_.bundle_holds.erase(it);
}

void Coordinator::Impl::discard_bundle(const std::string& hash) {
  std::vector<fs::path> trash;
  {
    // A job or another submission using the same bundle keeps it (its caller holds it once).
    MutexLock lock(mu);
    if (bundle_in_use(hash, 1)) return;
    move_bundle_aside(hash, "refused", trash);
  }
  std::error_code ec;
  for (const fs::path& p : trash) fs::remove_all(p, ec);
  try {
    store.delete_scene(hash);
  } catch (const std::exception& e) {
    spdlog::warn("cannot forget refused bundle {}: {}", hash, e.what());
  }
  log_event(spdlog::level::info, "bundle.refused", {{"scene", hash}});
}

Result<RetentionReport> Coordinator::apply_retention(double now) {
  std::optional<RetentionReport> report = impl_->run_retention(now > 0 ? now : wall_seconds());
  if (!report) return make_error(Code::Internal, "retention_failed", "cannot measure stored results");
  return *report;
}

std::string retention_metrics(const RetentionState& r) {
  std::string out = metric_header("tessera_retention_deleted_total", "counter", "Finished jobs and bundles deleted by retention.");
  out += "tessera_retention_deleted_total{what=\"jobs\"} " + std::to_string(r.deleted_jobs) + "\n";
  out += "tessera_retention_deleted_total{what=\"bundles\"} " + std::to_string(r.deleted_bundles) + "\n";
  out += metric_header("tessera_retention_freed_bytes_total", "counter", "Bytes of results, images and bundles deleted by retention.");
  out += "tessera_retention_freed_bytes_total " + std::to_string(r.freed_bytes) + "\n";
  out += metric_header("tessera_retention_passes_total", "counter", "Retention passes run.");
  out += "tessera_retention_passes_total " + std::to_string(r.passes) + "\n";
  out += metric_header("tessera_data_bytes", "gauge",
                       "Stored results, images, bundles and unpacked scenes in the data dir (at the last retention pass).");
  out += "tessera_data_bytes " + std::to_string(r.data_bytes) + "\n";
  out += metric_header("tessera_disk_full_errors_total", "counter", "Requests answered 507 because the disk was full.");
  out += "tessera_disk_full_errors_total " + std::to_string(disk_full_errors()) + "\n";
  return out;
}

}  // namespace tessera::server

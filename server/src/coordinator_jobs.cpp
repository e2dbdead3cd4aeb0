// Scenes and jobs: upload, submit (the scene is loaded here, so a broken one fails the request),
// status, image, cancel.
#include "coordinator_impl.h"
#include "disk_full.h"
#include "event_log.h"
#include "scene_planner.h"

#include "tessera/farm/mapped_file.h"
#include "tessera/farm/sha256.h"
#include "tessera/image/image.h"
#include "tessera/scene/error.h"

#include <spdlog/spdlog.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace tessera::server {

namespace fs = std::filesystem;
using nlohmann::json;

// Written to a temporary name, fsync'd, renamed, directory fsync'd: after a crash the file is
// either complete or absent.
void write_file_durably(const std::string& path, const std::string& bytes) {
  // A name of its own: two submissions of one new bundle may write it at once (same bytes; the
  // second rename replaces the first file whole).
  static std::atomic<uint64_t> writes{0};
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(++writes);
  const std::string data_dir = fs::path(path).parent_path().parent_path().string();
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw_write_error("cannot create " + tmp, errno, data_dir);
  size_t off = 0;
  while (off < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + off, bytes.size() - off);
    if (n < 0) {
      int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw_write_error("cannot write " + tmp, err, data_dir);
    }
    off += size_t(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    int err = errno;
    ::unlink(tmp.c_str());
    throw_write_error("cannot sync " + tmp, err, data_dir);
  }
  fs::rename(tmp, path);
  int dir = ::open(fs::path(path).parent_path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Result<SceneUpload> Coordinator::upload_scene(const std::string& bundle) {
  bool written = false;
  Impl::BundleHold hold(*impl_);
  return impl_->store_bundle(bundle, written, hold);
}

Result<SceneUpload> Coordinator::Impl::store_bundle(const std::string& bundle, bool& written, BundleHold& hold) {
  if (bundle.size() > opt.max_upload_bytes)
    return make_error(Code::PayloadTooLarge, "bundle_too_large",
                      "the bundle has " + std::to_string(bundle.size()) + " bytes; the limit is " +
                          std::to_string(opt.max_upload_bytes) + " (tessera-server --max-upload)");
  BundleResult inspected = inspect_bundle(bundle, opt.bundle_limits);
  if (!inspected.ok()) return make_error(Code::BadRequest, "bad_bundle", inspected.error);
  const std::string hash = sha256_hex(bundle);
  hold.take(hash);
  try {
    written = !touch_bundle(bundle_path(hash));
    if (written) write_file_durably(bundle_path(hash), bundle);
    store.add_scene(hash, bundle.size(), wall_seconds());
    metrics.counters.bytes_in += bundle.size();
  } catch (const std::exception& e) {
    if (written) discard_bundle(hash);  // (refused after it was written: not kept)
    return internal_error(e);
  }
  SceneUpload upload{hash, bundle.size(), {}};
  for (const BundleEntry& e : inspected.files) upload.files.push_back(e.path);
  return upload;
}

Result<std::string> Coordinator::scene_bundle_path(const std::string& hash) {
  if (!is_sha256_hex(hash)) return make_error(Code::BadRequest, "bad_hash", "'" + hash + "' is not a SHA-256 hash");
  std::string path = impl_->bundle_path(hash);
  if (!touch_bundle(path)) return make_error(Code::NotFound, "unknown_scene", "no scene bundle " + hash);
  return path;
}

namespace {

Result<StoredFile> stored_file(const std::string& path, FarmCounters& counters) {
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) return internal_error(std::runtime_error("cannot read " + path + ": " + ec.message()));
  counters.bytes_out += size;
  return StoredFile{path, size};
}

}  // namespace

Result<StoredFile> Coordinator::scene_bundle_file(const std::string& hash) {
  Result<std::string> path = scene_bundle_path(hash);
  if (!path.ok()) return path.status;
  return stored_file(path.value, impl_->metrics.counters);
}

Result<StoredFile> Coordinator::guide_file(const std::string& hash) {
  if (!is_sha256_hex(hash)) return make_error(Code::BadRequest, "bad_hash", "'" + hash + "' is not a SHA-256 hash");
  const std::string path = impl_->guide_path(hash);  // (immutable once written: no lock)
  if (!fs::exists(path)) return make_error(Code::NotFound, "unknown_guide", "no guide " + hash);
  return stored_file(path, impl_->metrics.counters);
}

Result<JobSubmission> Coordinator::submit_frames(const JobRequest& request, const std::string& bundle) {
  const auto [first, last] = *request.frames;
  const int64_t max_frames = std::max(1, impl_->opt.max_active_jobs);
  if (int64_t(last) - first >= max_frames)
    return make_error(Code::Unprocessable, "bad_settings",
                      "job settings: frames " + std::to_string(first) + ".." + std::to_string(last) +
                          " is not a range of 1.." + std::to_string(max_frames) + " frames");
  JobSettings base = request.settings;
  bool written = false;
  Impl::BundleHold hold(*impl_);
  if (!bundle.empty()) {
    Result<SceneUpload> uploaded = impl_->store_bundle(bundle, written, hold);
    if (!uploaded.ok()) return uploaded.status;
    base.scene = uploaded.value.hash;
  }
  const std::string name = base.name.empty() ? "frames" : base.name;
  JobSubmission submitted{{}, std::pair{first, last}};
  std::vector<JobStatus>& jobs = submitted.jobs;
  for (int frame = first; frame <= last; ++frame) {
    JobSettings one = base;
    one.defines["frame"] = std::to_string(frame);
    one.name = name + " frame " + std::to_string(frame);
    Result<JobStatus> r = submit_one(std::move(one), "");
    if (!r.ok()) {
      for (const JobStatus& j : jobs) (void)cancel_job(j.id);
      if (written && jobs.empty()) impl_->discard_bundle(base.scene);
      r.status.detail = "frame " + std::to_string(frame) + ": " + r.status.detail +
                        (jobs.empty() ? "" : " (the " + std::to_string(jobs.size()) + " frame(s) queued before were cancelled)");
      return r.status;
    }
    jobs.push_back(std::move(r.value));
  }
  return submitted;
}

// Unpacked once per bundle (later submissions list the folder); two bundles unpack in parallel.
Result<std::string> Coordinator::Impl::unpack_scene(const JobSettings& settings, const std::string& bundle_file) {
  const std::string dir = scene_dir(settings.scene);
  std::shared_ptr<std::mutex> bundle_mutex;
  {
    std::lock_guard<std::mutex> lock(unpack_mutexes_mu);
    if (unpack_mutexes.size() > 64)  // forget bundles nobody is unpacking
      std::erase_if(unpack_mutexes, [](const auto& entry) { return entry.second.expired(); });
    std::weak_ptr<std::mutex>& slot = unpack_mutexes[settings.scene];
    bundle_mutex = slot.lock();
    if (!bundle_mutex) slot = bundle_mutex = std::make_shared<std::mutex>();
  }
  std::vector<BundleEntry> entries;
  std::string error;
  try {
    std::lock_guard<std::mutex> lock(*bundle_mutex);
    if (fs::exists(dir)) {
      for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) entries.push_back({e.path().lexically_relative(dir).generic_string(), e.file_size()});
    } else {
      const MappedFile bundle(bundle_file);
      BundleResult unpacked = unpack_bundle(bundle.bytes(), dir, opt.bundle_limits);
      throw_if_disk_full(unpacked.error, opt.data_dir);
      if (!unpacked.ok()) return make_error(Code::BadRequest, "bad_bundle", unpacked.error);
      entries = std::move(unpacked.files);
    }
  } catch (const std::exception& e) {
    return internal_error(e);
  }
  std::string scene_file = find_scene_xml(entries, settings.scene_file, error);
  if (scene_file.empty()) return make_error(Code::Unprocessable, "no_scene_file", error);
  return scene_file;
}

Result<JobSubmission> Coordinator::submit_job(const JobRequest& request, const std::string& bundle) {
  if (request.frames) return submit_frames(request, bundle);
  Result<JobStatus> one = submit_one(request.settings, bundle);
  if (!one.ok()) return one.status;
  return JobSubmission{{std::move(one.value)}, std::nullopt};
}

Result<JobStatus> Coordinator::submit_one(JobSettings settings, const std::string& bundle) {
  Impl& s = *impl_;
  std::string error;
  if (!settings.webhook.empty() && !s.opt.webhook_allow.empty() &&
      std::none_of(s.opt.webhook_allow.begin(), s.opt.webhook_allow.end(),
                   [&](const std::string& prefix) { return settings.webhook.rfind(prefix, 0) == 0; }))
    return make_error(Code::Unprocessable, "webhook_not_allowed",
                      "webhook '" + settings.webhook + "' does not start with any --webhook-allow prefix");
  {
    // Checked before the scene is loaded, so a flood of submissions costs no unpacking, and again
    // before the job is stored.
    MutexLock lock(s.mu);
    if (Status st = s.jobs.check_active(s.opt.max_active_jobs); !st.ok()) return st;
  }
  bool written = false;
  Impl::BundleHold hold(s);
  if (!bundle.empty()) {
    Result<SceneUpload> uploaded = s.store_bundle(bundle, written, hold);
    if (!uploaded.ok()) return uploaded.status;
    settings.scene = uploaded.value.hash;
  } else if (!settings.scene.empty()) {
    hold.take(settings.scene);
  }
  // A bundle that came with a job the coordinator refuses is not kept: nothing would ever use it.
  const auto refuse = [&](Status st) {
    if (written) s.discard_bundle(settings.scene);
    return st;
  };
  if (!check_job_limits(settings, s.opt.limits, error)) return refuse(make_error(Code::Unprocessable, "bad_settings", error));
  Result<std::string> path = scene_bundle_path(settings.scene);
  if (!path.ok()) return refuse(path.status);
  Result<std::string> scene_file = s.unpack_scene(settings, path.value);
  if (!scene_file.ok()) return refuse(scene_file.status);
  if (settings.name.empty()) settings.name = default_job_name(scene_file.value);
  const PlanRequest request{s.scene_dir(settings.scene), scene_file.value, settings};
  Result<JobPlan> plan = s.opt.scene_planner.empty() ? plan_scene_here(request)
                                                      : plan_scene_in_child(s.opt.scene_planner, request);
  if (!plan.ok()) return refuse(plan.status);
  if (!check_job_limits(plan.value.settings, s.opt.limits, error))
    return refuse(make_error(Code::Unprocessable, "bad_settings", error));
  Result<JobStatus> added = s.add_job(settings.name, std::move(plan.value));
  if (!added.ok()) return refuse(added.status);
  return added;
}

Result<JobStatus> Coordinator::Impl::add_job(const std::string& name, JobPlan plan) {
  {
    MutexLock lock(mu);
    if (stopping) return make_error(Code::Unavailable, "stopping", "the coordinator is shutting down");
    if (Status st = jobs.check_active(opt.max_active_jobs); !st.ok()) return st;
    jobs.take_slot();
  }
  const double now = wall_seconds();
  const int priority = plan.settings.priority;
  uint64_t id = 0;
  std::unique_ptr<JobState> job;
  try {
    id = store.add_job(name, to_json(plan).dump(), priority, now);
    job = std::make_unique<JobState>(id, std::move(plan), name, priority, now);
  } catch (const std::exception& e) {
    MutexLock lock(mu);
    jobs.give_back_slot();
    return internal_error(e);
  }
  log_event(spdlog::level::info, "job.submitted",
            {{"job", id}, {"name", name}, {"width", job->plan().window.width()},
             {"height", job->plan().window.height()}, {"spp", job->plan().settings.spp}, {"tiles", job->num_tiles()},
             {"passes", job->num_passes()}, {"scene", job->plan().settings.scene}});
  JobStatus status;
  {
    // Stored, so accepted (even if the coordinator began stopping meanwhile: it runs after a restart).
    MutexLock lock(mu);
    jobs.give_back_slot();
    JobState& added = jobs.add(std::move(job));
    status = status_of(added);
    save_decisions(added);
    work_cv.notify_all();
  }
  add_lease_counts(status);
  return status;
}

JobStatus Coordinator::Impl::status_of(const JobState& job) {
  JobStatus s;
  const JobPlan& p = job.plan();
  s.id = job.id();
  s.name = job.name();
  s.state = phase_name(job.phase());
  s.priority = job.priority();
  s.error = job.error;
  if (p.settings.denoise) {
    // (A Done job's error is its denoise error: complete_job.)
    s.denoise_state = job.phase() == JobPhase::Done ? (job.error.empty() ? "done" : "failed")
                      : job.denoise_pending       ? "running"
                                                  : "waiting";
    if (job.phase() == JobPhase::Done) std::swap(s.error, s.denoise_error);
  }
  s.settings = p.settings;
  s.scene_file = p.scene_file;
  s.width = p.window.width();
  s.height = p.window.height();
  s.spp = p.settings.spp;
  s.tiles = job.num_tiles();
  s.passes = job.num_passes();
  s.units_done = job.done_units();
  s.units_total = job.planned_units();
  s.samples_done = job.done_samples();
  s.samples_total = job.total_samples();
  s.progress = job.progress();
  const double end = job.finished > 0 ? job.finished : wall_seconds();
  s.elapsed_seconds = job.started > 0 ? end - job.started : 0;
  s.eta_seconds = s.progress > 0 && s.progress < 1 ? s.elapsed_seconds * (1 - s.progress) / s.progress : 0.0;
  s.created = job.created();
  for (auto& [wid, samples] : job.samples_by_worker()) {
    const WorkerInfo* w = workers.find(wid);
    s.workers.push_back({wid, w ? w->row.name : "", samples,
                         s.samples_done ? double(samples) / double(s.samples_done) : 0});
  }
  s.duplicate_results = job.duplicates;
  s.mismatched_results = job.mismatched;
  s.result_bytes = job.result_bytes;
  s.lease_bytes = job.lease_bytes;
  s.nonfinite_samples = job.counters().nonfinite;
  // Speed and noise: samples/s over the job's running time, and the estimated relMSE of the image
  // now (noise_estimate.h).
  s.samples_per_second = s.elapsed_seconds > 0 ? double(s.samples_done) / s.elapsed_seconds : 0.0;
  if (const NoiseEstimate noise = job.noise(); std::isfinite(noise.rel_mse)) s.noise_estimate = noise.rel_mse;
  s.target_error = p.settings.target_error;
  s.spp_done = job.spp_complete();
  s.stopped_at_target = job.converged();
  if (const GuideTraining* g = job.guide())
    s.guide = JobStatus::Guide{job.guide_iterations(), g->tree_leaves(), g->tree_bytes(), g->predicted_gain(),
                               g->stepped_aside()};
  if (p.points) s.point_map = JobStatus::PointMap{job.sequencer().artifacts_stored(), job.latest_map_bytes};
  return s;
}

void Coordinator::Impl::add_lease_counts(JobStatus& status) {
  try {
    const LeaseCounts counts = store.lease_counts(status.id);
    status.leases_issued = counts.issued;
    status.max_leases_per_unit = counts.max_per_unit;
    status.reissued_acknowledged_passes = store.reissued_after_ack(status.id);
  } catch (const std::exception&) {
  }
}

Result<JobStatus> Coordinator::job_status(uint64_t id) {
  JobStatus status;
  {
    MutexLock lock(impl_->mu);
    const JobState* job = impl_->jobs.find(id);
    if (!job) return impl_->missing_job(id);
    status = impl_->status_of(*job);
  }
  impl_->add_lease_counts(status);
  return status;
}

Result<std::vector<JobSummary>> Coordinator::list_jobs() {
  MutexLock lock(impl_->mu);
  std::vector<JobSummary> list;
  for (const auto& [id, job] : impl_->jobs.all()) {
    const JobPlan& p = job->plan();
    list.push_back({id, job->name(), phase_name(job->phase()), job->error, job->priority(),
                    job->progress(),
                    p.window.width(), p.window.height(), p.settings.spp});
  }
  return list;
}

Status Coordinator::cancel_job(uint64_t id) {
  Impl& s = *impl_;
  MutexLock lock(s.mu);
  JobState* job = s.jobs.find(id);
  if (!job) return unknown_job(id);
  if (is_terminal(job->phase()))
    return make_error(Code::Conflict, "job_finished", "job " + std::to_string(id) + " is already " + phase_name(job->phase()));
  const uint64_t ticket = s.change_phase(*job, JobPhase::Cancelled);
  lock.unlock();
  return s.durable(ticket);
}

Status Coordinator::set_priority(uint64_t id, int priority) {
  Impl& s = *impl_;
  MutexLock lock(s.mu);
  JobState* job = s.jobs.find(id);
  if (!job) return unknown_job(id);
  if (is_terminal(job->phase()))
    return make_error(Code::Conflict, "job_finished",
                      "job " + std::to_string(id) + " is " + phase_name(job->phase()) + "; retry it first");
  s.jobs.set_priority(*job, priority);
  const uint64_t ticket = s.commits.append([id, priority](Store& st) { st.set_job_priority(id, priority); },
                                           GroupCommit::Retry::UntilDurable);
  log_event(spdlog::level::info, "job.priority", {{"job", id}, {"priority", priority}});
  s.work_cv.notify_all();
  lock.unlock();
  return s.durable(ticket);
}

Status Coordinator::retry_job(uint64_t id) {
  Impl& s = *impl_;
  auto not_ended = [id](JobPhase phase) {
    return make_error(Code::Conflict, "job_not_ended",
                      "job " + std::to_string(id) + " is " + phase_name(phase) + "; only failed or cancelled jobs are retried");
  };
  JobRow row;
  {
    MutexLock lock(s.mu);
    const JobState* old = s.jobs.find(id);
    if (!old) return unknown_job(id);
    if (old->phase() != JobPhase::Failed && old->phase() != JobPhase::Cancelled) return not_ended(old->phase());
    row = JobRow{id, old->name(), to_json(old->plan()).dump(), phase_name(old->phase()), old->error, old->priority(),
                 old->created(), old->started, old->finished};
  }
  // The passes it has stay: the job is rebuilt from its checkpoints and results (film included),
  // reading and decoding them off the lock.
  std::unique_ptr<JobState> job;
  try {
    job = s.rebuild_job(row);
  } catch (const std::exception& e) {
    return internal_error(e);
  }
  MutexLock lock(s.mu);
  const JobState* now = s.jobs.find(id);
  if (!now) return unknown_job(id);
  if (now->phase() != JobPhase::Failed && now->phase() != JobPhase::Cancelled)
    return not_ended(now->phase());  // (retried by another request meanwhile)
  JobState& fresh = s.jobs.replace(std::move(job));
  s.save_decisions(fresh);
  s.fold_splats(fresh);
  const uint64_t ticket = s.change_phase(fresh, JobPhase::Queued);
  lock.unlock();
  return s.durable(ticket);
}

}  // namespace tessera::server

// Construction, resume after a restart, lease expiry, health and shutdown.
#include "coordinator_impl.h"
#include "disk_full.h"
#include "event_log.h"

#include "tessera/denoise/denoiser.h"
#include "tessera/sequence/guide_artifact.h"
#include "tessera/farm/sample_counts.h"
#include "tessera/farm/sha256.h"
#include "tessera/farm/tile_result.h"
#include "tessera/image/image.h"

#include <spdlog/spdlog.h>

#include <filesystem>

namespace tessera::server {

namespace fs = std::filesystem;

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

Status internal_error(const std::exception& e) {
  if (is_disk_full(e)) return disk_full_status(e);
  return make_error(Code::Internal, "internal", e.what());
}

int http_status(Code code) {
  switch (code) {
    case Code::Ok: return 200;
    case Code::NotYet: return 202;
    case Code::BadRequest: return 400;
    case Code::NotFound: return 404;
    case Code::Conflict: return 409;
    case Code::Gone: return 410;
    case Code::PayloadTooLarge: return 413;
    case Code::Unprocessable: return 422;
    case Code::TooManyRequests: return 429;
    case Code::Unavailable: return 503;
    case Code::Internal: return 500;
    case Code::InsufficientStorage: return 507;
  }
  return 500;
}

namespace {
std::string prepare_data_dir(const std::string& dir) {
  fs::create_directories(fs::path(dir) / "bundles");
  fs::create_directories(fs::path(dir) / "scenes");
  fs::create_directories(fs::path(dir) / "tmp");
  fs::create_directories(fs::path(dir) / "images");
  fs::create_directories(fs::path(dir) / "guides");
  return (fs::path(dir) / "state.sqlite").string();
}
}  // namespace

Coordinator::Impl::Impl(CoordinatorOptions o)
    : opt(std::move(o)), store(prepare_data_dir(opt.data_dir)), fingerprint(build_fingerprint()) {}

std::string Coordinator::Impl::bundle_path(const std::string& hash) const {
  return (fs::path(opt.data_dir) / "bundles" / (hash + ".bundle")).string();
}
std::string Coordinator::Impl::guide_path(const std::string& hash) const {
  return (fs::path(opt.data_dir) / "guides" / (hash + ".guide")).string();
}
std::string Coordinator::Impl::scene_dir(const std::string& hash) const {
  return (fs::path(opt.data_dir) / "scenes" / hash).string();
}

Coordinator::Coordinator(CoordinatorOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  Impl& s = *impl_;
  // Resume: every job's acknowledged passes go back into its film; leases in flight died with the
  // previous process, so their units are simply available again.
  size_t resumed = 0, passes = 0;
  // (Under the lock: the group commit's callbacks and image writes take it too.)
  std::lock_guard<std::mutex> lock(s.mu);
  s.last_lease_id = s.store.last_lease_seq();
  s.workers_before_start = s.store.last_worker_id();
  for (JobRow& row : s.store.jobs()) {
    JobPhase phase;
    if (!parse_phase(row.state, phase)) phase = JobPhase::Failed;
    // A job that ended has its image on disk: only its bookkeeping is rebuilt, not its film.
    if (is_terminal(phase) && fs::exists(s.image_path(row.id))) {
      auto job = s.job_from_row(row);
      s.store.for_each_result(row.id, [&](ResultRow&& r) {
        if (r.tile < job->num_tiles() && r.pass < job->num_passes()) job->mark_done(job->unit(r.tile, r.pass), r.worker);
      }, /*with_data=*/false);
      if (job->phase == JobPhase::Done && job->done_units() < job->num_units()) job->restore_converged();
      job->release_film();
      s.jobs.emplace(row.id, std::move(job));
      continue;
    }
    JobState& job = *s.jobs.emplace(row.id, s.rebuild_job(row)).first->second;
    s.save_decisions(job);
    passes += job.done_units();
    if (!is_terminal(job.phase) && job.complete()) {  // its last result landed before a crash
      s.complete_job(job);
    } else if (is_terminal(job.phase)) {
      s.finish_job(job, /*notify=*/false);  // it ended before its image was written
    } else {
      ++resumed;
      s.hold_open_leases(job);
    }
  }
  // /metrics counts from what the data dir holds, so "done" never exceeds "leased" after a restart.
  std::tie(s.counters.leased, s.counters.done) = s.store.lease_and_result_counts();
  if (!s.jobs.empty())
    spdlog::info("coordinator: {} jobs in {}, {} resumed with {} acknowledged passes", s.jobs.size(), s.opt.data_dir,
                 resumed, passes);
  s.reaper = std::thread([&s] { s.reap_loop(); });
}

Coordinator::~Coordinator() {
  shutdown();
  if (impl_->reaper.joinable()) impl_->reaper.join();
}

void Coordinator::shutdown() {
  std::lock_guard<std::mutex> lock(impl_->mu);
  impl_->stopping = true;
  impl_->work_cv.notify_all();
}

void Coordinator::Impl::hold_open_leases(JobState& job) {
  // Their workers may still be rendering them: a heartbeat naming the lease re-adopts it, and only
  // a unit nobody claims within dead_after() is leased again (never rendered twice for a restart).
  for (const LeaseRow& l : store.open_leases(job.id())) {
    if (l.tile >= job.num_tiles() || l.pass >= job.num_passes()) continue;
    const size_t unit = job.unit(l.tile, l.pass);
    if (job.is_done(unit)) continue;
    job.lease_started(unit);
    add_lease(LeaseInfo{l.id, job.id(), l.worker, unit, Clock::now() + dead_after()});
  }
}

Status Coordinator::Impl::durable(uint64_t ticket) {
  try {
    commits.wait(ticket);
    return Status::success();
  } catch (const std::exception& e) {
    return internal_error(e);
  }
}

void Coordinator::Impl::add_lease(const LeaseInfo& lease) {
  auto [it, inserted] = leases.try_emplace(lease.id, lease);
  if (!inserted) {
    release_held(it->second.worker);
    it->second = lease;
  }
  ++leases_held[lease.worker];
}

void Coordinator::Impl::end_lease(std::map<uint64_t, LeaseInfo>::iterator it) {
  auto job = jobs.find(it->second.job);
  if (job != jobs.end()) job->second->lease_ended(it->second.unit);
  release_held(it->second.worker);
  leases.erase(it);
  work_cv.notify_all();
}

std::unique_ptr<JobState> Coordinator::Impl::job_from_row(const JobRow& row) const {
  JobPlan plan;
  std::string error;
  if (!job_plan_from_json(nlohmann::json::parse(row.plan_json), plan, error))
    throw std::runtime_error("job " + std::to_string(row.id) + " in the state database: " + error);
  auto job = std::make_unique<JobState>(row.id, std::move(plan), row.name, row.priority, row.created);
  if (!parse_phase(row.state, job->phase)) job->phase = JobPhase::Failed;
  job->error = row.error;
  job->started = row.started;
  job->finished = row.finished;
  return job;
}

std::unique_ptr<JobState> Coordinator::Impl::rebuild_job(const JobRow& row) {
  auto job = job_from_row(row);
  const std::string where = "job " + std::to_string(row.id) + ": ";
  job->begin_rebuild();
  if (job->sequencer().builder()) restore_guide(*job);
  // An adaptive job's decided passes first: its results are checked against them.
  store.for_each_pass_plan(row.id, [&](uint32_t pass, std::string&& data) {
    std::vector<uint32_t> counts;
    std::string err;
    if (!decode_sample_counts(data, size_t(job->plan().window.area()), counts, err) ||
        !job->restore_pass_plan(pass, std::move(counts), err))
      throw std::runtime_error(where + err);
  });
  // Each tile's checkpoint first, then the passes after it, in pass order: the film's sums as they were.
  store.for_each_checkpoint(row.id, [&](CheckpointRow&& c) {
    TileResult sums;
    std::string err;
    if (!decode_tile_result(c.data, sums, err)) throw std::runtime_error(where + "stored checkpoint is corrupt: " + err);
    if (c.tile >= job->num_tiles() || c.passes == 0 || c.passes > job->num_passes() ||
        !(sums.film.rect() == job->rect(job->unit(c.tile, 0))) || sums.film.has_aovs() != job->plan().settings.denoise ||
        sums.sample_end != job->sample_end(job->unit(c.tile, c.passes - 1)))
      throw std::runtime_error(where + "stored checkpoint of tile " + std::to_string(c.tile) + " does not fit the job");
    job->restore_checkpoint(c.tile, c.passes, std::move(sums.film));
  });
  store.for_each_result(row.id, [&](ResultRow&& r) {
    if (r.tile >= job->num_tiles() || r.pass >= job->num_passes()) return;
    const size_t unit = job->unit(r.tile, r.pass);
    if (!job->pass_decided(r.pass))
      throw std::runtime_error(where + "a result of pass " + std::to_string(r.pass) + " without its stored sample counts");
    if (r.data.empty() || r.pass < job->passes_in_film(r.tile))
      return job->mark_done(unit, r.worker);  // (held by its tile's checkpoint)
    TileResult result;
    std::string err;
    if (!decode_tile_result(r.data, result, err)) throw std::runtime_error(where + "stored result is corrupt: " + err);
    if (result.film.has_aovs() != job->plan().settings.denoise)
      throw std::runtime_error(where + "a stored result of pass " + std::to_string(r.pass) + " does not fit the job's AOVs");
    (void)job->add_result(unit, std::move(result.film), r.worker);
  });
  job->end_rebuild();
  return job;
}

std::string encode_checkpoint(uint64_t job, const JobState::Checkpoint& cp) {
  TileResult sums;
  sums.job_id = job;
  sums.tile = cp.tile;
  sums.pass = cp.passes - 1;
  sums.sample_end = cp.sample_end;
  sums.film = cp.sums;
  // Uncompressed: a checkpoint is written for most results, by the group commit's one writer, and
  // compressing (even zstd's fastest mode) took a third of that writer's time to save a fifth of
  // the bytes (sums are noise in their low bits). One per tile is within the storage bound as is.
  return encode_tile_result(sums, kUncompressed);
}

void Coordinator::Impl::save_decisions(JobState& job) {
  save_pass_plans(job);
  save_guides(job);
}

void Coordinator::Impl::save_pass_plans(JobState& job) {
  for (PassSequencer::DecidedPass& d : job.take_new_plans()) {
    log_event(spdlog::level::info, "job.pass_planned", {{"job", job.id()}, {"pass", d.pass}, {"seconds", d.seconds}});
    // Retried until stored, ahead of the leases appended after it: a lease of the pass is only
    // handed out once its counts are durable.
    auto counts = std::make_shared<const std::vector<uint32_t>>(std::move(d.counts));
    (void)commits.append([id = job.id(), pass = d.pass, counts](Store& st) {
      st.save_pass_plan(id, pass, encode_sample_counts(*counts));
    }, GroupCommit::Retry::UntilDurable);
  }
}

void Coordinator::Impl::restore_guide(JobState& job) {
  std::vector<std::string> hashes = store.guides(job.id());
  if (hashes.empty()) return;  // (not even its first artifact was stored: it is made again)
  std::string bytes, error;
  try {
    bytes = read_file(guide_path(hashes.back()));
  } catch (const std::exception& e) {
    error = e.what();
  }
  std::shared_ptr<const Artifact> latest;
  if (sha256_hex(bytes) == hashes.back()) latest = job.sequencer().builder()->decode(bytes, error);
  if (!latest)
    throw std::runtime_error("job " + std::to_string(job.id()) + ": its stored guide " + hashes.back() +
                             " is missing or corrupt " + error);
  job.restore_artifacts(std::move(hashes), std::move(latest));
  for (uint32_t pass : job.passes_feeding_next())
    store.for_each_training(job.id(), pass,
                            [&](uint32_t tile, std::string&& records) { job.restore_records(pass, tile, records); });
}

void Coordinator::Impl::save_guides(JobState& job) {
  while (auto made = job.take_artifact()) {
    background.push([this, id = job.id(), made = std::move(*made)] {
      const auto t0 = std::chrono::steady_clock::now();
      const std::string bytes = made.artifact->encode(), hash = sha256_hex(bytes);
      std::string error;
      try {
        write_file_durably(guide_path(hash), bytes);
      } catch (const std::exception& e) {
        error = e.what();
      }
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::lock_guard<std::mutex> lock(mu);
      auto it = jobs.find(id);
      if (it == jobs.end() || is_terminal(it->second->phase)) return;
      JobState& job = *it->second;
      if (!error.empty()) {
        (void)change_phase(job, JobPhase::Failed, "cannot store the job's guide: " + error);
        return;
      }
      // Retried until stored, ahead of the leases appended after it: a lease that renders with
      // the artifact is handed out only once its row is durable.
      (void)commits.append([id, iteration = made.iteration, hash](Store& st) { st.save_guide(id, iteration, hash); },
                           GroupCommit::Retry::UntilDurable);
      log_event(spdlog::level::info, "job.guide_stored",
                {{"job", id}, {"iteration", made.iteration}, {"memory_bytes", made.artifact->memory_bytes()},
                 {"bytes", bytes.size()}, {"barrier_seconds", made.seconds}, {"seconds", seconds}});
      job.artifact_stored(made.iteration, hash);
      work_cv.notify_all();
    });
  }
}

void Coordinator::Impl::checkpoint_tile(JobState& job, uint32_t tile, uint32_t min_new) {
  std::optional<JobState::Checkpoint> cp = job.take_checkpoint(tile, min_new);
  if (!cp) return;
  auto shared = std::make_shared<JobState::Checkpoint>(std::move(*cp));
  (void)commits.append(
      [id = job.id(), shared](Store& st) {
        st.save_checkpoint(id, shared->tile, shared->from, shared->passes, encode_checkpoint(id, *shared));
      },
      GroupCommit::Retry::No,
      [this, id = job.id(), tile = shared->tile, from = shared->from](bool durable) {
        auto it = jobs.find(id);
        if (!durable && it != jobs.end()) it->second->checkpoint_failed(tile, from);
      });
}

std::string Coordinator::Impl::image_path(uint64_t job) const {
  return (fs::path(opt.data_dir) / "images" / (std::to_string(job) + ".exr")).string();
}

void Coordinator::Impl::finish_job(JobState& job, bool notify) {
  // (A job cancelled while its images are being made: complete_job's task ends it.)
  if (!is_terminal(job.phase) || job.image_pending || job.denoise_pending) return;
  if (job.images_written) job.release_film();  // (a denoised job's images: complete_job)
  if (!job.has_film()) {  // its image is on disk already
    if (notify) send_webhook(job);
    return;
  }
  // Its sums stay (a retried job goes on from them) as one checkpoint per tile, not as results.
  for (uint32_t t = 0; t < job.num_tiles(); ++t) checkpoint_tile(job, t, 1);
  // The image is written off the lock; until then it is served from the film.
  job.image_pending = true;
  ImageAttributes attributes = image_attributes(job);
  background.push([this, id = job.id(), attributes = std::move(attributes), notify] {
    std::string error;
    try {
      std::optional<Image> image = film_image(id, /*consistent=*/true);
      if (!image) return;  // (the job was deleted meanwhile)
      write_image_durably(image_path(id), *image, attributes, opt.data_dir);
    } catch (const std::exception& e) {
      error = e.what();
    }
    std::lock_guard<std::mutex> lock(mu);
    auto it = jobs.find(id);
    if (it == jobs.end()) return;
    JobState& j = *it->second;
    j.image_pending = false;
    if (!error.empty())  // (a full disk: the film stays, and the retention pass tries again)
      return spdlog::warn("job {}: image not written yet: {}", id, error);
    if (!is_terminal(j.phase)) return;  // retried meanwhile: its film goes on
    j.release_film();
    log_event(spdlog::level::debug, "job.image_saved", {{"job", id}});
    if (notify) send_webhook(j);
  });
}

std::optional<Image> Coordinator::Impl::film_image(uint64_t id, bool consistent, std::vector<ImageLayer>* layers) {
  constexpr int kBandPixels = 1 << 18;  // about a millisecond of conversion under the lock
  const auto find = [&]() -> const JobState* {
    auto it = jobs.find(id);
    return it != jobs.end() && it->second->has_film() ? it->second.get() : nullptr;
  };
  int width = 0, height = 0;
  {
    std::lock_guard<std::mutex> lock(mu);
    const JobState* job = find();
    if (!job) return std::nullopt;
    width = job->plan().window.width();
    height = job->plan().window.height();
  }
  Image image(width, height, 3);  // (allocated off the lock)
  const std::vector<AovLayer> kinds = layers ? denoise_layers() : std::vector<AovLayer>{};
  if (layers) {
    layers->clear();
    for (AovLayer l : kinds)
      layers->push_back({aov_layer_name(l), aov_channel_names(l), Image(width, height, l == AovLayer::Depth ? 1 : 3)});
  }
  const int band = std::max(1, kBandPixels / std::max(1, width));
  uint64_t changes = 0;
  for (int y = 0; y < height;) {
    std::lock_guard<std::mutex> lock(mu);
    const JobState* job = find();
    if (!job) return std::nullopt;
    if (y == 0) {
      changes = job->film_changes();
    } else if (consistent && job->film_changes() != changes) {
      y = 0;  // (the film changed: convert it again from the top)
      continue;
    }
    job->image_rows(image, y, std::min(height, y + band));
    for (size_t i = 0; layers && i < layers->size(); ++i)
      job->aov_rows(kinds[i], (*layers)[i].image, y, std::min(height, y + band));
    y += band;
  }
  return image;
}

void Coordinator::Impl::send_webhook(const JobState& job) {
  if (job.plan().settings.webhook.empty()) return;
  // The body is made on the sender's thread: the lease log's counts are store reads.
  webhooks.send(job.id(), job.plan().settings.webhook, [this, status = status_of(job)]() mutable {
    add_lease_counts(status);
    return to_json(status).dump();
  });
}

void Coordinator::Impl::reap_loop() {
  std::unique_lock<std::mutex> lock(mu);
  auto next_retention = Clock::now();  // a pass at start-up, then every maintenance_interval (retention.h)
  while (!stopping) {
    work_cv.wait_for(lock, std::chrono::milliseconds(250));
    if (opt.maintenance_interval > 0 && Clock::now() >= next_retention && !stopping) {
      lock.unlock();
      try {
        (void)run_retention(wall_seconds());
      } catch (const std::exception& e) {
        spdlog::warn("retention pass failed: {}", e.what());
      }
      lock.lock();
      next_retention = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(opt.maintenance_interval));
    }
    reap_leases_and_workers();
  }
}

void Coordinator::Impl::reap_leases_and_workers() {
  std::vector<ReapWorker> live;
  for (auto& [id, w] : workers) live.push_back({id, is_live(w.state), w.last_seen});
  std::vector<ReapLease> held;
  held.reserve(leases.size());
  for (auto& [id, l] : leases) held.push_back({id, l.worker, l.expires});
  const Reaping reaping = decide_reaping(live, held, Clock::now(), dead_after());
  counters.expired += reaping.leases_of_lost;
  for (uint64_t id : reaping.lost_workers) set_worker_state(id, workers.at(id), WorkerState::Lost);
  for (uint64_t id : reaping.expired_leases) {
    auto it = leases.find(id);
    if (it == leases.end()) continue;
    const LeaseInfo& l = it->second;
    log_event(spdlog::level::warn, "lease.expired", {{"lease", l.id}, {"job", l.job}, {"unit", l.unit}, {"worker", l.worker}});
    ++counters.expired;
    end_lease(it);
  }
}

std::string Coordinator::metrics() {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mu);
  std::string out = metric_header("tessera_jobs", "gauge", "Jobs by state.");
  std::map<std::string, int> jobs;
  for (JobPhase p : {JobPhase::Queued, JobPhase::Running, JobPhase::Done, JobPhase::Failed, JobPhase::Cancelled})
    jobs[phase_name(p)] = 0;
  for (auto& [id, job] : s.jobs) ++jobs[phase_name(job->phase)];
  for (auto& [state, n] : jobs) out += "tessera_jobs{state=\"" + state + "\"} " + std::to_string(n) + "\n";

  out += metric_header("tessera_passes_total", "counter",
                       "Tile passes leased, done, expired, failed, duplicated, speculatively leased, mismatched.");
  const auto& c = s.counters;
  for (auto [event, n] : {std::pair{"leased", c.leased}, std::pair{"done", c.done}, std::pair{"expired", c.expired},
                          std::pair{"failed", c.failed}, std::pair{"duplicate", c.duplicates},
                          std::pair{"speculative", c.speculative}, std::pair{"mismatched", c.mismatched}})
    out += std::string("tessera_passes_total{event=\"") + event + "\"} " + std::to_string(n) + "\n";
  out += metric_header("tessera_leases_active", "gauge", "Leases in flight.");
  out += "tessera_leases_active " + std::to_string(s.leases.size()) + "\n";

  out += metric_header("tessera_workers", "gauge", "Workers by state.");
  std::map<std::string, int> workers;
  for (WorkerState state : kWorkerStates) workers[worker_state_name(state)] = 0;
  for (auto& [id, w] : s.workers) ++workers[worker_state_name(w.state)];
  for (auto& [state, n] : workers) out += "tessera_workers{state=\"" + state + "\"} " + std::to_string(n) + "\n";
  out += metric_header("tessera_worker_samples_per_second", "gauge", "Pixel samples per second of render time, per worker.");
  for (auto& [id, w] : s.workers)
    out += "tessera_worker_samples_per_second{worker=\"" + std::to_string(id) + "\",name=\"" + escape_label(w.row.name) +
           "\"} " + std::to_string(w.render_seconds > 0 ? double(w.samples_done) / w.render_seconds : 0.0) + "\n";

  out += metric_header("tessera_worker_scene_memory_bytes", "gauge", "Bytes of scenes loaded in a worker's cache, per worker.");
  for (auto& [id, w] : s.workers)
    out += "tessera_worker_scene_memory_bytes{worker=\"" + std::to_string(id) + "\",name=\"" + escape_label(w.row.name) +
           "\"} " + std::to_string(w.memory.scene_bytes) + "\n";

  out += s.lease_wait.render("tessera_lease_wait_seconds", "Time a lease request waited (long poll) before its answer.");
  out += s.upload_seconds.render("tessera_upload_seconds", "Time to verify and commit an uploaded tile result.");
  out += metric_header("tessera_bytes_total", "counter", "Payload bytes received (bundles, results) and sent (leases, bundles, images).");
  out += "tessera_bytes_total{direction=\"in\"} " + std::to_string(c.bytes_in) + "\n";
  out += "tessera_bytes_total{direction=\"out\"} " + std::to_string(c.bytes_out) + "\n";
  out += metric_header("tessera_webhooks_total", "counter", "Job webhooks delivered and given up on.");
  out += "tessera_webhooks_total{result=\"delivered\"} " + std::to_string(s.webhooks.delivered()) + "\n";
  out += "tessera_webhooks_total{result=\"failed\"} " + std::to_string(s.webhooks.failed()) + "\n";
  out += retention_metrics(s.retention);
  const GroupCommit::Stats commits = s.commits.stats();
  out += metric_header("tessera_store_commits_total", "counter",
                       "State database transactions committed by the group commit (one WAL fsync each), and failed.");
  out += "tessera_store_commits_total{result=\"committed\"} " + std::to_string(commits.commits) + "\n";
  out += "tessera_store_commits_total{result=\"failed\"} " + std::to_string(commits.failed_batches) + "\n";
  out += metric_header("tessera_store_records_total", "counter",
                       "Leases, results and phase changes committed by the group commit.");
  out += "tessera_store_records_total " + std::to_string(commits.records) + "\n";
  return out;
}

Health Coordinator::health() {
  std::lock_guard<std::mutex> lock(impl_->mu);
  uint64_t active = 0;
  for (auto& [id, job] : impl_->jobs) active += !is_terminal(job->phase);
  return {impl_->stopping ? "stopping" : "ok", impl_->fingerprint.version, active, impl_->leases.size(),
          std::chrono::duration<double>(Clock::now() - impl_->started).count()};
}

}  // namespace tessera::server

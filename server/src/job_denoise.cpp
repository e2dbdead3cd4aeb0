// A job's last step once its last unit is in (coordinator_impl.h, complete_job). A denoised job
// stays Running while, off the lock and one job at a time, its raw image is written with the AOV
// layers the denoiser reads and then the denoised image beside it; only then is it Done (durably),
// so a client that sees "done" finds both images, and its webhook fires after that. A denoiser that
// fails leaves the raw image and a denoise error on the Done job. A coordinator killed in between
// finds the job complete but not Done at start-up and makes its images again: the denoised image is
// a deterministic function of the raw one, so the same bits.
#include "coordinator_impl.h"
#include "disk_full.h"
#include "event_log.h"

#include "tessera/denoise/denoiser.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>

namespace tessera::server {

ImageAttributes Coordinator::Impl::image_attributes(const JobState& job) const {
  return {{"tessera_version", TESSERA_VERSION}, {"tessera_job", std::to_string(job.id())},
          {"tessera_spp", std::to_string(image_spp(job))}, {"tessera_seed", std::to_string(job.plan().settings.seed)}};
}

void Coordinator::Impl::complete_job(JobState& job) {
  if (!job.plan().settings.denoise) {
    (void)change_phase(job, JobPhase::Done);
    return;
  }
  if (job.denoise_pending || is_terminal(job.phase())) return;
  job.denoise_pending = true;
  // Its sums durable first, as finish_job does: the images take a while.
  for (uint32_t t = 0; t < job.num_tiles(); ++t) checkpoint_tile(job, t, 1);
  log_event(spdlog::level::info, "job.denoise_started", {{"job", job.id()}});
  denoising.push([this, id = job.id(), attributes = image_attributes(job), job_settings = job.plan().settings] {
    std::string error;
    bool raw_written = false;
    double seconds = 0;
    try {
      std::vector<ImageLayer> layers;
      const std::optional<Image> raw = film_image(id, /*consistent=*/true, &layers);
      if (!raw) return;  // (the job was deleted meanwhile)
      // The denoiser reads every layer; the EXRs carry those the job asked for (all unless `aovs` says).
      std::vector<ImageLayer> kept = layers;
      keep_job_exr_layers(job_settings, kept);
      write_image_durably(image_path(id), *raw, attributes, opt.data_dir, kept);
      raw_written = true;
      const auto start = std::chrono::steady_clock::now();
      DenoiseSettings settings;
      settings.threads = opt.denoise_threads;
      if (job_settings.denoise_mode == "preview") settings.mode = DenoiseMode::Preview;
      const Image denoised = denoise(make_denoise_input(*raw, layers), settings);
      seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      write_image_durably(denoised_path(id), denoised, attributes, opt.data_dir, kept);  // (both carry the AOVs)
    } catch (const std::exception& e) {
      error = std::string(raw_written ? "denoising failed: " : "the raw image was not written: ") + e.what();
    }
    MutexLock lock(mu);
    JobState* found = jobs.find(id);
    if (!found) return;
    JobState& j = *found;
    j.denoise_pending = false;
    j.images_written = raw_written;
    if (is_terminal(j.phase())) return finish_job(j, /*notify=*/true);  // (cancelled meanwhile)
    j.error = error;  // (a Done job's error is its denoise error)
    if (error.empty()) log_event(spdlog::level::info, "job.denoised", {{"job", id}, {"seconds", seconds}});
    else log_event(spdlog::level::err, "job.denoise_failed", {{"job", id}, {"reason", error}});
    (void)change_phase(j, JobPhase::Done);
  });
}

void Coordinator::Impl::refresh_denoised_preview(JobState& job) {
  if (job.preview_denoise_pending || job.denoise_pending || is_terminal(job.phase())) return;
  if (job.denoised_preview && job.denoised_preview_changes == job.film_changes()) return;
  job.preview_denoise_pending = true;
  denoising.push([this, id = job.id(), changes = job.film_changes()] {
    std::shared_ptr<const Image> preview;
    try {
      std::vector<ImageLayer> layers;
      if (const std::optional<Image> raw = film_image(id, /*consistent=*/false, &layers)) {
        DenoiseSettings settings;
        settings.mode = DenoiseMode::Preview;
        settings.threads = opt.denoise_threads;
        preview = std::make_shared<const Image>(denoise(make_denoise_input(*raw, layers), settings));
      }
    } catch (const std::exception& e) {
      spdlog::warn("job {}: preview not denoised: {}", id, e.what());
    }
    MutexLock lock(mu);
    JobState* found = jobs.find(id);
    if (!found) return;
    JobState& j = *found;
    j.preview_denoise_pending = false;
    if (!preview || is_terminal(j.phase())) return;
    j.denoised_preview = std::move(preview);
    j.denoised_preview_changes = changes;
  });
}

}  // namespace tessera::server

// A job's images: written once it ends (finish_job, off the lock), and served (GET
// /api/v1/jobs/N/image) from its film while it runs (a band of rows at a time under the lock), from
// disk once it has ended; a denoised job's denoised image, or while it runs a preview of its film
// denoised (job_denoise.cpp), encoded off the lock.
#include "coordinator_impl.h"
#include "disk_full.h"
#include "event_log.h"

#include "tessera/denoise/denoiser.h"

#include "tessera/image/image.h"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <atomic>
#include <filesystem>

namespace tessera::server {

namespace fs = std::filesystem;

namespace {

// Why a job has no denoised image at all (404); OK if it has one, or will.
Status denoised_image_status(const JobState& job) {
  const std::string name = "job " + std::to_string(job.id());
  if (!job.plan().settings.denoise)
    return make_error(Code::NotFound, "not_denoised", name + " was not submitted with denoise");
  if (job.phase() == JobPhase::Done && !job.error.empty())
    return make_error(Code::NotFound, "denoise_failed", name + ": " + job.error);
  if (is_terminal(job.phase()) && job.phase() != JobPhase::Done)
    return make_error(Code::NotFound, "not_denoised", name + " is " + phase_name(job.phase()) + ": no denoised image");
  return Status::success();
}

// The image (and for an EXR its layers) encoded as `format` through a file in DATA_DIR/tmp, checked
// before it is sent, since a full disk can truncate it silently. Throws.
ImageBytes encode_image(const std::string& data_dir, const std::string& format, const Image& image,
                        const std::vector<ImageLayer>& layers, const JobPlan& plan, const ImageAttributes& attributes) {
  static std::atomic<uint64_t> counter{0};
  const std::string tmp = (fs::path(data_dir) / "tmp" /
                           ("image-" + std::to_string(::getpid()) + "-" + std::to_string(++counter) + "." + format))
                              .string();
  try {
    if (format == "png") {
      LdrSettings ldr;
      if (plan.ldr) {
        ldr.gamma = plan.gamma;
        ldr.exposure = plan.exposure;
      }
      write_png(tmp, image, ldr);
    } else if (layers.empty()) {
      write_image(tmp, image, attributes);
    } else {
      write_exr_layers(tmp, image, layers, attributes);
    }
    verify_image_file(tmp, format, image, data_dir);
    ImageBytes out{read_file(tmp), format == "png" ? "image/png" : format == "exr" ? "image/x-exr" : "image/x-pfm"};
    fs::remove(tmp);
    return out;
  } catch (const std::exception&) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

}  // namespace

void Coordinator::Impl::finish_job(JobState& job, bool notify) {
  // (A job cancelled while its images are being made: complete_job's task ends it.)
  if (!is_terminal(job.phase()) || job.image_pending || job.denoise_pending) return;
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
  background.push([this, id = job.id(), attributes = std::move(attributes), notify, settings = job.plan().settings] {
    std::string error;
    try {
      std::vector<ImageLayer> layers;  // (the AOV layers the job asked for)
      std::optional<Image> image = film_image(id, /*consistent=*/true, settings.sums_aovs() ? &layers : nullptr);
      if (!image) return;  // (the job was deleted meanwhile)
      keep_job_exr_layers(settings, layers);
      write_image_durably(image_path(id), *image, attributes, opt.data_dir, layers);
    } catch (const std::exception& e) {
      error = e.what();
    }
    MutexLock lock(mu);
    JobState* found = jobs.find(id);
    if (!found) return;
    JobState& j = *found;
    j.image_pending = false;
    if (!error.empty())  // (a full disk: the film stays, and the retention pass tries again)
      return spdlog::warn("job {}: image not written yet: {}", id, error);
    if (!is_terminal(j.phase())) return;  // retried meanwhile: its film goes on
    j.release_film();
    log_event(spdlog::level::debug, "job.image_saved", {{"job", id}});
    if (notify) send_webhook(j);
  });
}

std::optional<Image> Coordinator::Impl::film_image(uint64_t id, bool consistent, std::vector<ImageLayer>* layers) {
  constexpr int kBandPixels = 1 << 18;  // about a millisecond of conversion under the lock
  const auto find = [&]() TESSERA_REQUIRES(mu) -> const JobState* {
    const JobState* job = jobs.find(id);
    return job && job->has_film() ? job : nullptr;
  };
  int width = 0, height = 0;
  {
    MutexLock lock(mu);
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
    MutexLock lock(mu);
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

Result<ImageBytes> Coordinator::job_image(uint64_t id, const std::string& format, bool denoised) {
  Impl& s = *impl_;
  if (format != "exr" && format != "png" && format != "pfm")
    return make_error(Code::BadRequest, "bad_format", "format '" + format + "' is not exr, png or pfm");
  Image image;
  JobPlan plan;
  uint32_t spp = 0;
  bool from_film = false;
  std::shared_ptr<const Image> preview;  // a running job's denoised preview
  {
    MutexLock lock(s.mu);
    JobState* found = s.jobs.find(id);
    if (!found) return s.missing_job(id);
    JobState& job = *found;
    if (denoised) {
      if (Status st = denoised_image_status(job); !st.ok()) return st;
      if (job.phase() != JobPhase::Done) {  // the latest preview denoised, a newer one on its way
        s.refresh_denoised_preview(job);
        if (!job.denoised_preview)
          return make_error(Code::NotYet, "not_denoised_yet",
                            "job " + std::to_string(id) + "'s denoised image is being made; ask again");
        preview = job.denoised_preview;
      }
    }
    plan = job.plan();
    spp = image_spp(job);
    from_film = !denoised && job.has_film();
  }
  if (preview) image = *preview;
  std::vector<ImageLayer> layers;  // an EXR from the film carries the AOV layers the job asked for
  if (from_film) {  // (or released meanwhile, once its image is on disk)
    const bool with_layers = format == "exr" && plan.settings.sums_aovs();
    if (std::optional<Image> converted = s.film_image(id, /*consistent=*/false, with_layers ? &layers : nullptr))
      image = std::move(*converted);
    keep_job_exr_layers(plan.settings, layers);
  }
  if (image.width() == 0) {  // an ended job: its images are on disk
    const std::string path = denoised ? s.denoised_path(id) : s.image_path(id);
    try {
      // As stored: the raw EXR of a job with AOVs or denoised carries the AOV layers.
      if (format == "exr") {
        ImageBytes out{read_file(path), "image/x-exr"};
        s.metrics.counters.bytes_out += out.bytes.size();
        return out;
      }
      image = read_exr(path);
    } catch (const std::exception& e) {
      return internal_error(e);
    }
  }
  try {
    ImageBytes out = encode_image(s.opt.data_dir, format, image, layers, plan,
                                  {{"tessera_version", TESSERA_VERSION},
                                   {"tessera_job", std::to_string(id)},
                                   {"tessera_spp", std::to_string(spp)},
                                   {"tessera_seed", std::to_string(plan.settings.seed)}});
    s.metrics.counters.bytes_out += out.bytes.size();
    return out;
  } catch (const std::exception& e) {
    return internal_error(e);
  }
}

}  // namespace tessera::server

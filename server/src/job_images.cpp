// Serving a job's image (GET /api/v1/jobs/N/image): from its film while it runs (a band of rows at a
// time under the lock), from disk once it has ended; a denoised job's denoised image, or while it
// runs a preview of its film denoised (job_denoise.cpp), encoded off the lock.
#include "coordinator_impl.h"
#include "disk_full.h"

#include "tessera/image/image.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>

namespace tessera::server {

namespace fs = std::filesystem;

namespace {

// Under `mu`: why a job has no denoised image at all (404); OK if it has one, or will.
Status denoised_image_status(const JobState& job) {
  const std::string name = "job " + std::to_string(job.id());
  if (!job.plan().settings.denoise)
    return make_error(Code::NotFound, "not_denoised", name + " was not submitted with denoise");
  if (job.phase == JobPhase::Done && !job.error.empty())
    return make_error(Code::NotFound, "denoise_failed", name + ": " + job.error);
  if (is_terminal(job.phase) && job.phase != JobPhase::Done)
    return make_error(Code::NotFound, "not_denoised", name + " is " + phase_name(job.phase) + ": no denoised image");
  return Status::success();
}

}  // namespace

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
    std::lock_guard<std::mutex> lock(s.mu);
    auto it = s.jobs.find(id);
    if (it == s.jobs.end()) return s.missing_job(id);
    JobState& job = *it->second;
    if (denoised) {
      if (Status st = denoised_image_status(job); !st.ok()) return st;
      if (job.phase != JobPhase::Done) {  // the latest preview denoised, a newer one on its way
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
  if (from_film) {  // (or released meanwhile, once its image is on disk)
    if (std::optional<Image> converted = s.film_image(id, /*consistent=*/false)) image = std::move(*converted);
  }
  if (image.width() == 0) {  // an ended job: its images are on disk
    const std::string path = denoised ? s.denoised_path(id) : s.image_path(id);
    try {
      // As stored: a denoised job's raw EXR carries the AOV layers.
      if (format == "exr") {
        ImageBytes out{read_file(path), "image/x-exr"};
        std::lock_guard<std::mutex> lock(s.mu);
        s.counters.bytes_out += out.bytes.size();
        return out;
      }
      image = read_exr(path);
    } catch (const std::exception& e) {
      return internal_error(e);
    }
  }
  static std::atomic<uint64_t> counter{0};
  const std::string tmp = (fs::path(s.opt.data_dir) / "tmp" /
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
    } else {
      write_image(tmp, image,
                  {{"tessera_version", TESSERA_VERSION},
                   {"tessera_job", std::to_string(id)},
                   {"tessera_spp", std::to_string(spp)},
                   {"tessera_seed", std::to_string(plan.settings.seed)}});
    }
    verify_image_file(tmp, format, image, s.opt.data_dir);  // (a full disk can truncate it silently)
    ImageBytes out{read_file(tmp), format == "png" ? "image/png" : format == "exr" ? "image/x-exr" : "image/x-pfm"};
    fs::remove(tmp);
    std::lock_guard<std::mutex> lock(s.mu);
    s.counters.bytes_out += out.bytes.size();
    return out;
  } catch (const std::exception& e) {
    std::error_code ec;
    fs::remove(tmp, ec);
    return internal_error(e);
  }
}

}  // namespace tessera::server

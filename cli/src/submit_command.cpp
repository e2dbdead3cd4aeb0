// `tessera submit`: the farm's client side of a render. The scene is loaded here first, so only
// the files it references are bundled and a broken scene fails before anything is sent.
#include "farm_connection.h"

#include "tessera/cli/command_line.h"
#include "tessera/cli/progress.h"
#include "tessera/farm/bundle.h"
#include "tessera/farm/job_scene.h"
#include "tessera/render/aov.h"
#include "tessera/scene/error.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <thread>

namespace tessera::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string extension_of(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return ext.empty() ? ext : ext.substr(1);
}

// How a submission reaches its coordinator and reports: errors always, the rest unless quiet.
struct Session {
  const client::FarmApi& api;
  const SubmitOptions& o;
  std::ostream& info() const { return o.quiet ? quiet_stream() : std::cerr; }
  std::string error(const client::HttpReply& r) const { return farm_error(r, o.connection); }

 private:
  static std::ostream& quiet_stream() {
    static std::ostream none(nullptr);  // (a stream with no buffer writes nothing)
    return none;
  }
};

bool download(const Session& s, uint64_t id, const std::string& out, bool denoised) {
  client::HttpReply r = s.api.job_image(id, extension_of(out), denoised);
  if (!r.ok()) {
    std::cerr << "tessera submit: cannot download the " << (denoised ? "denoised " : "") << "image: " << s.error(r)
              << "\n";
    return false;
  }
  if (fs::path(out).has_parent_path()) fs::create_directories(fs::path(out).parent_path());
  std::ofstream(out, std::ios::binary).write(r.body.data(), std::streamsize(r.body.size()));
  s.info() << "wrote " << out << "\n";
  return true;
}

// Each output; for a denoised job the denoised image, and FILE.noisy.ext the raw one (as
// `tessera render --denoise` writes them). A failed denoise leaves only the raw one, and fails.
bool download_outputs(const Session& s, uint64_t id, const std::vector<std::string>& outputs, const json& status) {
  const json state = status.value("denoise_state", json());
  const bool denoised = !state.is_null();
  if (denoised && state != "done")
    std::cerr << "tessera submit: job " << id << " was not denoised: " << status.value("denoise_error", json()).dump()
              << "\n";
  bool ok = true;
  for (const std::string& out : outputs) {
    if (!denoised) {
      ok = download(s, id, out, false) && ok;
      continue;
    }
    ok = download(s, id, noisy_path(out), false) && ok;
    ok = state == "done" && download(s, id, out, true) && ok;
  }
  return ok;
}

// Polls until the job ends; returns its final status (null when the server stays unreachable).
json wait_for(const Session& s, uint64_t id) {
  Progress progress("job " + std::to_string(id), !s.o.quiet);
  int failures = 0;
  for (;;) {
    client::HttpReply r = s.api.job(id);
    json j = r.json();
    if (r.ok() && j.is_object()) {
      failures = 0;
      progress.update(j.value("progress", 0.0), 1.0);
      std::string state = j.value("state", "");
      if (state == "done" || state == "failed" || state == "cancelled") {
        progress.finish();
        return j;
      }
    } else if (++failures > 300) {  // about ten minutes without an answer: the coordinator is gone
      progress.finish();
      std::cerr << "tessera submit: lost the coordinator: " << s.error(r) << "\n";
      return nullptr;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(r.ok() ? 250 : 2000));
  }
}


// "frame_####.png" with frame 7 -> "frame_0007.png" (the run of '#' sets the width).
std::string frame_path(const std::string& pattern, int frame) {
  const size_t a = pattern.find('#');
  if (a == std::string::npos) return pattern;
  size_t b = a;
  while (b < pattern.size() && pattern[b] == '#') ++b;
  std::string n = std::to_string(frame);
  if (n.size() < b - a) n.insert(0, b - a - n.size(), '0');
  return pattern.substr(0, a) + n + pattern.substr(b);
}

// Waits for one job and downloads its outputs; the exit code.
int finish_job(const Session& s, uint64_t id, const std::vector<std::string>& outputs) {
  json final_status = wait_for(s, id);
  if (final_status.is_null()) return 1;
  if (final_status.value("state", "") != "done") {
    std::cerr << "job " << id << " " << final_status.value("state", "") << ": " << final_status.value("error", "")
              << "\n";
    return 1;
  }
  s.info() << "job " << id << " done in " << final_status.value("elapsed_seconds", 0.0) << " s";
  if (final_status.value("stopped_at_target", false))
    s.info() << ", stopped at " << final_status.value("spp_done", 0) << " spp (estimated relMSE "
             << final_status.value("noise_estimate", 0.0) << ")";
  s.info() << "\n";
  return download_outputs(s, id, outputs, final_status) ? 0 : 1;
}

bool check_outputs(const SubmitOptions& o) {
  for (const auto& out : o.outputs) {
    const std::string ext = extension_of(out);
    if (ext != "exr" && ext != "png" && ext != "pfm") {
      std::cerr << "tessera submit: output '" << out << "': unknown format (use .exr, .pfm or .png)\n";
      return false;
    }
    if (!o.frames.empty() && out.find('#') == std::string::npos) {
      std::cerr << "tessera submit: with --frames, output '" << out << "' needs '#'s for the frame number\n";
      return false;
    }
  }
  std::string error;
  if (!o.aovs.empty() && !parse_aov_layers(o.aovs, &error)) {
    std::cerr << "tessera submit: --aovs: " << error << "\n";
    return false;
  }
  if (!o.aovs.empty() && !o.outputs.empty() &&
      std::none_of(o.outputs.begin(), o.outputs.end(), [](const std::string& out) { return extension_of(out) == "exr"; })) {
    std::cerr << "tessera submit: --aovs: AOV layers are written only into .exr outputs; give one with -o\n";
    return false;
  }
  return true;
}

JobSettings job_settings(const SubmitOptions& o) {
  JobSettings settings;
  settings.name = o.name.empty() ? default_job_name(fs::absolute(o.scene).lexically_normal().string()) : o.name;
  settings.spp = o.spp;
  settings.width = o.width;
  settings.height = o.height;
  settings.seed = o.seed;
  settings.tile_size = o.tile_size;
  settings.priority = o.priority;
  settings.defines = o.defines;
  settings.integrator = o.integrator;
  settings.light_selection = o.light_selection;
  settings.target_error = o.target_error;
  settings.adaptive = o.adaptive == "on";
  settings.denoise = o.denoise;
  settings.denoise_mode = o.denoise_mode;
  settings.aovs = o.aovs;
  settings.allow_unsupported = o.allow_unsupported;
  if (!o.guiding.empty()) settings.guiding = o.guiding == "on";
  settings.webhook = o.webhook;
  return settings;
}

// Loads the scene as the coordinator will and bundles the files it references; the bundle's bytes
// (settings.scene_file set to its XML), or none with the error printed.
std::optional<std::string> bundle_scene(const std::string& scene_file, JobSettings& settings, bool quiet) {
  try {
    const fs::path scene = fs::absolute(scene_file);
    LoadedJobScene loaded = load_job_scene(scene.parent_path().string(), scene.filename().string(), settings, /*confine=*/false);
    BundlePlan plan = plan_bundle(scene.string(), scene_files(loaded.desc, loaded.loaded));
    settings.scene_file = plan.files.front();
    std::string bundle = pack_bundle(plan.root_dir, plan.files);
    if (!quiet)
      std::cerr << "bundled " << plan.files.size() << " files (" << bundle.size() / 1024 << " KiB) from " << plan.root_dir
              << "\n";
    return bundle;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return std::nullopt;
  }
}

// A frame range's jobs: their ids printed, then (waiting) each finished in turn; the exit code.
int finish_frames(const Session& s, const json& answer, const std::vector<std::string>& outputs) {
  if (!s.o.quiet)
    for (const json& job : answer["jobs"]) std::cout << job.value("id", uint64_t(0)) << "\n";
  s.info() << answer["jobs"].size() << " frame jobs submitted to " << s.api.url() << "\n";
  if (!s.o.wait && outputs.empty()) return 0;
  int code = 0;
  for (const json& job : answer["jobs"]) {
    const int frame = std::stoi(job["settings"]["defines"].value("frame", "0"));
    std::vector<std::string> outs;
    for (const auto& out : outputs) outs.push_back(frame_path(out, frame));
    code = std::max(code, finish_job(s, job.value("id", uint64_t(0)), outs));
  }
  return code;
}

// --wait without -o: JOBNAME.exr here (JOBNAME_####.exr for frames), never over an existing file
// without --force: jobs of different scenes.xml used to land on the same scene.exr unnoticed.
std::optional<std::vector<std::string>> outputs_of(const SubmitOptions& o, const JobSettings& settings) {
  if (!o.wait || !o.outputs.empty()) return o.outputs;
  std::string name = settings.name;
  std::replace(name.begin(), name.end(), '/', '-');
  const std::string out = name + (o.frames.empty() ? ".exr" : "_####.exr");
  int first = 0, last = -1;  // the frames' files (none checked for a range it cannot read: the server says)
  if (o.frames.empty()) last = 0;
  else if (std::sscanf(o.frames.c_str(), "%d%*[-.]%d", &first, &last) == 1) last = first;
  for (int frame = first; frame <= last && frame - first < 100000; ++frame)
    if (fs::exists(frame_path(out, frame)) && !o.force) {
      std::cerr << "tessera submit: " << frame_path(out, frame) << " exists; --force overwrites it, -o names another file\n";
      return std::nullopt;
    }
  return std::vector<std::string>{out};
}

}  // namespace

int run_submit(const SubmitOptions& o) {
  if (!check_outputs(o)) return 2;
  JobSettings settings = job_settings(o);
  const std::optional<std::vector<std::string>> outputs = outputs_of(o, settings);
  if (!outputs) return 2;
  client::FarmApi api(client::FarmClient(""));
  if (!connect(o.connection, "tessera submit", api)) return 2;
  const Session session{api, o};
  const std::optional<std::string> bundle = bundle_scene(o.scene, settings, o.quiet);
  if (!bundle) return 1;
  json body = to_json(settings);
  body.erase("scene");
  if (!o.frames.empty()) body["frames"] = o.frames;
  client::HttpReply r = api.submit_job(body, *bundle);
  const json j = r.json();
  if (!r.ok() || !j.is_object()) {
    std::cerr << "tessera submit: " << (r.status == 0 ? "" : "the coordinator refused the job: ") << session.error(r)
              << "\n";
    return 1;
  }
  if (!o.frames.empty()) return finish_frames(session, j, *outputs);
  const uint64_t id = j.value("id", uint64_t(0));
  if (!o.quiet) std::cout << id << "\n";
  session.info() << "job " << id << " (" << j.value("name", "") << ") submitted to " << api.url() << ": "
                 << j.value("width", 0) << "x" << j.value("height", 0) << ", " << j.value("spp", 0) << " spp, "
                 << j.value("tiles", 0) << " tiles x " << j.value("passes", 0) << " passes\n";
  if (!o.wait && outputs->empty()) return 0;
  return finish_job(session, id, *outputs);
}

Command add_submit_command(CLI::App& app) {
  auto o = std::make_shared<SubmitOptions>();
  auto defines = std::make_shared<std::vector<std::string>>();
  CLI::App* s = app.add_subcommand("submit", "Send a scene to a render farm coordinator (docs/api.md)");
  s->add_option("scene", o->scene, "Scene file; only the files it references are uploaded")->required()
      ->check(CLI::ExistingFile);
  add_connection_options(*s, o->connection);
  s->add_option("-o,--output", o->outputs, "Wait, then download the image(s): .exr, .pfm or .png");
  s->add_flag("--wait", o->wait, "Wait for the job to finish, with a progress bar");
  s->add_option("--spp", o->spp, "Samples per pixel (default: the scene's)")->check(CLI::PositiveNumber);
  s->add_option("--width", o->width, "Film width (default: the scene's)")->check(CLI::PositiveNumber);
  s->add_option("--height", o->height, "Film height (default: the scene's)")->check(CLI::PositiveNumber);
  s->add_option("--seed", o->seed, "Sampling seed");
  s->add_option("--tile-size", o->tile_size, "Tile edge in pixels (does not change the image)")->check(CLI::Range(4, 1024));
  s->add_option("--priority", o->priority, "Higher runs first");
  s->add_option("--name", o->name,
                "Job name (default: the scene's folder, and its file's stem unless that is 'scene': cornell-box)");
  s->add_option("-D", *defines, "Override a scene <default>: -D name=value");
  add_integrator_option(*s, o->integrator);
  s->add_option("--light-selection", o->light_selection, "power or bvh")->check(CLI::IsMember({"power", "bvh"}));
  s->add_option("--target-error", o->target_error, "Stop at this estimated relMSE (--spp is then the budget)")
      ->check(CLI::Range(0.0, 1.0));
  s->add_option("--guiding", o->guiding,
                "Path guiding, as for render: the same image (default: on for a guided_path integrator, else off)")
      ->check(CLI::IsMember({"on", "off"}));
  s->add_flag("--denoise", o->denoise,
              "Denoise the finished image on the coordinator (job field denoise): each -o FILE.ext gets the "
              "denoised image and FILE.noisy.ext the raw one (its EXR with the AOV layers), as render --denoise");
  s->add_option("--denoise-mode", o->denoise_mode, "full, or preview (faster, less thorough), as for render")
      ->check(CLI::IsMember({"full", "preview"}))->capture_default_str();
  s->add_option("--aovs", o->aovs,
                "Layers each .exr output carries beside the image, as for render: albedo, normal, depth, variance, "
                "half_a, half_b, comma-separated, or all (the image stays the same bits)");
  s->add_option("--adaptive", o->adaptive, "Adaptive sampling, as for render: the same image (default off)")
      ->check(CLI::IsMember({"on", "off"}))->capture_default_str();
  s->add_flag("--allow-unsupported", o->allow_unsupported,
              "Substitute documented fallbacks for unsupported plugins/parameters (here, on the coordinator and workers)");
  s->add_option("--webhook", o->webhook, "URL the coordinator POSTs the job's status to when it ends");
  s->add_option("--frames", o->frames, "Render frames A-B, one job each with -D frame=N; '#'s in -o become N");
  s->add_flag("--force", o->force, "With --wait and no -o: overwrite an existing JOBNAME.exr");
  s->add_flag("-q,--quiet", o->quiet, "Print nothing but errors (not the job id either)");
  return {s, [o, defines] { return parse_defines(*defines, o->defines, "tessera submit") ? run_submit(*o) : 2; }};
}

}  // namespace tessera::cli

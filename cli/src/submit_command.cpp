// `tessera submit`, `tessera jobs`, `tessera cancel`: the farm's client side. submit loads the
// scene locally first, so only the files it references are bundled and a broken scene fails here.
#include "tessera/cli/commands.h"
#include "tessera/cli/progress.h"
#include "tessera/farm/bundle.h"
#include "tessera/farm/job_scene.h"
#include "tessera/scene/error.h"
#include "tessera/client/farm_api.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

namespace tessera::cli {

namespace fs = std::filesystem;
using nlohmann::json;

std::string default_server_url() {
  const char* env = std::getenv("TESSERA_SERVER");
  return env && *env ? env : "http://127.0.0.1:8420";
}

namespace {

// The coordinator's client, with the client token from --token-file or $TESSERA_CLIENT_TOKEN;
// false (the reason printed, prefixed by `who`) if the token file cannot be read.
bool make_client(const std::string& server, const std::string& token_file, const std::string& ca_file,
                 const char* who, client::FarmApi& out) {
  try {
    out = client::FarmApi(client::FarmClient(server.empty() ? default_server_url() : server,
                                             resolve_token("", token_file, "TESSERA_CLIENT_TOKEN"), ca_file));
    return true;
  } catch (const std::exception& e) {
    std::cerr << who << ": " << e.what() << "\n";
    return false;
  }
}

std::string extension_of(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return ext.empty() ? ext : ext.substr(1);
}

bool download(const client::FarmApi& api, uint64_t id, const std::string& out, bool denoised) {
  client::HttpReply r = api.job_image(id, extension_of(out), denoised);
  if (!r.ok()) {
    std::cerr << "tessera submit: cannot download the " << (denoised ? "denoised " : "") << "image: " << r.describe()
              << "\n";
    return false;
  }
  if (fs::path(out).has_parent_path()) fs::create_directories(fs::path(out).parent_path());
  std::ofstream(out, std::ios::binary).write(r.body.data(), std::streamsize(r.body.size()));
  std::cerr << "wrote " << out << "\n";
  return true;
}

// Each output; for a denoised job the denoised image, and FILE.noisy.ext the raw one (as
// `tessera render --denoise` writes them). A failed denoise leaves only the raw one, and fails.
bool download_outputs(const client::FarmApi& api, uint64_t id, const std::vector<std::string>& outputs,
                      const json& status) {
  const json state = status.value("denoise_state", json());
  const bool denoised = !state.is_null();
  if (denoised && state != "done")
    std::cerr << "tessera submit: job " << id << " was not denoised: " << status.value("denoise_error", json()).dump()
              << "\n";
  bool ok = true;
  for (const std::string& out : outputs) {
    if (!denoised) {
      ok = download(api, id, out, false) && ok;
      continue;
    }
    ok = download(api, id, noisy_path(out), false) && ok;
    ok = state == "done" && download(api, id, out, true) && ok;
  }
  return ok;
}

// Polls until the job ends; returns its final status (null when the server stays unreachable).
json wait_for(const client::FarmApi& api, uint64_t id, bool quiet) {
  Progress progress("job " + std::to_string(id), !quiet);
  int failures = 0;
  for (;;) {
    client::HttpReply r = api.job(id);
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
      std::cerr << "tessera submit: lost the coordinator: " << r.describe() << "\n";
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
int finish_job(const client::FarmApi& api, uint64_t id, const std::vector<std::string>& outputs, bool quiet) {
  json final_status = wait_for(api, id, quiet);
  if (final_status.is_null()) return 1;
  if (final_status.value("state", "") != "done") {
    std::cerr << "job " << id << " " << final_status.value("state", "") << ": " << final_status.value("error", "")
              << "\n";
    return 1;
  }
  std::cerr << "job " << id << " done in " << final_status.value("elapsed_seconds", 0.0) << " s";
  if (final_status.value("stopped_at_target", false))
    std::cerr << ", stopped at " << final_status.value("spp_done", 0) << " spp (estimated relMSE "
              << final_status.value("noise_estimate", 0.0) << ")";
  std::cerr << "\n";
  return download_outputs(api, id, outputs, final_status) ? 0 : 1;
}

}  // namespace

int run_submit(const SubmitOptions& o) {
  for (const auto& out : o.outputs) {
    std::string ext = extension_of(out);
    if (ext != "exr" && ext != "png" && ext != "pfm") {
      std::cerr << "tessera submit: output '" << out << "': unknown format (use .exr, .pfm or .png)\n";
      return 2;
    }
    if (!o.frames.empty() && out.find('#') == std::string::npos) {
      std::cerr << "tessera submit: with --frames, output '" << out << "' needs '#'s for the frame number\n";
      return 2;
    }
  }
  client::FarmApi api(client::FarmClient(""));
  if (!make_client(o.server, o.token_file, o.ca_file, "tessera submit", api)) return 2;
  std::string why;
  if (!api.valid(&why)) {
    std::cerr << "tessera submit: " << why << "\n";
    return 2;
  }
  JobSettings settings;
  settings.name = o.name.empty() ? fs::path(o.scene).stem().string() : o.name;
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
  if (!o.guiding.empty()) settings.guiding = o.guiding == "on";
  settings.webhook = o.webhook;

  std::string bundle;
  try {
    const fs::path scene = fs::absolute(o.scene);
    LoadedJobScene loaded = load_job_scene(scene.parent_path().string(), scene.filename().string(), settings, /*confine=*/false);
    BundlePlan plan = plan_bundle(scene.string(), scene_files(loaded.desc, loaded.loaded));
    settings.scene_file = plan.files.front();
    bundle = pack_bundle(plan.root_dir, plan.files);
    std::cerr << "bundled " << plan.files.size() << " files (" << bundle.size() / 1024 << " KiB) from " << plan.root_dir
              << "\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  // --wait without -o: the image lands where `tessera render` would put it, SCENE_STEM.exr here.
  std::vector<std::string> outputs = o.outputs;
  if (o.wait && outputs.empty())
    outputs.push_back(fs::path(o.scene).stem().string() + (o.frames.empty() ? ".exr" : "_####.exr"));
  json body = to_json(settings);
  body.erase("scene");
  if (!o.frames.empty()) body["frames"] = o.frames;
  client::HttpReply r = api.submit_job(body, bundle);
  json j = r.json();
  if (!r.ok() || !j.is_object()) {
    std::cerr << "tessera submit: the coordinator refused the job: " << r.describe() << "\n";
    return 1;
  }
  if (!o.frames.empty()) {
    for (const json& job : j["jobs"]) std::cout << job.value("id", uint64_t(0)) << "\n";
    std::cerr << j["jobs"].size() << " frame jobs submitted to " << api.url() << "\n";
    if (!o.wait && outputs.empty()) return 0;
    int code = 0;
    for (const json& job : j["jobs"]) {
      const int frame = std::stoi(job["settings"]["defines"].value("frame", "0"));
      std::vector<std::string> outs;
      for (const auto& out : outputs) outs.push_back(frame_path(out, frame));
      code = std::max(code, finish_job(api, job.value("id", uint64_t(0)), outs, o.quiet));
    }
    return code;
  }
  const uint64_t id = j.value("id", uint64_t(0));
  std::cout << id << "\n";
  std::cerr << "job " << id << " submitted to " << api.url() << ": " << j.value("width", 0) << "x"
            << j.value("height", 0) << ", " << j.value("spp", 0) << " spp, " << j.value("tiles", 0) << " tiles x "
            << j.value("passes", 0) << " passes\n";
  if (!o.wait && outputs.empty()) return 0;
  return finish_job(api, id, outputs, o.quiet);
}

int run_jobs(const JobsOptions& o) {
  client::FarmApi api(client::FarmClient(""));
  if (!make_client(o.server, o.token_file, o.ca_file, "tessera jobs", api)) return 2;
  client::HttpReply r = api.jobs();
  json j = r.json();
  if (!r.ok() || !j.is_object()) {
    std::cerr << "tessera jobs: " << r.describe() << "\n";
    return 1;
  }
  std::printf("%6s  %-10s %6s %9s %11s %6s  %s\n", "ID", "STATE", "PRIO", "PROGRESS", "SIZE", "SPP", "NAME");
  for (const json& job : j["jobs"])
    std::printf("%6llu  %-10s %6d %8.1f%% %5dx%-5d %6d  %s\n", (unsigned long long)job.value("id", uint64_t(0)),
                job.value("state", "").c_str(), job.value("priority", 0), 100.0 * job.value("progress", 0.0),
                job.value("width", 0), job.value("height", 0),
                job.value("stopped_at_target", false) ? job.value("spp_done", 0) : job.value("spp", 0), job.value("name", "").c_str());
  return 0;
}

int run_cancel(const JobsOptions& o) {
  client::FarmApi api(client::FarmClient(""));
  if (!make_client(o.server, o.token_file, o.ca_file, "tessera cancel", api)) return 2;
  client::HttpReply r = api.cancel_job(o.cancel_id);
  if (!r.ok()) {
    std::cerr << "tessera cancel: " << r.describe() << "\n";
    return 1;
  }
  std::cerr << "job " << o.cancel_id << " cancelled\n";
  return 0;
}

}  // namespace tessera::cli

// The `tessera` command's subcommands as library functions (main.cpp only dispatches), so tests
// can run them in-process.
#pragma once

#include "tessera/tools/bench_rays.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace tessera::cli {

struct RenderOptions {
  std::string scene;
  std::vector<std::string> outputs;        // by extension: .exr .pfm .png
  int spp = 0, width = 0, height = 0;      // 0: as the scene says
  int threads = 0;                         // 0: all cores
  int tile_size = 32;
  uint32_t seed = 0;
  std::map<std::string, std::string> defines;
  std::string integrator;                  // empty: as the scene says
  std::string light_selection;             // "power" or "bvh"; empty: the default (bvh)
  double target_error = 0;                 // > 0: stop at this estimated relMSE (spp is the budget)
  std::string guiding;                     // path guiding: "on", "off"; empty: as the scene says
  std::string adaptive = "off";            // adaptive sampling: "on" or "off"
  std::string aovs;                        // AOV layers for EXR outputs (render/aov.h); empty: none
  bool denoise = false;                    // outputs get the denoised image, FILE.noisy.ext the raw one
  std::string denoise_mode = "full";       // "full" or "preview"
  bool allow_unsupported = false;
  std::string strategy_images;             // bdpt: a directory for one image per strategy (bdpt.h)
  bool quiet = false;
};

/// `tessera denoise`.
struct DenoiseOptions {
  std::string input;                 // an EXR with the AOV layers (render --aovs all)
  std::vector<std::string> outputs;  // by extension; an .exr keeps the input's layers
  std::string mode = "full";         // "full" or "preview"
  int threads = 0;                   // 0: all cores (the result does not depend on it)
};

struct CompareOptions {
  std::string image, reference, variance;  // variance: the reference's per-pixel variance (optional)
};

/// How a farm command reaches its coordinator.
struct ConnectionOptions {
  std::string server;      // else $TESSERA_SERVER, else http://127.0.0.1:8420
  std::string token_file;  // else $TESSERA_CLIENT_TOKEN
  std::string ca_file;     // verifies an https:// server (else the system's CAs)
};

/// `tessera submit`: the same rendering flags as render, sent to a coordinator.
struct SubmitOptions {
  std::string scene;
  ConnectionOptions connection;
  std::vector<std::string> outputs;  // implies wait
  int spp = 0, width = 0, height = 0, tile_size = 32, priority = 0;
  uint32_t seed = 0;
  std::map<std::string, std::string> defines;
  std::string integrator, light_selection, name;
  double target_error = 0;           // stop at this estimated relMSE (spp is then the budget)
  std::string guiding;               // "on", "off"; empty: as the scene says
  std::string adaptive = "off";      // adaptive sampling: "on" or "off"
  bool denoise = false;              // outputs get the denoised image, FILE.noisy.ext the raw one
  std::string denoise_mode = "full"; // "full" or "preview"
  std::string aovs;                  // AOV layers the EXR outputs carry (render/aov.h); empty: none
  bool allow_unsupported = false;
  std::string webhook;               // URL the coordinator POSTs the job's status to when it ends
  std::string frames;                // "A-B": one job per frame (-D frame=N); outputs carry ####
  bool wait = false, quiet = false;  // quiet: nothing printed but errors
  bool force = false;                // --wait without -o may overwrite JOBNAME.exr
};

struct JobsOptions {
  ConnectionOptions connection;
  uint64_t cancel_id = 0;  // run_cancel
};

/// Each returns the process exit code and prints its own messages.
int run_render(const RenderOptions& options);
/// `geometry` may also be a single scene .xml: its accelerator is used.
int run_bench_rays(const BenchRaysOptions& options);
int run_compare(const CompareOptions& options);
int run_denoise(const DenoiseOptions& options);
/// FILE.ext -> FILE.noisy.ext: where a denoised render's raw image goes (render and submit --denoise).
std::string noisy_path(const std::string& path);
int run_submit(const SubmitOptions& options);
int run_jobs(const JobsOptions& options);
int run_cancel(const JobsOptions& options);
/// $TESSERA_SERVER, else http://127.0.0.1:8420.
std::string default_server_url();

/// Parses argv and runs the chosen subcommand.
int main_entry(int argc, char** argv);

}  // namespace tessera::cli

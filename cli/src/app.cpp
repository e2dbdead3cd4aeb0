// Command-line surface of `tessera` (CLI11). Only option parsing; each subcommand is a library call.
#include "tessera/cli/commands.h"
#include "tessera/cli/convergence.h"

#include <CLI/CLI.hpp>

#include <iostream>

namespace tessera::cli {
namespace {

// "-D name=value" -> defines[name] = value.
bool parse_define(const std::string& kv, std::map<std::string, std::string>& out) {
  auto eq = kv.find('=');
  if (eq == std::string::npos || eq == 0) return false;
  out[kv.substr(0, eq)] = kv.substr(eq + 1);
  return true;
}

}  // namespace

int main_entry(int argc, char** argv) {
  CLI::App app{"Tessera: a physically based path tracer for Mitsuba scenes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("tessera ") + TESSERA_VERSION);

  RenderOptions render;
  std::vector<std::string> defines;
  auto* r = app.add_subcommand("render", "Render a Mitsuba XML scene to EXR/PFM/PNG");
  r->add_option("scene", render.scene, "Scene file (Mitsuba XML 0.5/0.6 or 2.x/3.x)")->required();
  r->add_option("-o,--output", render.outputs,
                "Output image(s): .exr, .pfm or .png (default: SCENE_STEM.exr in the current directory, "
                "plus SCENE_STEM.png for an ldrfilm)");
  r->add_option("--spp", render.spp, "Samples per pixel (default: the scene's)")->check(CLI::PositiveNumber);
  r->add_option("--target-error", render.target_error,
                "Stop at a pass whose estimated relMSE is at most this (--spp is then the budget)")
      ->check(CLI::Range(0.0, 1.0));
  r->add_option("--guiding", render.guiding,
                "Path guiding (path/volpath): the first half of the samples trains a guide, the rest use it "
                "and make the image (default: on for a guided_path integrator, else off)")
      ->check(CLI::IsMember({"on", "off"}));
  r->add_option("--adaptive", render.adaptive,
                "Adaptive sampling: after the first quarter of the samples, each pass spends its samples "
                "where the estimated error is (--spp stays the total; default off)")
      ->check(CLI::IsMember({"on", "off"}))->capture_default_str();
  r->add_option("--aovs", render.aovs,
                "Layers written into each .exr output beside the image: albedo, normal, depth, variance, "
                "half_a, half_b, comma-separated, or all (docs/denoising.md); the image stays the same bits");
  r->add_flag("--denoise", render.denoise,
              "Denoise: each -o FILE.ext gets the denoised image and FILE.noisy.ext the raw one; EXR outputs "
              "carry the AOV layers (all the denoiser's unless --aovs says), so tessera denoise FILE.noisy.exr "
              "gives the same bits");
  r->add_option("--denoise-mode", render.denoise_mode, "full, or preview (faster, less thorough)")
      ->check(CLI::IsMember({"full", "preview"}))->capture_default_str();
  r->add_option("--width", render.width, "Film width (default: the scene's)")->check(CLI::PositiveNumber);
  r->add_option("--height", render.height, "Film height (default: the scene's)")->check(CLI::PositiveNumber);
  r->add_option("--threads", render.threads, "Render threads (default: all cores)")->check(CLI::NonNegativeNumber);
  r->add_option("--tile-size", render.tile_size, "Tile edge in pixels (does not change the image)")
      ->check(CLI::Range(1, 4096));
  r->add_option("--seed", render.seed, "Sampling seed");
  r->add_option("-D", defines, "Override a scene <default>: -D name=value");
  r->add_option("--integrator", render.integrator, "Override the integrator")
      ->check(CLI::IsMember({"path", "volpath", "direct"}));
  r->add_option("--light-selection", render.light_selection,
                "How next-event estimation picks a light: power (alias table) or bvh (light hierarchy; "
                "default)")
      ->check(CLI::IsMember({"power", "bvh"}));
  r->add_flag("--allow-unsupported", render.allow_unsupported,
              "Substitute documented fallbacks for unsupported plugins/parameters");
  r->add_flag("-q,--quiet", render.quiet, "No progress output");

  auto* bench = app.add_subcommand("bench", "Benchmarks");
  bench->require_subcommand(1);
  tessera::BenchRaysOptions rays;
  auto* br = bench->add_subcommand("rays", "Trace a ray file (../shared/docs/rayfile.md) and report Mrays/s");
  br->add_option("geometry", rays.geometry, "Scene .xml, or OBJ files/folders")->required();
  br->add_option("--rays", rays.rays, "Ray file")->required()->check(CLI::ExistingFile);
  br->add_option("--hits", rays.hits_out, "Write the hit file here");
  br->add_option("--compare", rays.compare, "Reference hit file to check agreement against")
      ->check(CLI::ExistingFile);
  br->add_option("--threads", rays.threads, "Threads (default: all cores)")->check(CLI::NonNegativeNumber);
  br->add_option("--repeat", rays.repeat, "Trace each set this often and report the median (default 1)")
      ->check(CLI::Range(1, 100));

  ConvergenceOptions conv;
  auto* bc = bench->add_subcommand("convergence", "relMSE against a reference as the budget grows, per strategy (CSV, SVG)");
  bc->add_option("scene", conv.scene, "Scene file")->required()->check(CLI::ExistingFile);
  bc->add_option("--reference", conv.reference, "Reference image (.exr/.pfm/.hdr) of the same size")->required()
      ->check(CLI::ExistingFile);
  bc->add_option("--spp", conv.spp, "Budgets, e.g. 1,2,4,8 (default 1..64 doubling)")->delimiter(',');
  bc->add_option("--seconds", conv.seconds, "Then keep doubling spp until one render takes this long")
      ->check(CLI::NonNegativeNumber);
  bc->add_option("--guiding", conv.guiding, "Path guiding, e.g. off,on: each strategy with each (default off); "
                 "guided series are named STRATEGY+guiding")->delimiter(',')->check(CLI::IsMember({"off", "on"}));
  bc->add_option("--adaptive", conv.adaptive, "Adaptive sampling, e.g. off,on: each series with each (default off); "
                 "adaptive series are named SERIES+adaptive")->delimiter(',')->check(CLI::IsMember({"off", "on"}));
  bc->add_option("--strategy", conv.strategies, "Sampling strategies: mis, bsdf, nee (default mis)")->delimiter(',')
      ->check(CLI::IsMember({"mis", "bsdf", "nee"}));
  bc->add_option("--csv", conv.csv, "Write the measurements here");
  bc->add_option("--plot", conv.plot, "Write an SVG plot here (log-log relMSE against seconds and spp)");
  bc->add_option("--width", conv.width, "Film width (default: the scene's)")->check(CLI::PositiveNumber);
  bc->add_option("--height", conv.height, "Film height (default: the scene's)")->check(CLI::PositiveNumber);
  bc->add_option("--threads", conv.threads, "Render threads (default: all cores)")->check(CLI::NonNegativeNumber);
  bc->add_option("--seed", conv.seed, "Seed of the first budget (budget i uses seed + i)");
  bc->add_flag("--allow-unsupported", conv.allow_unsupported, "Substitute documented fallbacks for unsupported plugins");

  DenoiseOptions dn;
  auto* dsub = app.add_subcommand("denoise", "Denoise an EXR rendered with --aovs all (docs/denoising.md)");
  dsub->add_option("input", dn.input, "EXR with the AOV layers albedo, normal, depth, variance, half_a, half_b")
      ->required()->check(CLI::ExistingFile);
  dsub->add_option("-o,--output", dn.outputs, "Output image(s): .exr (with the input's AOV layers), .pfm or .png")
      ->required();
  dsub->add_option("--mode", dn.mode, "full, or preview (faster, less thorough)")
      ->check(CLI::IsMember({"full", "preview"}))->capture_default_str();
  dsub->add_option("--threads", dn.threads, "Threads (default: all cores; the result is the same)")
      ->check(CLI::NonNegativeNumber);

  CompareOptions compare;
  auto* cmp = app.add_subcommand("compare", "Error of an image against a reference (relMSE, means, z-scores)");
  cmp->add_option("image", compare.image, "Rendered image (.exr/.pfm/.hdr)")->required()->check(CLI::ExistingFile);
  cmp->add_option("reference", compare.reference, "Reference image")->required()->check(CLI::ExistingFile);
  cmp->add_option("--variance", compare.variance, "Per-pixel variance of the reference")->check(CLI::ExistingFile);

  SubmitOptions submit;
  std::vector<std::string> submit_defines;
  auto* sub = app.add_subcommand("submit", "Send a scene to a render farm coordinator (docs/api.md)");
  sub->add_option("scene", submit.scene, "Scene file; only the files it references are uploaded")->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--server", submit.server, "Coordinator URL (default: $TESSERA_SERVER or http://127.0.0.1:8420)");
  sub->add_option("--token-file", submit.token_file, "Client token file (default: $TESSERA_CLIENT_TOKEN)");
  sub->add_option("--ca-file", submit.ca_file, "PEM file to verify an https server (default: system CAs)")
      ->check(CLI::ExistingFile);
  sub->add_option("-o,--output", submit.outputs, "Wait, then download the image(s): .exr, .pfm or .png");
  sub->add_flag("--wait", submit.wait, "Wait for the job to finish, with a progress bar");
  sub->add_option("--spp", submit.spp, "Samples per pixel (default: the scene's)")->check(CLI::PositiveNumber);
  sub->add_option("--width", submit.width, "Film width (default: the scene's)")->check(CLI::PositiveNumber);
  sub->add_option("--height", submit.height, "Film height (default: the scene's)")->check(CLI::PositiveNumber);
  sub->add_option("--seed", submit.seed, "Sampling seed");
  sub->add_option("--tile-size", submit.tile_size, "Tile edge in pixels (does not change the image)")
      ->check(CLI::Range(4, 1024));
  sub->add_option("--priority", submit.priority, "Higher runs first");
  sub->add_option("--name", submit.name, "Job name (default: the scene's file name)");
  sub->add_option("-D", submit_defines, "Override a scene <default>: -D name=value");
  sub->add_option("--integrator", submit.integrator, "Override the integrator")
      ->check(CLI::IsMember({"path", "volpath", "direct"}));
  sub->add_option("--light-selection", submit.light_selection, "power or bvh")->check(CLI::IsMember({"power", "bvh"}));
  sub->add_option("--target-error", submit.target_error, "Stop at this estimated relMSE (--spp is then the budget)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--guiding", submit.guiding,
                  "Path guiding, as for render: the same image (default: on for a guided_path integrator, "
                  "else off)")
      ->check(CLI::IsMember({"on", "off"}));
  sub->add_flag("--denoise", submit.denoise,
                "Denoise the finished image on the coordinator (job field denoise): each -o FILE.ext gets the "
                "denoised image and FILE.noisy.ext the raw one (its EXR with the AOV layers), as render --denoise");
  sub->add_option("--adaptive", submit.adaptive, "Adaptive sampling, as for render: the same image (default off)")
      ->check(CLI::IsMember({"on", "off"}))->capture_default_str();
  sub->add_option("--webhook", submit.webhook, "URL the coordinator POSTs the job's status to when it ends");
  sub->add_option("--frames", submit.frames, "Render frames A-B, one job each with -D frame=N; '#'s in -o become N");
  sub->add_flag("-q,--quiet", submit.quiet, "No progress output");

  JobsOptions jobs;
  auto* jl = app.add_subcommand("jobs", "List a coordinator's jobs");
  jl->add_option("--token-file", jobs.token_file, "Client token file (default: $TESSERA_CLIENT_TOKEN)");
  jl->add_option("--ca-file", jobs.ca_file, "PEM file to verify an https server")->check(CLI::ExistingFile);
  jl->add_option("--server", jobs.server, "Coordinator URL (default: $TESSERA_SERVER or http://127.0.0.1:8420)");
  auto* cancel = app.add_subcommand("cancel", "Cancel a job");
  cancel->add_option("id", jobs.cancel_id, "Job id")->required();
  cancel->add_option("--token-file", jobs.token_file, "Client token file (default: $TESSERA_CLIENT_TOKEN)");
  cancel->add_option("--ca-file", jobs.ca_file, "PEM file to verify an https server")->check(CLI::ExistingFile);
  cancel->add_option("--server", jobs.server, "Coordinator URL (default: $TESSERA_SERVER or http://127.0.0.1:8420)");

  CLI11_PARSE(app, argc, argv);

  if (sub->parsed()) {
    for (const auto& d : submit_defines)
      if (!parse_define(d, submit.defines)) {
        std::cerr << "tessera submit: -D expects name=value, got '" << d << "'\n";
        return 2;
      }
    return run_submit(submit);
  }
  if (jl->parsed()) return run_jobs(jobs);
  if (cancel->parsed()) return run_cancel(jobs);

  if (r->parsed()) {
    for (const auto& d : defines)
      if (!parse_define(d, render.defines)) {
        std::cerr << "tessera render: -D expects name=value, got '" << d << "'\n";
        return 2;
      }
    return run_render(render);
  }
  if (br->parsed()) return run_bench_rays(rays);
  if (bc->parsed()) return run_bench_convergence(conv);
  if (cmp->parsed()) return run_compare(compare);
  if (dsub->parsed()) return run_denoise(dn);
  return 2;
}

}  // namespace tessera::cli

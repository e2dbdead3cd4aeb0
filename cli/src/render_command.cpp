// `tessera render`: parse -> load (meshes, images, BVH) -> render -> write, with timings.
#include "render_output.h"
#include "strategy_images.h"

#include "tessera/cli/command_line.h"
#include "tessera/cli/commands.h"
#include "tessera/cli/progress.h"
#include "tessera/denoise/denoiser.h"
#include "tessera/scene/error.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "tessera/sequence/renderer.h"

#include <tbb/info.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>

namespace tessera::cli {
namespace {

using Clock = std::chrono::steady_clock;

// A flag whose value turned out wrong once the scene was loaded (exit code 2, as CLI11's are).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void print_messages(const LoadResult& result) {
  for (const auto& m : result.messages)
    std::cerr << (m.level == LoadMessage::Level::Warning ? "warning: " : "note: ") << m.loc.str() << ": "
              << m.text << "\n";
}

// The AOV layers the outputs get (--aovs, or the denoiser's with --denoise); none, with the reason
// printed, when the outputs or the list are wrong.
std::optional<std::vector<AovLayer>> output_layers(const RenderOptions& options) {
  for (const auto& out : options.outputs) {
    const std::string ext = lower_extension(out);
    if (ext != ".exr" && ext != ".pfm" && ext != ".png") {
      std::cerr << "tessera render: output '" << out << "': unknown format (use .exr, .pfm or .png)\n";
      return std::nullopt;
    }
  }
  if (options.aovs.empty()) return options.denoise ? denoise_layers() : std::vector<AovLayer>{};
  std::string error;
  auto parsed = parse_aov_layers(options.aovs, &error);
  if (!parsed) {
    std::cerr << "tessera render: --aovs: " << error << "\n";
    return std::nullopt;
  }
  bool exr = false;
  for (const auto& out : options.outputs) exr |= lower_extension(out) == ".exr";
  if (!exr && !options.outputs.empty()) {
    std::cerr << "tessera render: --aovs: AOV layers are written only into .exr outputs; give one with -o\n";
    return std::nullopt;
  }
  return parsed;
}

// Parses and loads the scene as the options say, timing both. Throws the loader's errors.
LoadResult load_render_scene(const RenderOptions& options, LoadTimes& times) {
  auto t_parse = Clock::now();
  ParseOptions parse_options;
  parse_options.defines = options.defines;
  SceneDesc desc = parse_scene_file(options.scene, parse_options);
  times.parse = seconds_since(t_parse);
  auto t_load = Clock::now();
  LoadOptions load_options;
  load_options.allow_unsupported = options.allow_unsupported;
  load_options.width = options.width;
  load_options.height = options.height;
  load_options.spp = options.spp;
  load_options.integrator = options.integrator;
  LoadResult loaded = load_scene(desc, load_options);
  times.load = seconds_since(t_load);
  print_messages(loaded);
  if (!options.light_selection.empty()) {
    LightSelection selection;
    if (!parse_light_selection(options.light_selection, selection))
      throw UsageError("--light-selection: unknown strategy '" + options.light_selection + "'");
    loaded.scene->set_light_selection(selection);
  }
  return loaded;
}

RenderSettings render_settings(const RenderOptions& options, const Scene& scene, bool aovs) {
  RenderSettings settings;
  settings.spp = scene.sampler.sample_count;
  settings.seed = options.seed;
  settings.threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
  settings.tile_size = options.tile_size;
  settings.target_error = options.target_error;
  // Guiding as the command line says, else as the scene's integrator does (guide_plan()).
  if (!options.guiding.empty()) settings.guiding = options.guiding == "on";
  settings.adaptive = options.adaptive == "on";
  settings.aovs = aovs || options.denoise;
  return settings;
}

// Renders with a progress bar in samples per pixel, moving with the work done (later passes are
// longer; a light tracer's passes of paths count as much as their samples).
Film render_with_progress(const Scene& scene, const RenderSettings& settings, bool quiet, RenderStats& stats) {
  Progress progress("render", !quiet);
  Film film = render(
      scene, settings,
      [&](const RenderProgress& p) { progress.update(p.done_fraction * double(settings.spp), double(settings.spp)); },
      &stats);
  progress.finish();
  return film;
}

}  // namespace

int run_render(const RenderOptions& options) {
  const std::optional<std::vector<AovLayer>> aovs = output_layers(options);
  if (!aovs) return 2;
  try {
    LoadTimes times;
    LoadResult loaded = load_render_scene(options, times);
    const Scene& scene = *loaded.scene;
    const RenderSettings settings = render_settings(options, scene, !aovs->empty());
    if (!options.strategy_images.empty() && scene.integrator.type != IntegratorType::Bdpt)
      throw UsageError("--strategy-images: the scene is not rendered by bdpt (use --integrator bdpt)");
    RenderStats stats;
    const Film film = render_with_progress(scene, settings, options.quiet, stats);
    write_outputs(options, scene, film, stats.spp_done, *aovs);
    print_render_report(options, scene, settings, stats, film, times);
    if (!options.strategy_images.empty()) {
      const int n = write_strategy_images(*loaded.scene, settings, options.strategy_images);
      if (!options.quiet) std::cerr << "strategy images: " << n << " in " << options.strategy_images << "\n";
    }
    return 0;
  } catch (const UsageError& e) {
    std::cerr << "tessera render: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {  // (SceneError and UnsupportedError name file and line)
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}

Command add_render_command(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  auto defines = std::make_shared<std::vector<std::string>>();
  CLI::App* r = app.add_subcommand("render", "Render a Mitsuba XML scene to EXR/PFM/PNG");
  r->add_option("scene", o->scene, "Scene file (Mitsuba XML 0.5/0.6 or 2.x/3.x)")->required();
  r->add_option("-o,--output", o->outputs,
                "Output image(s): .exr, .pfm or .png (default: SCENE_STEM.exr in the current directory, "
                "plus SCENE_STEM.png for an ldrfilm)");
  r->add_option("--spp", o->spp, "Samples per pixel (default: the scene's)")->check(CLI::PositiveNumber);
  r->add_option("--target-error", o->target_error,
                "Stop at a pass whose estimated relMSE is at most this (--spp is then the budget)")
      ->check(CLI::Range(0.0, 1.0));
  r->add_option("--guiding", o->guiding,
                "Path guiding (path/volpath): iterations of 1, 2, 4, ... samples per pixel each learn from the "
                "ones before; the last four make the image (default: on for a guided_path integrator, else off)")
      ->check(CLI::IsMember({"on", "off"}));
  r->add_option("--adaptive", o->adaptive,
                "Adaptive sampling: after the first quarter of the samples, each pass spends its samples "
                "where the estimated error is (--spp stays the total; default off)")
      ->check(CLI::IsMember({"on", "off"}))->capture_default_str();
  r->add_option("--aovs", o->aovs,
                "Layers written into each .exr output beside the image: albedo, normal, depth, variance, "
                "half_a, half_b, comma-separated, or all (docs/denoising.md); the image stays the same bits");
  r->add_flag("--denoise", o->denoise,
              "Denoise: each -o FILE.ext gets the denoised image and FILE.noisy.ext the raw one; EXR outputs "
              "carry the AOV layers (all the denoiser's unless --aovs says), so tessera denoise FILE.noisy.exr "
              "gives the same bits");
  r->add_option("--denoise-mode", o->denoise_mode, "full, or preview (faster, less thorough)")
      ->check(CLI::IsMember({"full", "preview"}))->capture_default_str();
  r->add_option("--width", o->width, "Film width (default: the scene's)")->check(CLI::PositiveNumber);
  r->add_option("--height", o->height, "Film height (default: the scene's)")->check(CLI::PositiveNumber);
  r->add_option("--threads", o->threads, "Render threads (default: all cores)")->check(CLI::NonNegativeNumber);
  r->add_option("--tile-size", o->tile_size, "Tile edge in pixels (does not change the image)")->check(CLI::Range(1, 4096));
  r->add_option("--seed", o->seed, "Sampling seed");
  r->add_option("-D", *defines, "Override a scene <default>: -D name=value");
  add_integrator_option(*r, o->integrator);
  r->add_option("--light-selection", o->light_selection,
                "How next-event estimation picks a light: power (alias table) or bvh (light hierarchy; default)")
      ->check(CLI::IsMember({"power", "bvh"}));
  r->add_option("--strategy-images", o->strategy_images,
                "bdpt: also write DIR/sS_tT.exr, what each strategy (s light and t camera vertices) adds with "
                "its MIS weight, for paths up to the max depth (5 when unbounded); they sum to the image");
  r->add_flag("--allow-unsupported", o->allow_unsupported, "Substitute documented fallbacks for unsupported plugins/parameters");
  r->add_flag("-q,--quiet", o->quiet, "No progress output");
  return {r, [o, defines] { return parse_defines(*defines, o->defines, "tessera render") ? run_render(*o) : 2; }};
}

}  // namespace tessera::cli

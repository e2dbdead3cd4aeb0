// `tessera render`: parse -> load (meshes, images, BVH) -> render -> write, with timings.
#include "tessera/cli/commands.h"
#include "tessera/cli/progress.h"
#include "tessera/denoise/denoiser.h"
#include "tessera/image/image.h"
#include "tessera/sequence/path_program.h"
#include "tessera/sequence/renderer.h"
#include "tessera/render/shape.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "tessera/texture/bitmap.h"

#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace tessera::cli {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void print_messages(const LoadResult& result) {
  for (const auto& m : result.messages)
    std::cerr << (m.level == LoadMessage::Level::Warning ? "warning: " : "note: ") << m.loc.str() << ": "
              << m.text << "\n";
}

// Without -o: the scene's stem in the current directory (the scene's own folder may be read-only),
// as EXR, plus PNG when the scene asked for an ldrfilm.
std::vector<std::string> output_paths(const RenderOptions& options, const Scene& scene) {
  if (!options.outputs.empty()) return options.outputs;
  std::string stem = std::filesystem::path(options.scene).stem().string();
  std::vector<std::string> outs = {stem + ".exr"};
  if (scene.film.ldr) outs.push_back(stem + ".png");
  return outs;
}

void write_output(const std::string& out, const Scene& scene, const Image& image, const std::vector<ImageLayer>& layers,
                  const ImageAttributes& attributes) {
  auto parent = std::filesystem::path(out).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  const std::string ext = lower_extension(out);
  if (ext == ".png") {
    LdrSettings ldr;
    if (scene.film.ldr) {
      ldr.gamma = scene.film.gamma;
      ldr.exposure = scene.film.exposure;
    }
    write_png(out, image, ldr);
  } else if (ext == ".exr") {
    write_exr_layers(out, image, layers, attributes);
  } else {
    write_image(out, image, attributes);
  }
  std::cerr << "wrote " << out << "\n";
}

// Each output gets the image; with --denoise the denoised one, and FILE.noisy.ext the raw one. The
// denoiser reads the float32 layers the EXR outputs hold, so `tessera denoise FILE.noisy.exr`
// gives the same bits.
void write_outputs(const RenderOptions& options, const Scene& scene, const Film& film, uint32_t spp,
                   const std::vector<AovLayer>& aovs) {
  const Image raw = film.to_image();
  const std::vector<ImageLayer> layers = film.aov_layers(aovs);
  const ImageAttributes attributes = {{"tessera_version", TESSERA_VERSION},
                                      {"tessera_scene", options.scene},
                                      {"tessera_spp", std::to_string(spp)},
                                      {"tessera_seed", std::to_string(options.seed)}};
  Image denoised;
  if (options.denoise) {
    DenoiseSettings settings;
    settings.mode = options.denoise_mode == "preview" ? DenoiseMode::Preview : DenoiseMode::Full;
    settings.threads = options.threads;
    const auto start = Clock::now();
    // (The layers written already hold the denoiser's unless --aovs named fewer.)
    const std::vector<AovLayer> needed = denoise_layers();
    const bool written = std::all_of(needed.begin(), needed.end(), [&](AovLayer l) {
      return std::find(aovs.begin(), aovs.end(), l) != aovs.end();
    });
    denoised = denoise(make_denoise_input(raw, written ? layers : film.aov_layers(needed)), settings);
    std::fprintf(stderr, "denoise (%s): %.3f s\n", options.denoise_mode.c_str(), seconds_since(start));
  }
  for (const auto& out : output_paths(options, scene)) {
    if (options.denoise) {
      write_output(out, scene, denoised, layers, attributes);
      write_output(noisy_path(out), scene, raw, layers, attributes);
    } else {
      write_output(out, scene, raw, layers, attributes);
    }
  }
}

}  // namespace

int run_render(const RenderOptions& options) {
  for (const auto& out : options.outputs) {
    std::string ext = lower_extension(out);
    if (ext != ".exr" && ext != ".pfm" && ext != ".png") {
      std::cerr << "tessera render: output '" << out << "': unknown format (use .exr, .pfm or .png)\n";
      return 2;
    }
  }
  std::vector<AovLayer> aovs;
  if (options.denoise && options.aovs.empty()) aovs = denoise_layers();
  if (!options.aovs.empty()) {
    std::string error;
    auto parsed = parse_aov_layers(options.aovs, &error);
    if (!parsed) {
      std::cerr << "tessera render: --aovs: " << error << "\n";
      return 2;
    }
    aovs = *parsed;
    bool exr = false;
    for (const auto& out : options.outputs) exr |= lower_extension(out) == ".exr";
    if (!exr && !options.outputs.empty()) {
      std::cerr << "tessera render: --aovs: AOV layers are written only into .exr outputs; give one with -o\n";
      return 2;
    }
  }
  try {
    auto t_parse = Clock::now();
    ParseOptions parse_options;
    parse_options.defines = options.defines;
    SceneDesc desc = parse_scene_file(options.scene, parse_options);
    double parse_s = seconds_since(t_parse);

    auto t_load = Clock::now();
    LoadOptions load_options;
    load_options.allow_unsupported = options.allow_unsupported;
    load_options.width = options.width;
    load_options.height = options.height;
    load_options.spp = options.spp;
    load_options.integrator = options.integrator;
    LoadResult loaded = load_scene(desc, load_options);
    double load_s = seconds_since(t_load);
    print_messages(loaded);
    if (!options.light_selection.empty()) {
      LightSelection selection;
      if (!parse_light_selection(options.light_selection, selection)) {
        std::cerr << "tessera render: --light-selection: unknown strategy '" << options.light_selection << "'\n";
        return 2;
      }
      loaded.scene->set_light_selection(selection);
    }
    const Scene& scene = *loaded.scene;

    RenderSettings settings;
    settings.spp = scene.sampler.sample_count;
    settings.seed = options.seed;
    settings.threads = options.threads > 0 ? options.threads : tbb::info::default_concurrency();
    settings.tile_size = options.tile_size;
    settings.target_error = options.target_error;
    // Guiding as the command line says, else as the scene's integrator does (guide_plan()).
    if (!options.guiding.empty()) settings.guiding = options.guiding == "on";
    settings.adaptive = options.adaptive == "on";
    settings.aovs = !aovs.empty() || options.denoise;

    const std::vector<uint32_t> passes = pass_schedule(uint32_t(settings.spp));
    Progress progress("render", !options.quiet);
    RenderStats stats;
    Film film = render(
        scene, settings,
        [&](const RenderProgress& p) {
          // Weigh tiles by their pass's samples: later passes are longer than the first ones.
          double tiles_per_pass = double(p.tiles_total) / std::max(p.num_passes, 1);
          double in_pass = double(p.tiles_done) - double(p.pass) * tiles_per_pass;
          double done = double(p.samples_done) + double(passes[size_t(p.pass)]) * in_pass / tiles_per_pass;
          progress.update(done, double(settings.spp));
        },
        &stats);
    progress.finish();
    write_outputs(options, scene, film, stats.spp_done, aovs);

    const auto& c = stats.counters;
    const size_t accel = scene.accel_bytes();
    const size_t meshes = scene.memory().meshes;
    const TextureMemory textures = texture_memory(scene.textures);
    std::fprintf(stderr,
                 "scene %s: %zu triangles (%llu with instances), %zu shapes, %zu instances, %zu lights (%zu selectable, %s selection); BVH %.1f MB\n"
                 "memory: BVH %.1f bytes/triangle, meshes %.1f MB (%.1f bytes/triangle), textures %.1f MB in %zu "
                 "images (%.1f MB as float)\n"
                 "times: parse %.3f s, load %.3f s (BVH build %.3f s), render %.3f s\n"
                 "render: %dx%d, %d spp, %d threads: %.3g samples/s, %.3g rays/s",
                 options.scene.c_str(), scene.num_triangles(), (unsigned long long)scene.num_instanced_triangles(),
                 scene.shapes.size(), scene.instances.size(), scene.lights.size(),
                 scene.light_sampler().lights().size(), light_selection_name(scene.light_sampler().strategy()),
                 double(accel) / 1e6,
                 double(accel) / double(std::max<size_t>(scene.num_triangles(), 1)), double(meshes) / 1e6,
                 double(meshes) / double(std::max<size_t>(scene.num_triangles(), 1)), double(textures.bytes) / 1e6,
                 textures.images, double(textures.float_bytes) / 1e6, parse_s, load_s - scene.bvh_build_seconds(),
                 scene.bvh_build_seconds(), stats.seconds, film.width(), film.height(), settings.spp,
                 settings.threads, double(c.samples) / std::max(stats.seconds, 1e-9),
                 double(c.rays()) / std::max(stats.seconds, 1e-9));
    if (c.nonfinite > 0) std::fprintf(stderr, "; %llu NaN/Inf samples dropped", (unsigned long long)c.nonfinite);
    std::fprintf(stderr, "\n");
    if (stats.guide_leaves > 0)
      std::fprintf(stderr, "guide: %zu spatial leaves, %.1f MB (cap %.0f MB)\n", stats.guide_leaves,
                   double(stats.guide_bytes) / 1e6, double(guide_plan(scene, settings.guiding)->settings.max_bytes) / 1e6);
    if (settings.target_error > 0)
      std::fprintf(stderr, "target error %g: %s at %u spp, estimated relMSE %.4g\n", settings.target_error,
                   stats.spp_done < uint32_t(settings.spp) ? "stopped" : "not reached, budget spent", stats.spp_done,
                   stats.noise_estimate);
    return 0;
  } catch (const UnsupportedError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const SceneError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace tessera::cli

#include "render_output.h"

#include "tessera/denoise/denoiser.h"
#include "tessera/image/image.h"
#include "tessera/render/shape.h"
#include "tessera/sequence/path_program.h"
#include "tessera/sequence/photon_program.h"
#include "tessera/texture/bitmap.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace tessera::cli {

namespace {

using Clock = std::chrono::steady_clock;

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

}  // namespace

// The denoiser reads the float32 layers the EXR outputs hold, so `tessera denoise FILE.noisy.exr`
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
    std::fprintf(stderr, "denoise (%s): %.3f s\n", options.denoise_mode.c_str(),
                 std::chrono::duration<double>(Clock::now() - start).count());
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

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void print_render_report(const RenderOptions& options, const Scene& scene, const RenderSettings& settings,
                         const RenderStats& stats, const Film& film, const LoadTimes& times) {
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
               textures.images, double(textures.float_bytes) / 1e6, times.parse, times.load - scene.bvh_build_seconds(),
               scene.bvh_build_seconds(), stats.seconds, film.width(), film.height(), settings.spp,
               settings.threads, double(c.samples) / std::max(stats.seconds, 1e-9),
               double(c.rays()) / std::max(stats.seconds, 1e-9));
  if (c.nonfinite > 0) std::fprintf(stderr, "; %llu NaN/Inf samples dropped", (unsigned long long)c.nonfinite);
  std::fprintf(stderr, "\n");
  if (stats.guide_stepped_aside)
    std::fprintf(stderr, "guide: stepped aside, its predicted gain %.3g below the least of %g: the rest rendered unguided\n",
                 double(stats.guide_gain), guide_plan(scene, settings.guiding)->settings.min_gain);
  else if (stats.guide_leaves > 0)
    std::fprintf(stderr, "guide: %zu spatial leaves, %.1f MB (cap %.0f MB), predicted gain %.3g\n", stats.guide_leaves,
                 double(stats.guide_bytes) / 1e6, double(guide_plan(scene, settings.guiding)->settings.max_bytes) / 1e6,
                 double(stats.guide_gain));
  if (const std::optional<PointMapPlan> points = point_map_plan(scene))
    std::fprintf(stderr, "%s: initial radius %.4g (%s), alpha %.3g\n", integrator_name(points->type),
                 double(points->initial_radius), scene.integrator.initial_radius > 0.f ? "the scene's" : "automatic",
                 double(points->alpha));
  if (const EmissionPortal& portal = scene.emission_portal(); portal.active())
    std::fprintf(stderr, "emission portal: %d boxes from %u escapes of %u pilot camera paths\n", portal.box_count(),
                 portal.escapes(), EmissionPortal::kPilotPaths);
  if (settings.target_error > 0)
    std::fprintf(stderr, "target error %g: %s at %u spp, estimated relMSE %.4g\n", settings.target_error,
                 stats.spp_done < uint32_t(settings.spp) ? "stopped" : "not reached, budget spent", stats.spp_done,
                 stats.noise_estimate);
}

}  // namespace tessera::cli

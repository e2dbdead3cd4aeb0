// `tessera denoise IN.exr -o OUT.exr`: the denoiser (denoise/denoiser.h) on an EXR written with
// `--aovs all`. An EXR output keeps the input's AOV layers beside the denoised image.
#include "tessera/cli/command_line.h"
#include "tessera/cli/commands.h"
#include "tessera/denoise/denoiser.h"
#include "tessera/image/image.h"

#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>

namespace tessera::cli {

std::string noisy_path(const std::string& path) {
  std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + ".noisy" + p.extension().string())).string();
}

int run_denoise(const DenoiseOptions& options) {
  try {
    ImageAttributes attributes;  // kept: the render's scene, seed and spp
    const DenoiseInput in = read_denoise_input(options.input, &attributes);
    DenoiseSettings settings;
    settings.mode = options.mode == "preview" ? DenoiseMode::Preview : DenoiseMode::Full;
    settings.threads = options.threads;
    const auto start = std::chrono::steady_clock::now();
    const Image out = denoise(in, settings);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double megapixels = double(out.width()) * double(out.height()) / 1e6;
    for (const auto& path : options.outputs) {
      const auto parent = std::filesystem::path(path).parent_path();
      if (!parent.empty()) std::filesystem::create_directories(parent);
      if (std::filesystem::path(path).extension() == ".exr")
        write_exr_layers(path, out, denoise_input_layers(in), attributes);
      else
        write_image(path, out, attributes);
      std::fprintf(stderr, "wrote %s\n", path.c_str());
    }
    std::fprintf(stderr, "denoise (%s): %dx%d in %.3f s (%.2f s per megapixel)\n", options.mode.c_str(), out.width(),
                 out.height(), seconds, seconds / std::max(megapixels, 1e-9));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

Command add_denoise_command(CLI::App& app) {
  auto o = std::make_shared<DenoiseOptions>();
  CLI::App* d = app.add_subcommand("denoise", "Denoise an EXR rendered with --aovs all (docs/denoising.md)");
  d->add_option("input", o->input, "EXR with the AOV layers albedo, normal, depth, variance, half_a, half_b")
      ->required()->check(CLI::ExistingFile);
  d->add_option("-o,--output", o->outputs, "Output image(s): .exr (with the input's AOV layers), .pfm or .png")
      ->required();
  d->add_option("--mode", o->mode, "full, or preview (faster, less thorough)")
      ->check(CLI::IsMember({"full", "preview"}))->capture_default_str();
  d->add_option("--threads", o->threads, "Threads (default: all cores; the result is the same)")
      ->check(CLI::NonNegativeNumber);
  return {d, [o] { return run_denoise(*o); }};
}

}  // namespace tessera::cli

// What `tessera render` writes and prints once the image is made: the outputs (denoised and raw
// with --denoise), and the report of the scene, its memory and the render's speed.
#pragma once

#include "tessera/cli/commands.h"
#include "tessera/render/aov.h"
#include "tessera/render/film.h"
#include "tessera/render/scene.h"
#include "tessera/sequence/renderer.h"

#include <string>
#include <vector>

namespace tessera::cli {

/// The extension of `path`, lower case, with its dot ("" when none).
std::string lower_extension(const std::string& path);

/// Each output gets the image; with --denoise the denoised one, and FILE.noisy.ext the raw one.
void write_outputs(const RenderOptions& options, const Scene& scene, const Film& film, uint32_t spp,
                   const std::vector<AovLayer>& aovs);

/// Seconds spent parsing and loading (the BVH build included) before the render.
struct LoadTimes {
  double parse = 0, load = 0;
};

/// The report on standard error: scene, memory, times and speed; guide and target error if any.
void print_render_report(const RenderOptions& options, const Scene& scene, const RenderSettings& settings,
                         const RenderStats& stats, const Film& film, const LoadTimes& times);

}  // namespace tessera::cli

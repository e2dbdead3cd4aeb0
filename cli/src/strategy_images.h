// `tessera render --strategy-images DIR`: what each strategy of bidirectional path tracing adds
// to the image (pbrt-v4's visualizestrategies), for debugging a scene's light transport.
#pragma once

#include "tessera/render/scene.h"
#include "tessera/sequence/renderer.h"

#include <string>

namespace tessera::cli {

/// Renders `scene` (a bdpt scene) once per strategy (s, t) of paths up to its max depth (5 when
/// unbounded), each with its MIS weight, and writes DIR/s{s}_t{t}.exr: the images sum to the
/// render's up to that length. Returns the number written; throws std::invalid_argument for an
/// integrator that is not bdpt and std::runtime_error when DIR cannot be made.
int write_strategy_images(Scene& scene, const RenderSettings& settings, const std::string& dir);

}  // namespace tessera::cli

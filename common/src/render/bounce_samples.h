// The dimensions of one bounce of a camera path, drawn in one fixed layout whether used or not
// (render/sampler.h), so that a pixel's later bounces see the same dimensions whatever happened
// before: `path`, `volpath` and the camera subpaths of `bdpt` share it.
#pragma once

#include "tessera/core/vec.h"
#include "tessera/render/sampler.h"

namespace tessera {

struct BounceSamples {
  float u_pick;   // light selection
  Vec2 u_light;   // a point on the light
  float u_lobe;   // the BSDF's lobe (unused by phase functions)
  Vec2 u_dir;     // the scattered direction
  float u_rr;     // Russian roulette
  static BounceSamples draw(Sampler& sampler) {
    BounceSamples b;
    b.u_pick = sampler.next_1d();
    b.u_light = sampler.next_2d();
    b.u_lobe = sampler.next_1d();
    b.u_dir = sampler.next_2d();
    b.u_rr = sampler.next_1d();
    return b;
  }
};

}  // namespace tessera

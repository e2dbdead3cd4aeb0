// The photon half of an sppm pass (sppm.h): bdpt's light subpaths, their non-delta vertices after
// the first segment stored as photons.
#include "tessera/render/sppm.h"

#include "render/bdpt_subpath.h"
#include "render/octahedral.h"
#include "tessera/render/render_tile.h"
#include "tessera/render/sampler.h"

#include <cmath>

namespace tessera {

float sppm_initial_radius(const Scene& scene) {
  if (scene.integrator.initial_radius > 0.f) return scene.integrator.initial_radius;
  const Bounds3 b = scene.bounds();
  const float radius = b.empty() ? 1.f : std::max(0.5f * length(b.diagonal()), 1e-4f);
  return 5.f * radius / float(std::max({scene.film.width, scene.film.height, 1}));
}

void trace_photons(const Scene& scene, uint32_t pass, uint64_t begin, uint64_t end, uint32_t seed,
                   std::vector<Photon>& out, RenderCounters& counters) {
  const IntegratorSettings& s = scene.integrator;
  Sampler sampler(scene.sampler.type, seed);
  thread_local bdpt::LightSubpath light;
  for (uint64_t i = begin; i < end; ++i) {
    sampler.start_pixel_sample(photon_pixel(i), pass);
    const float time = camera_sample_time(scene, sampler);
    ++counters.samples;
    if (s.max_depth == 0) continue;
    bdpt::trace_light_subpath(scene, s, sampler, time, light, counters);
    for (const bdpt::Vertex& v : light.vertices) {
      if (v.length < 2 && !s.photon_direct) continue;  // (direct light: next-event estimation's)
      Photon ph;
      for (int c = 0; c < 3; ++c) {
        ph.p[c] = v.si.p[c];
        ph.power[c] = v.beta[c];
      }
      if (!(std::isfinite(ph.power[0]) && std::isfinite(ph.power[1]) && std::isfinite(ph.power[2]))) {
        ++counters.nonfinite;
        continue;
      }
      ph.wi = octahedral::encode(v.wo_world, 16);
      bdpt::encode_record_normal(v.si.ng, v.wo_world, ph.n);
      ph.length = uint16_t(std::min(v.length, 0xFFFF));
      out.push_back(ph);
    }
  }
}

}  // namespace tessera

// Stochastic progressive photon mapping (`sppm`: Hachisuka and Jensen 2009, built as pbrt-v4 builds
// it), for the light paths a camera path cannot find: caustics seen through glass or water
// (specular-diffuse-specular paths) and caustics of point lights.
//
// A render is passes k = 0, 1, ...; each has two halves (sequence/photon_program.h runs them):
//   photons  photon_count light subpaths, started as bdpt starts them (a light picked by power, its
//            emission sampled, distant lights through the scene's emission portal) and continued by
//            the adjoint BSDF with Russian roulette. Each stores a photon at every non-delta surface
//            it reaches after its first segment (direct light is next-event estimation's). Photon i
//            of pass k draws from the sampler at pseudo-pixel photon_pixel(i), sample index k, so it
//            is the same whichever unit, thread or machine traces it.
//   gather   per pixel, sample k's camera ray, followed through delta BSDFs to its first non-delta
//            vertex: the visible point. Emitters the ray hits on the way, and next-event estimation
//            at the visible point (full weight), are the pass's direct light. Photons within the
//            pixel's radius r whose surface faces the same way add its indirect light:
//            Phi = sum of power * f(wo, wi) over those photons.
// Per pixel, across passes (SppmPixel): radius r (initially the photon map's cell), photon count N,
// flux tau. A pass that finds M photons updates them with alpha (the fraction of new photons kept):
//   N' = N + alpha M,  r' = r sqrt(N' / (N + M)),  tau' = (tau + beta Phi) r'^2 / r^2,
// beta being the camera path's throughput to the visible point. After K passes the pixel's radiance
// is (sum of the passes' direct light) / K + tau_K / (K photon_count pi r_K^2).
//
// The film: pass k adds one sample to each pixel, direct_k + I_k - I_(k-1), with I_k = tau_k /
// (photon_count pi r_k^2) (I_-1 = 0). The film's mean over the passes done is then the estimate
// above at every pass (a preview shows the passes done so far), and a pixel's sums follow the
// film's pass order like any other technique's. (Its per-pixel variance means nothing: sppm has no
// target error or adaptive sampling.)
//
// Depth: a path of c camera segments to the visible point and a photon of l segments from its light
// is c + l segments long, gathered only if that is at most max_depth (-1: unbounded), so
// IntegratorSettings::max_depth means what it means for `path` and `bdpt`.
//
// Differences from Mitsuba 0.6's sppm: direct light at visible points is next-event estimation, as
// pbrt-v4 does (Mitsuba gathers it from photons too: the same expected image, less noise here);
// the delta part of a BSDF with both kinds of lobes (smooth plastic's coating) ends at the visible
// point, which has only the smooth part (so does pbrt-v4's). Surfaces only: media are volpath's.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/vec.h"
#include "tessera/render/film.h"
#include "tessera/render/point_grid.h"
#include "tessera/render/scene.h"

#include <cstdint>
#include <span>
#include <vector>

namespace tessera {

/// One stored photon: 32 bytes, the layout of a photon map's bytes (little-endian).
struct Photon {
  float p[3];
  float power[3];     // flux carried (before the BSDF where it landed), per photon traced
  uint32_t wi;        // octahedral 16:16, unit, world: towards where the photon came from
  uint8_t n[2];       // octahedral 8:8: the surface's geometric normal on the side it arrived
  uint16_t length;    // segments from the light
};
static_assert(sizeof(Photon) == 32, "photon records are 32 bytes");

/// At most this many bytes of photons a pass (1 GiB: 33,554,432 photons); a scene asking for more
/// is refused when it loads.
inline constexpr uint64_t kMaxPhotonMapBytes = uint64_t(1) << 30;
inline constexpr uint64_t kMaxPhotonsPerPass = kMaxPhotonMapBytes / sizeof(Photon);

/// A pass's photons, for gathers (point_grid.h).
using PhotonMap = PointGrid<Photon>;

/// A pixel's statistics across passes (see above): 32 bytes, the layout of a gather unit's state.
struct SppmPixel {
  float radius = 0.f;
  float n = 0.f;
  double tau[3] = {0, 0, 0};
};
static_assert(sizeof(SppmPixel) == 32, "per-pixel state is 32 bytes");

/// The gather radius of the first pass: the scene's own, else Mitsuba's guess (5 scene-sphere
/// radii over the film's larger side).
float sppm_initial_radius(const Scene& scene);

/// The sampler's pixel for photon `i` (outside any film, so no camera sample shares it).
inline Vec2i photon_pixel(uint64_t i) { return {-1 - int(i & 0xFFFF), int(i >> 16)}; }

/// Traces photons [begin, end) of pass `pass` and appends the photons they store to `out`, in
/// order; adds their rays to `counters`.
void trace_photons(const Scene& scene, uint32_t pass, uint64_t begin, uint64_t end, uint32_t seed,
                   std::vector<Photon>& out, RenderCounters& counters);

/// The gather of pass `pass` over `rect`: `state` holds the rect's pixels (row-major) as the
/// previous pass left them (all zero radius: the first pass, which starts at map.max_radius()) and is
/// updated in place; `tile` (reset to rect) gets each pixel's film sample of the pass.
void sppm_gather(const Scene& scene, const PhotonMap& map, const TileRect& rect, uint32_t pass, uint32_t seed,
                 std::span<SppmPixel> state, FilmTile& tile);

}  // namespace tessera

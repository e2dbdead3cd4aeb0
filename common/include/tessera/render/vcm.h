// Vertex connection and merging (`vcm`: Georgiev et al. 2012, "Light Transport Simulation with
// Vertex Connection and Merging"; Hachisuka et al. 2012), built as Georgiev's SmallVCM builds it,
// on bdpt's subpaths (bdpt.h) and its recursive MIS quantities.
//
// A render is iterations k = 0, 1, ..., one sample per pixel each (sequence/photon_program.h runs
// them): first the light subpaths of the iteration's pixel samples (a Paths pass: exactly bdpt's
// light subpaths, splatted onto the film by light tracing as bdpt's are, and their non-delta
// vertices kept as records: the iteration's light vertex map); then the camera subpaths (a Tile
// pass) with every bdpt strategy plus vertex merging: at each non-delta camera vertex, the light
// vertices of every light subpath of the iteration within radius r_k are merged with it,
//   sum of f(wo, wi_light) beta_light w / (pi r_k^2 N_L)        (f without the cosine)
// where N_L is the iteration's light subpaths (its window pixels) and w the vertex's MIS weight
// against every connection and every other merge. The radius shrinks as SmallVCM's does:
//   r_k = r_0 / (k + 1)^((1 - alpha) / 2),
// r_0 the scene's initial radius, else SmallVCM's default, 0.003 scene-sphere radii. (sppm's larger
// automatic radius lets merges, whose MIS weight grows with eta_vcm, take over direct light and
// blur it: 10% too dark in the glass-caustic scene's blocks under a shadow edge.) Merges use
// eta_vcm = pi r_k^2 N_L to convert between the two kinds of strategy (bdpt_subpath.h).
//
// Merges happen only where connections cannot do their work well, by two rules:
// - not with light vertices where the light first meets a surface (unless merge_direct): that is
//   direct light, which next-event estimation renders with less noise; a merge's count of light
//   vertices within r_k is noisy, and its MIS weight, which grows with eta_vcm, ignores that;
// - only at vertices whose BSDF is at least merge_roughness rough (Bsdf::roughness; 0: at every
//   non-delta vertex): on a glossy surface a merge evaluates a narrow lobe with a direction from
//   up to r_k away, so it blurs and is noisy where connections are sharp.
// (With both off, merges are SmallVCM's.) Where a merge does not happen it is no strategy at all:
// its terms leave the weights of every other strategy of the paths through that vertex (Georgiev's
// recursion skips them there), so the weights still sum to one and the estimator stays
// consistent. Only vertices that merge are kept in the light vertex map.
//
// merge = false: no merging, the same program and estimator as bdpt, bit for bit (its MIS terms
// for merges are exactly zero). connect = false: progressive photon mapping as SmallVCM's "ppm"
// mode has it: emitters only along purely specular camera paths, the first non-delta camera vertex
// merges every light vertex (direct light too) with weight 1, however smooth (merge_roughness is
// not read), no connections, no light tracing; it converges to the image sppm converges to.
#pragma once

#include "tessera/render/bdpt.h"
#include "tessera/render/integrator.h"
#include "tessera/render/point_grid.h"
#include "tessera/render/scene.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace tessera {

/// A light vertex kept for merging: 40 bytes, the layout of a vertex map's bytes (little-endian).
struct LightVertexRecord {
  float p[3];
  float beta[3];     // the light subpath's weight arriving here (bdpt::Vertex::beta)
  uint32_t wo;       // octahedral 16:16, unit, world: towards the previous vertex of the subpath
  uint8_t n[2];      // octahedral 8:8: the geometric normal on the side it arrived from
  uint16_t length;   // segments from the light
  float d_vcm, d_vm;
};
static_assert(sizeof(LightVertexRecord) == 40, "light vertex records are 40 bytes");

using LightVertexMap = PointGrid<LightVertexRecord>;

/// What the camera subpaths of iteration k merge with.
struct VcmIteration {
  const LightVertexMap* map = nullptr;  // (camera subpaths) the iteration's light vertices
  float radius = 0.f;                   // r_k; 0: no merging (bdpt)
  double light_paths = 0;               // N_L
};

/// r_0 of `scene`: its initial radius, else 0.003 scene-sphere radii.
float vcm_initial_radius(const Scene& scene);
/// r_k = r_0 / (k+1)^((1-alpha)/2): what every machine computes for iteration k, bit for bit.
float vcm_radius(float initial_radius, float alpha, uint32_t iteration);
/// r_k for iteration k of `scene` (its initial radius and its alpha).
inline float vcm_radius(const Scene& scene, uint32_t iteration) {
  return vcm_radius(vcm_initial_radius(scene), scene.integrator.alpha, iteration);
}

/// Light paths [path_begin, path_end) of iteration `it` (numbered as trace_light_paths numbers
/// them): their light tracing into `splats` (reset by the caller) and their non-delta vertices,
/// in path order, appended to `records`.
void trace_vcm_light_paths(const Scene& scene, const VcmIteration& it, uint64_t path_begin, uint64_t path_end,
                           uint32_t seed, LightSplats& splats, std::vector<LightVertexRecord>& records);

/// The camera half of iteration `it` (it.map and the iteration must outlive the integrator).
std::unique_ptr<Integrator> make_vcm_integrator(const IntegratorSettings& settings, const VcmIteration& it);

}  // namespace tessera

// Internals of bdpt.h: subpath vertices, their MIS quantities and the light subpath.
//
// MIS (Georgiev 2012, power heuristic): every vertex carries
//   d_vcm  1 / (density with which the subpath's own direction sampled this vertex, area measure),
//          times the weight ratio of the strategy that would have ended the other subpath here;
//   d_vc   the sum of the ratios of the connections with more vertices on the other side;
//   d_vm   the same for the merges (vertex merging: vcm.h), zero without them.
// All are squared quantities already (mis()). A strategy's weight is 1 / (1 + the ratios of every
// other strategy), each ratio built from these at the two ends of the connection or merge.
// MisWeights carries vertex merging's two constants (Georgiev's eta_vcm = pi r^2 light paths):
// with merging off both are 0 and every quantity is bdpt's, bit for bit.
#pragma once

#include "tessera/render/bdpt.h"
#include "tessera/render/bsdf_adjoint.h"
#include "tessera/render/interaction.h"
#include "tessera/render/vcm.h"

#include <vector>

namespace tessera::bdpt {

/// The power heuristic's exponent (2), applied to a density ratio.
inline float mis(float x) { return x * x; }

/// The weight of strategy (s, t) (s light vertices, t camera vertices): its MIS weight, or with
/// IntegratorSettings::only_s set, 0 for every other strategy and for that one 1 (or its MIS
/// weight, only_weighted).
inline float strategy_weight(const IntegratorSettings& settings, int s, int t, float mis_weight) {
  if (settings.only_s < 0) return mis_weight;
  if (s != settings.only_s || t != settings.only_t) return 0.f;
  return settings.only_weighted ? mis_weight : 1.f;
}

/// Vertex merging's MIS constants for one iteration: vm = mis(eta_vcm) when merging (0: off),
/// vc = mis(1 / eta_vcm) when connecting; merges only at vertices whose BSDF is at least
/// min_roughness rough (Bsdf::roughness; 0: at every non-delta vertex).
/// merge_direct: merges also with light vertices where the light first meets a surface.
struct MisWeights {
  float vm = 0.f, vc = 0.f;
  float min_roughness = 0.f;
  bool merge_direct = true;
};

/// The constants of iteration `it` of a vcm render that merges (none for bdpt: radius 0). Without
/// connections (photon mapping) the first non-delta camera vertex merges, however smooth.
inline MisWeights vcm_weights(const IntegratorSettings& s, const VcmIteration& it) {
  if (!(it.radius > 0.f)) return {};
  const float eta = float(3.14159265358979323846 * double(it.radius) * double(it.radius) * it.light_paths);
  return {s.merge ? mis(eta) : 0.f, s.connect ? mis(1.f / eta) : 0.f, s.connect ? s.merge_roughness : 0.f,
          s.merge_direct || !s.connect};
}

/// 1 when the iteration merges at a non-delta vertex of this BSDF, else 0. Where it does not, a
/// merge there is no strategy, and its terms leave every other strategy's weight (the vm and 1
/// of Georgiev's updates at that vertex), so the weights of a path's strategies still sum to 1.
inline float merges_at(const MisWeights& mw, const Bsdf& bsdf, const SurfaceInteraction& si) {
  if (!(mw.vm > 0.f)) return 0.f;
  return mw.min_roughness <= 0.f || bsdf.roughness(si) >= mw.min_roughness ? 1.f : 0.f;
}

/// A merge (or a photon's gather) counts only where the surfaces face within about 60 degrees.
inline constexpr float kMinMergeNormalCos = 0.5f;
/// The unit normal of a record's 8:8 octahedral bytes.
Vec3 record_normal(const uint8_t n[2]);
/// Those bytes for `ng` turned to the side `w` arrives from.
void encode_record_normal(Vec3 ng, Vec3 w, uint8_t out[2]);

struct Vertex {
  SurfaceInteraction si;
  const Bsdf* bsdf = nullptr;
  Vec3 wo;         // local: towards the previous vertex of its subpath
  Vec3 wo_world;
  Rgb beta;        // light: emitted power along the subpath; camera: throughput
  int length = 0;  // segments from the subpath's origin
  float d_vcm = 0.f, d_vc = 0.f, d_vm = 0.f;
  float vm = 0.f;  // MisWeights::vm where the iteration merges at this vertex (merges_at), else 0
  Vec2 u_lens;     // light vertices: the lens sample of its camera connection
};

/// Where light subpaths start, as sample_le() gave it.
struct LightOrigin {
  const Light* light = nullptr;
  LightEmission emission;
  float emission_pdf = 0.f;  // pick pmf * pdf_pos * pdf_dir
  bool delta = false;        // delta position or direction
};

/// A light subpath's non-delta surface vertices, in order (lengths increasing).
struct LightSubpath {
  LightOrigin origin;
  std::vector<Vertex> vertices;
};

/// Traces the light subpath of the sampler's pixel sample from Sampler::kLightDimension, up to
/// the length a path of at most settings.max_depth segments can use; the sampler's dimension is
/// restored afterwards. `weights`: vertex merging's (none: bdpt).
void trace_light_subpath(const Scene& scene, const IntegratorSettings& settings, Sampler& sampler, float time,
                         LightSubpath& out, RenderCounters& counters, const MisWeights& weights = {});

/// Next-event estimation's density at the surface point `si` of picking the subpath's origin: per
/// unit area at the origin for finite lights, per unit solid angle for distant ones, the light's
/// selection pmf alone for a delta position or direction.
float direct_pdf(const Scene& scene, const SurfaceInteraction& si, const LightOrigin& origin);

/// Next-event estimation's light sample at a surface point: the light picked as `path` picks it,
/// its sample, and the sample's direction in the shading frame.
struct DirectSample {
  const Light* light = nullptr;
  float pmf = 0.f;
  LightSample ls;
  Vec3 wi;  // local
  /// The light's radiance along the sample (deferred_li when the light deferred it).
  Rgb li() const { return ls.li_deferred ? light->deferred_li(ls) : ls.li; }
};
/// False when there is no sample, or its direction lies on different sides of the geometric and
/// the shading surface.
bool sample_direct(const Scene& scene, const SurfaceInteraction& si, float u_pick, Vec2 u_light, DirectSample& out);
/// The transmittance of the shadow ray from `si` to the sample's point, at `time`.
float direct_transmittance(const Scene& scene, const SurfaceInteraction& si, const LightSample& ls, float time,
                           RenderCounters& counters);

/// Light::pdf_le as light subpaths start: for a distant light, pdf_pos is the scene's emission
/// portal's density of the line through `on_line` along `dir` (the direction of travel) when the
/// scene has a portal, else its own disk's.
inline void emission_pdfs(const Scene& scene, const Light& light, Vec3 p, Vec3 n, Vec3 dir, Vec3 on_line,
                          float& pdf_pos, float& pdf_dir) {
  light.pdf_le(p, n, dir, pdf_pos, pdf_dir);
  if (const EmissionPortal& portal = scene.emission_portal(); light.is_distant() && portal.active())
    pdf_pos = portal.pdf(on_line, dir);
}

}  // namespace tessera::bdpt

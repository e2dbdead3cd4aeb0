// Light subpaths and the adjoint BSDF (bdpt_subpath.h).
#include "render/bdpt_subpath.h"

#include "render/octahedral.h"

#include <algorithm>
#include <cmath>

namespace tessera::bdpt {
namespace {

// A subpath longer than this is cut, whatever the depth limit: Russian roulette ends paths long
// before, but a vertex list must have a bound.
constexpr size_t kMaxVertices = 1024;

// The first ray of a subpath leaving the light: off the surface of an area light, as is otherwise.
Ray emission_ray(const LightEmission& e, float time) {
  Ray ray = (!e.infinite && !e.delta_pos) ? spawn_ray(e.p, e.p_error, e.n, e.dir) : Ray{e.p, e.dir};
  ray.time = time;
  return ray;
}

bool start_light_subpath(const Scene& scene, Sampler& sampler, LightOrigin& o, Rgb& beta) {
  const float u_pick = sampler.next_1d();
  const Vec2 u_pos = sampler.next_2d(), u_dir = sampler.next_2d();
  float pmf = 0.f;
  o.light = scene.light_sampler().sample_emitter(u_pick, pmf);
  if (!o.light || !(pmf > 0.f) || !o.light->sample_le(u_pos, u_dir, o.emission)) return false;
  LightEmission& e = o.emission;
  // A distant light's ray starts where the scene's emission portal puts it (emission_portal.h).
  if (const EmissionPortal& portal = scene.emission_portal(); e.infinite && portal.active())
    if (!portal.sample(e.dir, u_pos, e.p, e.pdf_pos)) return false;
  o.emission_pdf = pmf * e.pdf_pos * e.pdf_dir;
  o.delta = e.delta_pos || e.delta_dir;
  const float cos_light = (e.infinite || e.delta_pos) ? 1.f : std::abs(dot(e.n, e.dir));
  if (!(o.emission_pdf > 0.f) || !std::isfinite(o.emission_pdf)) return false;
  beta = e.le * (cos_light / o.emission_pdf);
  return !beta.is_black() && beta.is_finite();
}

// Russian roulette on a light subpath: survival in proportion to how much of the emitted power
// it still carries (capped at 0.95), from rr_depth on.
bool survives(const IntegratorSettings& s, int length, Rgb& beta, float beta0, float u_rr) {
  if (length >= s.rr_depth) {
    const float q = std::min(beta.max_value() / beta0, 0.95f);
    if (!(u_rr < q)) return false;
    beta *= 1.f / q;
  }
  return !beta.is_black();
}

// Georgiev's update at a new vertex: the subpath's MIS quantities into the area measure there.
// The first vertex after the light also learns next-event estimation's density for the origin
// from this point (it depends on the point under a light hierarchy).
// Without next-event estimation (sampleDirect off) that strategy's ratio is zero.
void arrive(const Scene& scene, const IntegratorSettings& s, const LightOrigin& o, const SurfaceInteraction& si,
            float dist, int length, float& d_vcm, float& d_vc, float& d_vm) {
  const float cos_in = std::abs(dot(si.ng, si.wo));
  if (length == 1) d_vcm = s.sample_direct ? mis(direct_pdf(scene, si, o) / o.emission_pdf) : 0.f;
  if (length > 1 || !o.emission.infinite) d_vcm *= mis(dist * dist);
  const float inv = cos_in > 0.f ? 1.f / mis(cos_in) : 0.f;
  d_vcm *= inv;
  d_vc *= inv;
  d_vm *= inv;
}

}  // namespace

Vec3 record_normal(const uint8_t n[2]) { return octahedral::decode((uint32_t(n[0]) << 8) | n[1], 8); }

void encode_record_normal(Vec3 ng, Vec3 w, uint8_t out[2]) {
  const uint32_t n8 = octahedral::encode(dot(ng, w) >= 0.f ? ng : -ng, 8);
  out[0] = uint8_t(n8 >> 8);
  out[1] = uint8_t(n8 & 0xFF);
}

bool sample_direct(const Scene& scene, const SurfaceInteraction& si, float u_pick, Vec2 u_light, DirectSample& out) {
  out.light = scene.sample_light({si.p, si.shading.n}, u_pick, out.pmf);
  out.ls = LightSample{};
  out.ls.defer_li = true;
  if (!out.light || !(out.pmf > 0.f) || !out.light->sample_li(si.p, u_light, out.ls) || !(out.ls.pdf > 0.f)) return false;
  out.wi = si.to_local(out.ls.wi);
  return consistent_side(si, out.ls.wi, out.wi);
}

float direct_transmittance(const Scene& scene, const SurfaceInteraction& si, const LightSample& ls, float time,
                           RenderCounters& counters) {
  Ray shadow = ls.dist < kInfinity ? spawn_ray_to(si, ls.p_light, ls.p_light_error, ls.n_light) : spawn_ray(si, ls.wi);
  shadow.time = time;
  ++counters.shadow_rays;
  return scene.transmittance(shadow);
}

float direct_pdf(const Scene& scene, const SurfaceInteraction& si, const LightOrigin& o) {
  const LightEmission& e = o.emission;
  const float pmf = scene.light_pmf({si.p, si.shading.n}, o.light);
  if (!(pmf > 0.f)) return 0.f;
  if (e.delta_pos || e.delta_dir) return pmf;
  if (e.infinite) return pmf * o.light->pdf_env(-e.dir);
  SurfaceInteraction on_light;
  on_light.p = e.p;
  on_light.ng = e.n;
  const Vec3 d = e.p - si.p;
  const float dist2 = length_squared(d);
  if (!(dist2 > 0.f)) return 0.f;
  const float cos_light = std::abs(dot(e.n, d)) / std::sqrt(dist2);
  const float pdf = pmf * o.light->pdf_li(si.p, on_light) * cos_light / dist2;
  return std::isfinite(pdf) ? pdf : 0.f;
}

void trace_light_subpath(const Scene& scene, const IntegratorSettings& s, Sampler& sampler, float time,
                         LightSubpath& out, RenderCounters& counters, const MisWeights& mw) {
  out.vertices.clear();
  const uint32_t saved = sampler.dimension();
  sampler.set_dimension(Sampler::kLightDimension);
  Rgb beta;
  if (!start_light_subpath(scene, sampler, out.origin, beta)) {
    sampler.set_dimension(saved);
    return;
  }
  const LightOrigin& o = out.origin;
  const float beta0 = beta.max_value();
  const float cos_light = (o.emission.infinite || o.emission.delta_pos) ? 1.f : std::abs(dot(o.emission.n, o.emission.dir));
  float d_vcm = 0.f, d_vc = o.delta ? 0.f : mis(cos_light / o.emission_pdf), d_vm = d_vc * mw.vc;
  Ray ray = emission_ray(o.emission, time);
  ++counters.bounce_rays;
  Vertex v;
  for (int len = 1; out.vertices.size() < kMaxVertices; ++len) {
    if (!scene.intersect(ray, v.si)) break;
    const Vec3 w_prev = -ray.d;
    if (!reconcile_shading_frame(v.si, w_prev, s.strict_normals)) break;
    arrive(scene, s, o, v.si, v.si.t * length(ray.d), len, d_vcm, d_vc, d_vm);
    const Bsdf* bsdf = v.si.bsdf();
    if (!bsdf) break;
    v.bsdf = bsdf;
    v.wo_world = normalize(w_prev);
    v.wo = v.si.to_local(v.wo_world);
    v.beta = beta;
    v.length = len;
    v.d_vcm = d_vcm;
    v.d_vc = d_vc;
    v.d_vm = d_vm;
    const bool direct = len == 1;  // (a merge here would be direct light: merge_direct)
    const float merges = bsdf->is_delta() || (direct && !mw.merge_direct) ? 0.f : merges_at(mw, *bsdf, v.si);
    v.vm = mw.vm * merges;
    v.u_lens = sampler.next_2d();
    const float u_lobe = sampler.next_1d();
    const Vec2 u_dir = sampler.next_2d();
    const float u_rr = sampler.next_1d();
    if (!bsdf->is_delta()) out.vertices.push_back(v);
    // The next vertex and one segment to the camera must fit in the depth.
    if (s.max_depth >= 0 && len + 2 > s.max_depth) break;
    BsdfSample bs;
    if (!bsdf->sample(v.si, v.wo, u_lobe, u_dir, bs)) break;
    const Vec3 wi = v.si.to_world(bs.wi);
    if (!consistent_side(v.si, wi, bs.wi)) break;
    const float cos_out = std::abs(dot(v.si.ng, wi));
    if (bs.delta) {
      beta *= adjoint_weight(v.si, bs, v.wo_world, wi);
      d_vc *= mis(cos_out);
      d_vm *= mis(cos_out);
      d_vcm = 0.f;
    } else {
      beta *= adjoint_eval(v.si, *bsdf, v.wo_world, wi) * (1.f / bs.pdf);
      const float pdf_rev = bsdf->pdf(v.si, bs.wi, v.wo);
      // (Georgiev's updates; without merging, v.vm is 0 and d_vc is bdpt's to the bit.)
      d_vc = mis(cos_out / bs.pdf) * (d_vc * mis(pdf_rev) + d_vcm + v.vm);
      d_vm = mis(cos_out / bs.pdf) * (d_vm * mis(pdf_rev) + d_vcm * mw.vc + merges);
      d_vcm = mis(1.f / bs.pdf);
    }
    if (!survives(s, len, beta, beta0, u_rr)) break;
    ray = spawn_ray(v.si, wi);
    ray.time = time;
    ++counters.bounce_rays;
  }
  sampler.set_dimension(saved);
}

}  // namespace tessera::bdpt

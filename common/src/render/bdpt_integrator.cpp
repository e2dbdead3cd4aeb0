// The camera's half of bidirectional path tracing (bdpt.h): every strategy with t >= 2 for one
// pixel sample, and the light tracer's directly visible emitters.
#include "render/bdpt_subpath.h"
#include "render/bounce_samples.h"
#include "render/octahedral.h"
#include "tessera/render/vcm.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

using bdpt::mis;

// The camera subpath's state: throughput, Georgiev's quantities and the previous vertex (for
// next-event estimation's density at an emitter the subpath hits).
struct CameraPath {
  Rgb beta{1.f};
  float eta = 1.f;
  int length = 1;  // segments up to the vertex being visited
  float d_vcm = 0.f, d_vc = 0.f, d_vm = 0.f;
  // d_vc without the previous vertex's merge: for s = 0, where that merge would be of direct light
  // (MisWeights::merge_direct off); d_vc itself otherwise, and with merging off.
  float d_vc_direct = 0.f;
  LightSampleContext prev_ctx;
  float time = 0.f;
  bool specular = true;  // every vertex so far was delta (vcm's photon mapping mode)
};

// What a camera vertex needs besides its interaction.
struct CameraVertex {
  const SurfaceInteraction* si;
  const Bsdf* bsdf;
  Vec3 wo;          // local
  float merges;     // bdpt::merges_at
  float vm;         // MisWeights::vm times merges
};

// bdpt, and vcm's camera half (vcm.h) when an iteration to merge with is given.
class BdptIntegrator final : public Integrator {
 public:
  explicit BdptIntegrator(const IntegratorSettings& s, const VcmIteration& it = {})
      : s_(s), light_image_(traces_light_paths(s)), it_(it), mw_(bdpt::vcm_weights(s, it)),
        connect_(!(it.radius > 0.f) || s.connect), merge_(it.map && it.radius > 0.f && s.merge) {}

  Rgb li(const Scene& scene, const Ray& camera_ray, Sampler& sampler, RenderCounters& counters, const PathGuide*,
         SampleFeatures*) const override {
    if (s_.max_depth == 0) return {};
    thread_local bdpt::LightSubpath light;
    light.vertices.clear();
    if (connect_) bdpt::trace_light_subpath(scene, s_, sampler, camera_ray.time, light, counters, mw_);
    CameraPath c;
    c.time = camera_ray.time;
    float pdf_pos = 0.f, pdf_dir = 0.f;
    scene.camera->pdf_we(camera_ray, pdf_pos, pdf_dir);
    c.d_vcm = light_image_ && pdf_dir > 0.f ? mis(1.f / pdf_dir) : 0.f;
    Ray ray = camera_ray;
    Rgb L;
    SurfaceInteraction si;
    for (;;) {
      if (!scene.intersect(ray, si)) {
        if (connect_ || c.specular) L += c.beta * environment(scene, c, normalize(ray.d));
        break;
      }
      const float dist = si.t * length(ray.d);
      const Vec3 wo_world = normalize(-ray.d);
      const float cos_in = std::abs(dot(si.ng, wo_world));
      const float inv = cos_in > 0.f ? 1.f / mis(cos_in) : 0.f;
      c.d_vcm *= mis(dist * dist) * inv;
      c.d_vc *= inv;
      c.d_vc_direct *= inv;
      c.d_vm *= inv;
      if (const Light* area = si.area_light(); area && (connect_ || c.specular))
        L += c.beta * emission(scene, c, si, *area, wo_world, dist);
      if (s_.max_depth >= 0 && c.length >= s_.max_depth) break;
      if (!reconcile_shading_frame(si, wo_world, s_.strict_normals)) break;
      const Bsdf* bsdf = si.bsdf();
      if (!bsdf) break;
      const float merges = bsdf->is_delta() ? 0.f : bdpt::merges_at(mw_, *bsdf, si);
      const CameraVertex v{&si, bsdf, si.to_local(wo_world), merges, mw_.vm * merges};
      const BounceSamples u = BounceSamples::draw(sampler);
      if (!bsdf->is_delta()) {
        if (connect_ && s_.sample_direct && (s_.max_depth < 0 || c.length + 1 <= s_.max_depth))
          L += c.beta * direct(scene, c, v, u, counters);
        L += c.beta * connect(scene, c, v, light, counters);
        if (merge_ && merges > 0.f) L += c.beta * merge(c, v);
        if (!connect_) break;  // (photon mapping: the first non-delta vertex merges everything)
      }
      if (!scatter(c, v, u, ray)) break;
      ++counters.bounce_rays;
    }
    return L;
  }

 private:
  // s = 0 at an area light: weighted against next-event estimation from the previous vertex and
  // against light subpaths that start here.
  Rgb emission(const Scene& scene, const CameraPath& c, const SurfaceInteraction& si, const Light& area,
               Vec3 wo_world, float dist) const {
    const Rgb le = area.le(si, wo_world);
    if (le.is_black()) return {};
    if (c.length == 1) return s_.hide_emitters ? Rgb() : le * bdpt::strategy_weight(s_, 0, 2, 1.f);
    float direct_a = 0.f;
    if (s_.sample_direct) {
      const float cos_light = std::abs(dot(si.ng, wo_world));
      direct_a = scene.light_pmf(c.prev_ctx, &area) * area.pdf_li(c.prev_ctx.p, si) * cos_light / (dist * dist);
    }
    float pdf_pos = 0.f, pdf_dir = 0.f;
    bdpt::emission_pdfs(scene, area, si.p, si.ng, wo_world, si.p, pdf_pos, pdf_dir);
    const float emission_pdf = scene.light_sampler().emitter_pmf(&area) * pdf_pos * pdf_dir;
    const float w = mis(direct_a) * c.d_vcm + mis(emission_pdf) * c.d_vc_direct;
    return le * bdpt::strategy_weight(s_, 0, c.length + 1, 1.f / (1.f + w));
  }

  // s = 0 for a ray that leaves the scene.
  Rgb environment(const Scene& scene, const CameraPath& c, Vec3 d) const {
    Rgb sum;
    for (const Light* env : scene.infinite_lights()) {
      const Rgb le = env->le_env(d);
      if (le.is_black()) continue;
      if (c.length == 1) {
        if (!s_.hide_emitters) sum += le * bdpt::strategy_weight(s_, 0, 2, 1.f);
        continue;
      }
      const float direct_w = s_.sample_direct ? scene.light_pmf(c.prev_ctx, env) * env->pdf_env(d) : 0.f;
      float pdf_pos = 0.f, pdf_dir = 0.f;
      bdpt::emission_pdfs(scene, *env, Vec3(0.f), Vec3(0.f), -d, c.prev_ctx.p, pdf_pos, pdf_dir);
      const float emission_pdf = scene.light_sampler().emitter_pmf(env) * pdf_pos * pdf_dir;
      sum += le * bdpt::strategy_weight(s_, 0, c.length + 1, 1.f / (1.f + mis(direct_w) * c.d_vcm + mis(emission_pdf) * c.d_vc_direct));
    }
    return sum;
  }

  // s = 1: next-event estimation, weighted against the BSDF hitting the light (s = 0) and against
  // light subpaths through this vertex (s >= 2).
  Rgb direct(const Scene& scene, const CameraPath& c, const CameraVertex& v, const BounceSamples& u,
             RenderCounters& counters) const {
    const SurfaceInteraction& si = *v.si;
    bdpt::DirectSample d;
    if (!bdpt::sample_direct(scene, si, u.u_pick, u.u_light, d)) return {};
    const Light* light = d.light;
    const LightSample& ls = d.ls;
    const float pmf = d.pmf;
    const Vec3 wi = d.wi;
    const Rgb f = v.bsdf->eval(si, v.wo, wi);
    if (f.is_black()) return {};
    const bool delta_pos = ls.delta && ls.dist < kInfinity;
    const float direct_w = delta_pos ? ls.dist * ls.dist : ls.pdf;
    const bool on_surface = length_squared(ls.n_light) > 0.f;
    const float cos_at_light = on_surface ? std::abs(dot(ls.n_light, ls.wi)) : 1.f;
    float pdf_pos = 0.f, pdf_dir = 0.f;
    bdpt::emission_pdfs(scene, *light, ls.p_light, ls.n_light, -ls.wi, si.p, pdf_pos, pdf_dir);
    const float emission_w = scene.light_sampler().emitter_pmf(light) * pdf_pos * pdf_dir;
    const float pdf_fwd = ls.delta ? 0.f : v.bsdf->pdf(si, v.wo, wi);
    const float pdf_rev = v.bsdf->pdf(si, wi, v.wo);
    const float cos_to_light = std::abs(dot(si.ng, ls.wi));
    const float w_light = mis(pdf_fwd / (pmf * direct_w));
    const float w_camera = cos_at_light > 0.f ? mis(emission_w * cos_to_light / (pmf * direct_w * cos_at_light)) *
                                                   (c.d_vcm + c.d_vc * mis(pdf_rev) + (mw_.merge_direct ? v.vm : 0.f))
                                             : 0.f;
    const float tr = bdpt::direct_transmittance(scene, si, ls, c.time, counters);
    if (!(tr > 0.f)) return {};
    const Rgb li = d.li();
    return f * li * (tr * bdpt::strategy_weight(s_, 1, c.length + 1, 1.f / (w_light + 1.f + w_camera)) / (pmf * ls.pdf));
  }

  // s >= 2: this vertex connected to each light vertex the depth allows.
  Rgb connect(const Scene& scene, const CameraPath& c, const CameraVertex& v, const bdpt::LightSubpath& light,
              RenderCounters& counters) const {
    const SurfaceInteraction& si = *v.si;
    Rgb sum;
    for (const bdpt::Vertex& lv : light.vertices) {
      if (s_.max_depth >= 0 && lv.length + 1 + c.length > s_.max_depth) break;
      const Vec3 d = lv.si.p - si.p;
      const float dist2 = length_squared(d);
      if (!(dist2 > 0.f)) continue;
      const Vec3 dir = d / std::sqrt(dist2);
      const Vec3 wi = si.to_local(dir);
      if (!consistent_side(si, dir, wi)) continue;
      const Rgb f_camera = v.bsdf->eval(si, v.wo, wi);
      if (f_camera.is_black()) continue;
      const Rgb f_light = adjoint_eval(lv.si, *lv.bsdf, lv.wo_world, -dir);
      if (f_light.is_black()) continue;
      const Vec3 wl = lv.si.to_local(-dir);
      const float pdf_c_fwd = v.bsdf->pdf(si, v.wo, wi), pdf_c_rev = v.bsdf->pdf(si, wi, v.wo);
      const float pdf_l_fwd = lv.bsdf->pdf(lv.si, lv.wo, wl), pdf_l_rev = lv.bsdf->pdf(lv.si, wl, lv.wo);
      const float cos_c = std::abs(dot(si.ng, dir)), cos_l = std::abs(dot(lv.si.ng, dir));
      const float w_light = mis(pdf_c_fwd * cos_l / dist2) * (lv.d_vcm + lv.d_vc * mis(pdf_l_rev) + lv.vm);
      const float w_camera = mis(pdf_l_fwd * cos_c / dist2) * (c.d_vcm + c.d_vc * mis(pdf_c_rev) + v.vm);
      Ray shadow = spawn_ray_to(si, lv.si.p, lv.si.p_error, lv.si.ng);
      shadow.time = c.time;
      ++counters.shadow_rays;
      const float tr = scene.transmittance(shadow);
      if (!(tr > 0.f)) continue;
      const float w = bdpt::strategy_weight(s_, lv.length + 1, c.length + 1, 1.f / (w_light + 1.f + w_camera));
      sum += f_camera * f_light * lv.beta * (tr * w / dist2);
    }
    return sum;
  }

  // The BSDF-sampled next segment, with Georgiev's update and Russian roulette as `path` does it.
  bool scatter(CameraPath& c, const CameraVertex& v, const BounceSamples& u, Ray& ray) const {
    const SurfaceInteraction& si = *v.si;
    BsdfSample bs;
    if (!v.bsdf->sample(si, v.wo, u.u_lobe, u.u_dir, bs)) return false;
    const Vec3 wi = si.to_world(bs.wi);
    if (!consistent_side(si, wi, bs.wi)) return false;
    const float cos_out = std::abs(dot(si.ng, wi));
    if (bs.delta) {
      c.d_vc *= mis(cos_out);
      c.d_vc_direct = c.d_vc;
      c.d_vm *= mis(cos_out);
      c.d_vcm = 0.f;
    } else {
      const float pdf_rev = v.bsdf->pdf(si, bs.wi, v.wo);
      const float d_vc = c.d_vc * mis(pdf_rev) + c.d_vcm;
      c.d_vc = mis(cos_out / bs.pdf) * (d_vc + v.vm);
      c.d_vc_direct = mw_.merge_direct ? c.d_vc : mis(cos_out / bs.pdf) * d_vc;
      c.d_vm = mis(cos_out / bs.pdf) * (c.d_vm * mis(pdf_rev) + c.d_vcm * mw_.vc + v.merges);
      c.d_vcm = mis(1.f / bs.pdf);
      c.specular = false;
    }
    c.beta *= bs.weight;
    c.eta *= bs.eta;
    c.prev_ctx = {si.p, si.shading.n};
    const int depth = c.length;  // scattering events so far
    ++c.length;
    if (depth >= s_.rr_depth) {
      const float q = std::min(c.beta.max_value() * c.eta * c.eta, 0.95f);
      if (!(u.u_rr < q)) return false;
      c.beta *= 1.f / q;
    }
    if (c.beta.is_black()) return false;
    ray = spawn_ray(si, wi);
    ray.time = c.time;
    return true;
  }

  // Vertex merging (vcm.h) at a non-delta camera vertex: the iteration's light vertices within
  // its radius, each weighted against every connection and every other merge (or, photon
  // mapping, with weight 1).
  Rgb merge(const CameraPath& c, const CameraVertex& v) const {
    const SurfaceInteraction& si = *v.si;
    const Vec3 wo_world = si.to_world(v.wo);
    const Vec3 n_side = dot(si.ng, wo_world) >= 0.f ? si.ng : -si.ng;
    Rgb sum;
    it_.map->for_each_near(si.p, it_.radius, [&](const LightVertexRecord& lv) {
      if (s_.max_depth >= 0 && int(lv.length) + c.length > s_.max_depth) return;
      if (dot(bdpt::record_normal(lv.n), n_side) < bdpt::kMinMergeNormalCos) return;
      const Vec3 wi_world = octahedral::decode(lv.wo, 16);
      const Vec3 wi = si.to_local(wi_world);
      if (!consistent_side(si, wi_world, wi) || !(std::abs(wi.z) > 1e-6f)) return;
      const Rgb f = v.bsdf->eval(si, v.wo, wi);
      if (f.is_black()) return;
      float w = 1.f;
      if (connect_) {
        const float w_light = lv.d_vcm * mw_.vc + lv.d_vm * mis(v.bsdf->pdf(si, v.wo, wi));
        const float w_camera = c.d_vcm * mw_.vc + c.d_vm * mis(v.bsdf->pdf(si, wi, v.wo));
        w = 1.f / (w_light + 1.f + w_camera);
      }
      sum += f * Rgb(lv.beta[0], lv.beta[1], lv.beta[2]) * (w / std::abs(wi.z));  // (eval has the cosine)
    });
    return sum * float(1.0 / (M_PI * double(it_.radius) * double(it_.radius) * it_.light_paths));
  }

  IntegratorSettings s_;
  bool light_image_;
  VcmIteration it_;
  bdpt::MisWeights mw_;
  bool connect_, merge_;
};

// ptracer's camera side: what the camera sees directly (s = 0 at the first hit); the light
// tracing units do the rest.
class DirectlyVisibleEmitters final : public Integrator {
 public:
  explicit DirectlyVisibleEmitters(const IntegratorSettings& s) : s_(s) {}
  Rgb li(const Scene& scene, const Ray& ray, Sampler&, RenderCounters&, const PathGuide*,
         SampleFeatures*) const override {
    if (s_.max_depth == 0 || s_.hide_emitters) return {};
    SurfaceInteraction si;
    if (scene.intersect(ray, si)) {
      const Light* area = si.area_light();
      return area ? area->le(si, normalize(-ray.d)) : Rgb();
    }
    Rgb sum;
    for (const Light* env : scene.infinite_lights()) sum += env->le_env(normalize(ray.d));
    return sum;
  }

 private:
  IntegratorSettings s_;
};

}  // namespace

bool traces_light_paths(const IntegratorSettings& s) {
  return s.type == IntegratorType::Ptracer || (s.type == IntegratorType::Bdpt && s.light_image) ||
         (s.type == IntegratorType::Vcm && s.light_image && s.connect);
}

std::vector<std::pair<int, int>> bdpt_strategies(int max_length) {
  std::vector<std::pair<int, int>> out;
  for (int length = 1; length <= max_length; ++length)
    for (int s = 0; s <= length; ++s)
      if (const int t = length + 1 - s; t >= 2 || s >= 2) out.emplace_back(s, t);  // ((0, 1), (1, 1): none)
  return out;
}

std::unique_ptr<Integrator> make_bdpt_integrator(const IntegratorSettings& settings) {
  return std::make_unique<BdptIntegrator>(settings);
}

float vcm_initial_radius(const Scene& scene) {
  if (scene.integrator.initial_radius > 0.f) return scene.integrator.initial_radius;
  const Bounds3 b = scene.bounds();
  return 0.003f * (b.empty() ? 1.f : std::max(0.5f * length(b.diagonal()), 1e-4f));  // (SmallVCM's)
}

float vcm_radius(float initial_radius, float alpha, uint32_t iteration) {
  return initial_radius / std::pow(float(iteration) + 1.f, 0.5f * (1.f - alpha));
}

std::unique_ptr<Integrator> make_vcm_integrator(const IntegratorSettings& settings, const VcmIteration& it) {
  return std::make_unique<BdptIntegrator>(settings, it);
}

std::unique_ptr<Integrator> make_ptracer_integrator(const IntegratorSettings& settings) {
  return std::make_unique<DirectlyVisibleEmitters>(settings);
}

}  // namespace tessera

// Unidirectional path tracer (see integrator.h): next-event estimation and BSDF sampling at each
// vertex, combined with the power heuristic; emitters hit by BSDF-sampled rays are weighted against
// the light-sampling density at the previous vertex (pdf_li or pdf_env times the selection pmf).
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/render/integrator.h"

#include <algorithm>

namespace tessera {
namespace {

class PathIntegrator final : public Integrator {
 public:
  explicit PathIntegrator(const IntegratorSettings& s) : s_(s) {}

  Rgb li(const Scene& scene, const Ray& camera_ray, Sampler& sampler,
         RenderCounters& counters) const override {
    if (s_.max_depth == 0) return {};
    Rgb L, throughput(1.f);
    float eta = 1.f;  // product of the relative IORs crossed by refraction (BsdfSample::eta)
    Ray ray = camera_ray;
    int depth = 0;  // scattering events so far
    float prev_bsdf_pdf = 0.f;
    bool prev_delta = true;  // the camera "vertex" has no BSDF to combine with
    LightSampleContext prev_ctx;  // the previous vertex, for the light-selection pmf in MIS
    SurfaceInteraction si;

    for (;;) {
      const bool visible_emitters = depth > 0 || !s_.hide_emitters;
      if (!scene.intersect(ray, si)) {
        if (visible_emitters) {
          for (const Light* env : scene.infinite_lights()) {
            Rgb le = env->le_env(ray.d);
            if (le.is_black()) continue;
            float w = prev_delta ? 1.f
                                 : power_heuristic(prev_bsdf_pdf, env->pdf_env(ray.d) * scene.light_pmf(prev_ctx, env));
            L += throughput * le * w;
          }
        }
        break;
      }

      const Vec3 wo_world = -ray.d;
      if (const Light* area = si.area_light(); area && visible_emitters) {
        Rgb le = area->le(si, wo_world);
        if (!le.is_black()) {
          float w = prev_delta ? 1.f
                               : power_heuristic(prev_bsdf_pdf, area->pdf_li(prev_ctx.p, si) * scene.light_pmf(prev_ctx, area));
          L += throughput * le * w;
        }
      }

      if (s_.max_depth >= 0 && depth + 1 >= s_.max_depth) break;
      if (!reconcile_shading_frame(si, wo_world, s_.strict_normals)) break;
      const Vec3 wo = si.to_local(wo_world);
      const Bsdf* bsdf = si.bsdf();
      if (!bsdf) break;

      // Fixed dimension layout per bounce (see sampler.h), drawn whether used or not.
      const float u_pick = sampler.next_1d();
      const Vec2 u_light = sampler.next_2d();
      const float u_lobe = sampler.next_1d();
      const Vec2 u_bsdf = sampler.next_2d();
      const float u_rr = sampler.next_1d();

      if (!bsdf->is_delta()) L += throughput * sample_direct(scene, si, *bsdf, wo, u_pick, u_light, counters);

      BsdfSample bs;
      if (!bsdf->sample(si, wo, u_lobe, u_bsdf, bs)) break;
      const Vec3 wi_world = si.to_world(bs.wi);
      if (!consistent_side(si, wi_world, bs.wi)) break;
      throughput *= bs.weight;
      prev_bsdf_pdf = bs.pdf;
      prev_delta = bs.delta;
      eta *= bs.eta;
      prev_ctx = {si.p, si.shading.n};
      ++depth;

      // Russian roulette as Mitsuba 3: survival probability from the throughput, times eta^2 so that
      // refraction's radiance scaling does not kill paths inside glass early; capped at 0.95.
      if (depth >= s_.rr_depth) {
        float q = std::min(throughput.max_value() * eta * eta, 0.95f);
        if (!(u_rr < q)) break;
        throughput *= 1.f / q;
      }
      if (throughput.is_black()) break;
      ray = spawn_ray(si.p, si.ng, wi_world);
      ++counters.bounce_rays;
    }
    return L;
  }

 private:
  // One light sample, MIS-weighted against the BSDF; not yet multiplied by the throughput.
  Rgb sample_direct(const Scene& scene, const SurfaceInteraction& si, const Bsdf& bsdf, Vec3 wo,
                    float u_pick, Vec2 u_light, RenderCounters& counters) const {
    float pmf = 0.f;
    const Light* light = scene.sample_light({si.p, si.shading.n}, u_pick, pmf);
    LightSample ls;
    if (!light || !(pmf > 0.f) || !light->sample_li(si.p, u_light, ls)) return {};
    if (!(ls.pdf > 0.f) || ls.li.is_black()) return {};
    const Vec3 wi = si.to_local(ls.wi);
    if (!consistent_side(si, ls.wi, wi)) return {};
    Rgb f = bsdf.eval(si, wo, wi);
    if (f.is_black()) return {};
    Ray shadow = ls.dist < kInfinity ? spawn_ray_to(si.p, si.ng, ls.p_light) : spawn_ray(si.p, si.ng, ls.wi);
    ++counters.shadow_rays;
    const float tr = scene.transmittance(shadow);
    if (!(tr > 0.f)) return {};
    float light_pdf = ls.pdf * pmf;
    float w = ls.delta ? 1.f : power_heuristic(light_pdf, bsdf.pdf(si, wo, wi));
    return f * ls.li * (tr * w / light_pdf);
  }

  IntegratorSettings s_;
};

}  // namespace

std::unique_ptr<Integrator> make_path_integrator(const IntegratorSettings& settings) {
  return std::make_unique<PathIntegrator>(settings);
}

std::unique_ptr<Integrator> make_integrator(const IntegratorSettings& settings) {
  switch (settings.type) {
    case IntegratorType::Direct: return make_direct_integrator(settings);
    case IntegratorType::Path: break;
  }
  return make_path_integrator(settings);
}

}  // namespace tessera

// Mitsuba's `direct` integrator. With n_l light and n_b BSDF samples, a light sample of density
// p_l is weighted by w = (n_l p_l)^2 / ((n_l p_l)^2 + (n_b p_b)^2) / n_l and symmetrically for BSDF
// samples (Veach's power heuristic for unequal sample counts), so the weights of the two
// strategies sum to one for every direction.
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/render/integrator.h"

namespace tessera {
namespace {

class DirectIntegrator final : public Integrator {
 public:
  explicit DirectIntegrator(const IntegratorSettings& s) : s_(s) {}

  Rgb li(const Scene& scene, const Ray& ray, Sampler& sampler, RenderCounters& counters,
         const PathGuide* /*guide*/, SampleFeatures* features) const override {
    Rgb L;
    SurfaceInteraction si;
    if (!scene.intersect(ray, si)) {
      if (!s_.hide_emitters)
        for (const Light* env : scene.infinite_lights()) L += env->le_env(ray.d);
      return L;
    }
    const Vec3 wo_world = -ray.d;
    if (features) {
      features->depth_found = true;
      features->depth = length(si.p - ray.o);
    }
    if (const Light* area = si.area_light(); area && !s_.hide_emitters) L += area->le(si, wo_world);

    if (!reconcile_shading_frame(si, wo_world, s_.strict_normals)) return L;
    const Vec3 wo = si.to_local(wo_world);
    const Bsdf* bsdf = si.bsdf();
    if (!bsdf) return L;

    const int n_l = std::max(s_.emitter_samples, 0), n_b = std::max(s_.bsdf_samples, 0);
    const float fn_l = float(n_l), fn_b = float(n_b);

    for (int i = 0; i < n_l; ++i) {
      const float u_pick = sampler.next_1d();
      const Vec2 u_light = sampler.next_2d();
      if (bsdf->is_delta()) continue;
      float pmf = 0.f;
      const Light* light = scene.sample_light({si.p, si.shading.n}, u_pick, pmf);
      LightSample ls;
      if (!light || !(pmf > 0.f) || !light->sample_li(si.p, u_light, ls)) continue;
      if (!(ls.pdf > 0.f) || ls.li.is_black()) continue;
      const Vec3 wi = si.to_local(ls.wi);
      if (!consistent_side(si, ls.wi, wi)) continue;
      Rgb f = bsdf->eval(si, wo, wi);
      if (f.is_black()) continue;
      Ray shadow = ls.dist < kInfinity ? spawn_ray_to(si, ls.p_light, ls.p_light_error, ls.n_light) : spawn_ray(si, ls.wi);
      shadow.time = ray.time;
      ++counters.shadow_rays;
      const float tr = scene.transmittance(shadow);
      if (!(tr > 0.f)) continue;
      float light_pdf = ls.pdf * pmf;
      float w = ls.delta ? 1.f : power_heuristic(fn_l * light_pdf, fn_b * bsdf->pdf(si, wo, wi));
      L += f * ls.li * (tr * w / (light_pdf * fn_l));
    }

    for (int j = 0; j < n_b; ++j) {
      const float u_lobe = sampler.next_1d();
      const Vec2 u_bsdf = sampler.next_2d();
      BsdfSample bs;
      const bool sampled = bsdf->sample(si, wo, u_lobe, u_bsdf, bs);
      if (features && j == 0) {  // its first BSDF sample estimates the albedo, as in path (aov.h)
        features->found = true;
        features->albedo = sampled ? bs.weight : Rgb();
        features->normal = si.shading.n;
      }
      if (!sampled) continue;
      const Vec3 wi_world = si.to_world(bs.wi);
      if (!consistent_side(si, wi_world, bs.wi)) continue;
      Ray next = spawn_ray(si, wi_world);
      next.time = ray.time;
      ++counters.bounce_rays;
      SurfaceInteraction hit;
      if (scene.intersect(next, hit)) {
        const Light* area = hit.area_light();
        if (!area) continue;
        Rgb le = area->le(hit, -wi_world);
        if (le.is_black()) continue;
        float light_pdf = bs.delta ? 0.f : area->pdf_li(si.p, hit) * scene.light_pmf({si.p, si.shading.n}, area);
        float w = bs.delta ? 1.f : power_heuristic(fn_b * bs.pdf, fn_l * light_pdf);
        L += bs.weight * le * (w / fn_b);
      } else {
        for (const Light* env : scene.infinite_lights()) {
          Rgb le = env->le_env(wi_world);
          if (le.is_black()) continue;
          float light_pdf = bs.delta ? 0.f : env->pdf_env(wi_world) * scene.light_pmf({si.p, si.shading.n}, env);
          float w = bs.delta ? 1.f : power_heuristic(fn_b * bs.pdf, fn_l * light_pdf);
          L += bs.weight * le * (w / fn_b);
        }
      }
    }
    return L;
  }

 private:
  IntegratorSettings s_;
};

}  // namespace

std::unique_ptr<Integrator> make_direct_integrator(const IntegratorSettings& settings) {
  return std::make_unique<DirectIntegrator>(settings);
}

}  // namespace tessera

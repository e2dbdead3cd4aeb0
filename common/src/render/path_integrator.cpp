// Unidirectional path tracer (see integrator.h): next-event estimation and BSDF sampling at each
// vertex, combined with the power heuristic (or one of them alone: IntegratorSettings::strategy); emitters hit by BSDF-sampled rays are weighted against
// the light-sampling density at the previous vertex (pdf_li or pdf_env times the selection pmf).
//
// As `volpath` it also tracks participating media: each segment samples the current medium's
// free-flight distance; a scattering point does next-event estimation with the phase function and
// continues in a phase-sampled direction, and `null` surfaces only switch the medium. Shadow rays
// carry the medium's transmittance (Scene::transmittance with a medium). Transmittance is the same
// factor for both strategies that can reach a light, so the MIS weights use the directional pdfs.
#include "render/bounce_samples.h"

#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/render/guided_sampling.h"
#include "tessera/render/bdpt.h"
#include "tessera/render/integrator.h"

#include <algorithm>
#include <stdexcept>

namespace tessera {
namespace {

// A path crossing more index-matched boundaries than this in one segment is cut (a ray caught
// between coincident null surfaces would otherwise never advance).
constexpr int kMaxNullCrossings = 256;

// GuideRoulette::Radiance: a path whose expected contribution is a tenth of its pixel's survives;
// below, in proportion, but at least with 0.35 (a survivor's weight stays under 3 where the
// guide's estimate was wrong: lower floors made fireflies on living-room and bathroom, higher ones
// cost living-room more time than they saved error; docs/performance.md).
constexpr float kRadianceWindow = 0.1f;
constexpr float kMinRadianceSurvival = 0.35f;

// Where next-event estimation happens: a surface (bsdf set) or a point in a medium (phase set).
struct Vertex {
  const SurfaceInteraction* si = nullptr;
  const Bsdf* bsdf = nullptr;
  Vec3 wo;  // local shading frame for a surface, world space in a medium
  const PhaseFunction* phase = nullptr;
  Vec3 p, ng;  // ng is zero in a medium: no ray offset, no side test
  float time = 0.f;  // the path's time (motion blur): shadow rays see the scene at that instant
  const Medium* medium = nullptr;  // medium around the vertex (on a surface: resolved per light side)
  const DirectionalTree* guide = nullptr;  // a guided surface vertex: its scattering pdf is the mixture's
  float bsdf_fraction = 1.f;
};

// A path under construction: the radiance gathered so far and what the next step needs.
struct PathState {
  Ray ray;
  Rgb L, throughput{1.f};
  float eta = 1.f;  // product of the relative IORs crossed by refraction (BsdfSample::eta)
  int depth = 0;  // scattering events so far
  int null_crossings = 0;
  float prev_pdf = 0.f;
  bool prev_delta = true;  // the camera "vertex" has no BSDF to combine with
  LightSampleContext prev_ctx;  // the previous vertex, for the light-selection pmf in MIS
  const Medium* medium = nullptr;
  const PathGuide* guide = nullptr;  // path guiding, if this pass guides or trains
  GuideRecords* records = nullptr;   // where a training pass keeps the path's vertices
  float pixel = -1.f;                // the guide's estimate of the pixel (at the first guided vertex)
  float radiance = 0.f;              // its estimate of the radiance along the last guided direction
  SampleFeatures* features = nullptr;  // AOVs, when asked for (aov.h)
  Vec3 camera_o;                       // the camera ray's origin, for the depth AOV
};

// What a segment through a medium did to the path.
enum class MediumEvent { PassedThrough, Scattered, Ended };

class PathIntegrator final : public Integrator {
 public:
  PathIntegrator(const IntegratorSettings& s, bool volumetric) : s_(s), volumetric_(volumetric) {}

  Rgb li(const Scene& scene, const Ray& camera_ray, Sampler& sampler, RenderCounters& counters,
         const PathGuide* guide, SampleFeatures* features) const override {
    if (s_.max_depth == 0) return {};
    const bool media = volumetric_ && scene.has_media();
    PathState path;
    path.medium = media ? scene.camera_medium : nullptr;
    path.ray = camera_ray;
    path.guide = guide;
    path.features = features;
    path.camera_o = camera_ray.o;
    GuideRecords records;
    if (guide && guide->train) path.records = &records;
    SurfaceInteraction si;
    for (;;) {
      path.ray.time = camera_ray.time;  // every ray of a path sees the scene at the camera ray's time
      // Media take two more dimensions per segment (sampler.h); scenes without media keep the layout.
      const Vec2 u_medium = media ? sampler.next_2d() : Vec2();
      const bool found = scene.intersect(path.ray, si, media);
      if (path.medium) {
        const MediumEvent event = medium_step(scene, path, found ? si.t : kInfinity, u_medium, sampler, counters);
        if (event == MediumEvent::Ended) break;
        if (event == MediumEvent::Scattered) continue;
      }
      if (!found) {
        add_environment(scene, path);
        break;
      }
      if (!surface_step(scene, path, si, media, sampler, counters)) break;
    }
    if (path.records) path.records->commit(*guide, path.L, sampler);
    return path.L;
  }

 private:
  bool visible_emitters(const PathState& path) const { return path.depth > 0 || !s_.hide_emitters; }

  // The free flight through the path's medium up to `t_max` (the next surface); at a scattering
  // point, next-event estimation with the phase function and the phase-sampled next segment.
  MediumEvent medium_step(const Scene& scene, PathState& path, float t_max, Vec2 u_medium, Sampler& sampler,
                          RenderCounters& counters) const {
    MediumSample ms;
    path.medium->sample(path.ray, t_max, u_medium, ms);
    path.throughput *= ms.weight;
    if (path.throughput.is_black()) return MediumEvent::Ended;
    if (!ms.scattered) return MediumEvent::PassedThrough;
    if (s_.max_depth >= 0 && path.depth + 1 >= s_.max_depth) return MediumEvent::Ended;
    Vertex v;
    v.p = path.ray.at(ms.t);
    v.wo = -normalize(path.ray.d);
    v.phase = &path.medium->phase();
    v.medium = path.medium;
    v.time = path.ray.time;
    const BounceSamples u = BounceSamples::draw(sampler);
    path.L += path.throughput * sample_direct(scene, v, u.u_pick, u.u_light, counters);
    Vec3 wi;
    float pdf = 0.f;
    const float weight = v.phase->sample(v.wo, u.u_dir, wi, pdf);
    if (path.features && !path.features->found) {
      path.features->found = true;
      path.features->albedo = path.throughput;
    }
    if (!(weight > 0.f) || !(pdf > 0.f)) return MediumEvent::Ended;
    path.throughput *= weight;
    path.prev_pdf = pdf;
    path.prev_delta = false;
    path.prev_ctx = {v.p, Vec3(0.f)};
    ++path.depth;
    path.null_crossings = 0;
    if (!survives_roulette(path.depth, path.throughput, path.eta, u.u_rr)) return MediumEvent::Ended;
    path.ray = Ray{v.p, wi};
    ++counters.bounce_rays;
    return MediumEvent::Scattered;
  }

  // A ray that left the scene: the environment's radiance, MIS-weighted against the previous vertex.
  void add_environment(const Scene& scene, PathState& path) const {
    if (!visible_emitters(path)) return;
    for (const Light* env : scene.infinite_lights()) {
      Rgb le = env->le_env(path.ray.d);
      if (le.is_black()) continue;
      float w = path.prev_delta ? 1.f : hit_weight(path.prev_pdf, [&] {
        return env->pdf_env(path.ray.d) * scene.light_pmf(path.prev_ctx, env);
      });
      if (w > 0.f || s_.strategy == SamplingStrategy::Mis) path.L += path.throughput * le * w;
    }
  }

  // A surface hit: an index-matched boundary only switches the medium; otherwise its emission
  // (MIS-weighted), next-event estimation and the BSDF-sampled next segment. False ends the path.
  bool surface_step(const Scene& scene, PathState& path, SurfaceInteraction& si, bool media, Sampler& sampler,
                    RenderCounters& counters) const {
    const Bsdf* bsdf = si.bsdf();
    if (media && bsdf && bsdf->is_null()) {
      // The path vertex stays where it was.
      if (++path.null_crossings > kMaxNullCrossings) return false;
      path.medium = medium_after(si, path.ray.d, path.medium);
      path.ray = spawn_ray(si, path.ray.d);
      return true;
    }
    path.null_crossings = 0;
    // Recorded where a direction is sampled at all (not at delta-only BSDFs). The leaf is found
    // first and its data asked for: far in memory, it then arrives while the vertex does the rest.
    const bool recorded = path.guide && bsdf && !bsdf->is_delta();
    Vec3 extent;  // (of the leaf's region: the stochastic spatial filter's box)
    const uint32_t leaf = recorded ? path.guide->tree->leaf_of(si.p, path.records ? &extent : nullptr) : 0;
    if (recorded) path.guide->tree->prefetch_leaf(leaf);
    if (path.features && !path.features->depth_found) {
      path.features->depth_found = true;
      path.features->depth = length(si.p - path.camera_o);
    }
    const Vec3 wo_world = -path.ray.d;
    if (const Light* area = si.area_light(); area && visible_emitters(path)) add_emission(scene, path, si, *area);
    if (s_.max_depth >= 0 && path.depth + 1 >= s_.max_depth) return false;
    if (!reconcile_shading_frame(si, wo_world, s_.strict_normals)) return false;
    if (!bsdf) return false;
    const Vec3 wo = si.to_local(wo_world);
    const BounceSamples u = BounceSamples::draw(sampler);
    // Guided where the lobe is rough enough (guides_lobe).
    const bool guided = recorded && path.guide->sample && guides_lobe(*bsdf, si);
    const DirectionalTree* guide = guided ? &path.guide->tree->sampling(leaf) : nullptr;
    if (guide) guide->prefetch();  // (its descents come after the shadow ray)
    const float fraction = guide ? path.guide->tree->bsdf_fraction(leaf) : 1.f;
    if (!bsdf->is_delta()) {
      Vertex v;
      v.si = &si;
      v.bsdf = bsdf;
      v.wo = wo;
      v.p = si.p;
      v.ng = si.ng;
      v.medium = path.medium;
      v.time = path.ray.time;
      v.guide = guide;
      v.bsdf_fraction = fraction;
      path.L += path.throughput * sample_direct(scene, v, u.u_pick, u.u_light, counters);
    }
    BsdfSample bs;
    MixturePdfs mixture;
    const bool sampled = guide ? sample_guided(*bsdf, si, wo, *guide, fraction, u.u_lobe, u.u_dir, bs, &mixture)
                               : bsdf->sample(si, wo, u.u_lobe, u.u_dir, bs);
    if (path.features && !path.features->found && !bsdf->is_delta())
      take_features(*path.features, si, path.throughput, sampled ? bs.weight : Rgb());
    if (!sampled) return false;
    const Vec3 wi_world = si.to_world(bs.wi);
    if (!consistent_side(si, wi_world, bs.wi)) return false;
    path.throughput *= bs.weight;
    if (path.records && !bs.delta)
      path.records->add(si.p, extent, leaf, wi_world, bs.pdf, bs.weight.luminance() * bs.pdf,
                        guide ? std::optional(mixture) : std::nullopt, path.throughput, path.L);
    path.prev_pdf = bs.pdf;
    path.prev_delta = bs.delta;
    path.eta *= bs.eta;
    path.prev_ctx = {si.p, si.shading.n};
    ++path.depth;
    if (media) path.medium = medium_after(si, wi_world, path.medium);
    // (The pixel's estimate is kept by the leaf of the path's first recorded vertex: SpatialTree::pixel.)
    if (recorded && path.guide->sample && !bs.delta && path.pixel < 0.f) path.pixel = path.guide->tree->pixel(leaf);
    if (!survives_vertex(path, leaf, bs.delta, guide ? &mixture : nullptr, u.u_rr)) return false;
    path.ray = spawn_ray(si, wi_world);
    ++counters.bounce_rays;
    return true;
  }

  // The first vertex that is not purely specular: the albedo is the chain's throughput times this
  // sample's eval·cos/pdf, an estimate of the BSDF's directional albedo (aov.h).
  static void take_features(SampleFeatures& f, const SurfaceInteraction& si, Rgb throughput, Rgb weight) {
    f.found = true;
    f.albedo = throughput * weight;
    f.normal = si.shading.n;
  }

  // An emitter hit by the path, MIS-weighted against the previous vertex's light sampling.
  void add_emission(const Scene& scene, PathState& path, const SurfaceInteraction& si, const Light& area) const {
    Rgb le = area.le(si, -path.ray.d);
    if (le.is_black()) return;
    float w = path.prev_delta ? 1.f : hit_weight(path.prev_pdf, [&] {
      return area.pdf_li(path.prev_ctx.p, si) * scene.light_pmf(path.prev_ctx, &area);
    });
    if (w > 0.f || s_.strategy == SamplingStrategy::Mis) path.L += path.throughput * le * w;
  }

  // Russian roulette as Mitsuba 3: survival probability from the throughput, times eta^2 so that
  // refraction's radiance scaling does not kill paths inside glass early; capped at 0.95.
  bool survives_roulette(int depth, Rgb& throughput, float eta, float u_rr) const {
    return survives(depth >= s_.rr_depth ? std::min(throughput.max_value() * eta * eta, 0.95f) : 1.f, u_rr, throughput);
  }

  // The path survives with probability q (1: no roulette), its throughput divided by q; a path
  // that carries nothing ends.
  static bool survives(float q, float u_rr, Rgb& throughput) {
    if (q < 1.f) {
      if (!(u_rr < q)) return false;
      throughput *= 1.f / q;
    }
    return !throughput.is_black();
  }

  // Russian roulette after a surface vertex: as the guide's settings ask once it samples, else
  // by the throughput.
  bool survives_vertex(PathState& path, uint32_t leaf, bool delta, const MixturePdfs* mixture, float u_rr) const {
    if (path.guide && path.guide->sample) {
      // (Müller's rule: 0.99 whatever the throughput, which a guided direction toward bright light
      // makes small.)
      if (path.guide->roulette == GuideRoulette::Guided)
        return survives(path.depth >= s_.rr_depth ? 0.99f : 1.f, u_rr, path.throughput);
      if (path.guide->roulette == GuideRoulette::Radiance)
        if (const float q = radiance_survival(path, leaf, delta, mixture); q > 0.f) return survives(q, u_rr, path.throughput);
    }
    return survives_roulette(path.depth, path.throughput, path.eta, u_rr);
  }

  // GuideRoulette::Radiance's survival probability: the path's expected contribution from wi (its
  // throughput times the guide's radiance estimate along wi) over the pixel's estimate, relative to
  // kRadianceWindow, within [kMinRadianceSurvival, 0.99] (so that paths in glass end too); 0 where
  // the guide knows neither. A delta vertex takes the estimate of the last guided one: what lies
  // along its chain.
  static float radiance_survival(PathState& path, uint32_t leaf, bool delta, const MixturePdfs* mixture) {
    if (!(path.pixel > 0.f)) return 0.f;
    if (!delta) path.radiance = mixture ? path.guide->tree->radiance(leaf) * mixture->guide : 0.f;
    if (!(path.radiance > 0.f)) return 0.f;
    const float q = path.throughput.luminance() * path.radiance / (path.pixel * kRadianceWindow);
    return std::clamp(q, kMinRadianceSurvival, 0.99f);
  }

  // Weight of an emitter found by a BSDF/phase-sampled ray after a non-delta lobe (integrator.h);
  // `light_pdf` gives next-event estimation's density for it, computed only when needed.
  template <typename LightPdf>
  float hit_weight(float prev_pdf, LightPdf&& light_pdf) const {
    switch (s_.strategy) {
      case SamplingStrategy::Bsdf: return 1.f;
      case SamplingStrategy::Nee: return light_pdf() > 0.f ? 0.f : 1.f;
      case SamplingStrategy::Mis: break;
    }
    return power_heuristic(prev_pdf, light_pdf());
  }

  // The density with which the vertex would have sampled the world direction `wi`.
  static float vertex_pdf(const Vertex& v, Vec3 wi_world) {
    if (!v.si) return v.phase->pdf(v.wo, wi_world);
    const Vec3 wi = v.si->to_local(wi_world);
    return v.guide ? guided_pdf(*v.bsdf, *v.si, v.wo, wi, *v.guide, v.bsdf_fraction) : v.bsdf->pdf(*v.si, v.wo, wi);
  }

  // One light sample, weighted by the strategy (MIS: against the BSDF or phase function); not yet
  // multiplied by the throughput.
  Rgb sample_direct(const Scene& scene, const Vertex& v, float u_pick, Vec2 u_light, RenderCounters& counters) const {
    float pmf = 0.f;
    const LightSampleContext ctx{v.p, v.si ? v.si->shading.n : Vec3(0.f)};
    const Light* light = scene.sample_light(ctx, u_pick, pmf);
    const bool mis = s_.strategy == SamplingStrategy::Mis;
    // BSDF-only keeps next-event estimation for the delta lights no sampled ray can hit.
    const bool bsdf_only = s_.strategy == SamplingStrategy::Bsdf;
    if (bsdf_only && light && !light->is_delta()) return {};
    LightSample ls;
    ls.defer_li = true;  // most samples of an interior's sky are occluded
    if (!light || !(pmf > 0.f) || !light->sample_li(v.p, u_light, ls)) return {};
    if (!(ls.pdf > 0.f) || (!ls.li_deferred && ls.li.is_black())) return {};
    if (bsdf_only && !ls.delta) return {};
    Rgb f;
    const Medium* shadow_medium = v.medium;
    if (v.si) {
      const Vec3 wi = v.si->to_local(ls.wi);
      if (!consistent_side(*v.si, ls.wi, wi)) return {};
      f = v.bsdf->eval(*v.si, v.wo, wi);
      if (volumetric_) shadow_medium = medium_after(*v.si, ls.wi, v.medium);
    } else {
      f = Rgb(v.phase->eval(v.wo, ls.wi));
    }
    if (f.is_black()) return {};
    const Vec3 p_error = v.si ? v.si->p_error : Vec3(0.f);  // a medium vertex is exact
    Ray shadow = ls.dist < kInfinity ? spawn_ray_to(v.p, p_error, v.ng, ls.p_light, ls.p_light_error, ls.n_light)
                                     : spawn_ray(v.p, p_error, v.ng, ls.wi);
    shadow.time = v.time;
    ++counters.shadow_rays;
    const Rgb tr = volumetric_ ? scene.transmittance(shadow, shadow_medium) : Rgb(scene.transmittance(shadow));
    if (tr.is_black()) return {};
    // (After the shadow ray: most light samples of a room lit through an opening are occluded, and
    // a guided vertex's mixture pdf is a descent of its guide.)
    const float scatter_pdf = !ls.delta && mis ? vertex_pdf(v, ls.wi) : 0.f;
    const Rgb li = ls.li_deferred ? light->deferred_li(ls) : ls.li;
    float light_pdf = ls.pdf * pmf;
    float w = ls.delta || !mis ? 1.f : power_heuristic(light_pdf, scatter_pdf);
    return f * li * tr * (w / light_pdf);
  }

  IntegratorSettings s_;
  bool volumetric_;
};

}  // namespace

const char* sampling_strategy_name(SamplingStrategy strategy) {
  switch (strategy) {
    case SamplingStrategy::Bsdf: return "bsdf";
    case SamplingStrategy::Nee: return "nee";
    case SamplingStrategy::Mis: break;
  }
  return "mis";
}

bool parse_sampling_strategy(const std::string& name, SamplingStrategy& out) {
  for (SamplingStrategy s : {SamplingStrategy::Mis, SamplingStrategy::Bsdf, SamplingStrategy::Nee})
    if (name == sampling_strategy_name(s)) {
      out = s;
      return true;
    }
  return false;
}

std::unique_ptr<Integrator> make_path_integrator(const IntegratorSettings& settings) {
  return std::make_unique<PathIntegrator>(settings, settings.type == IntegratorType::VolPath);
}

std::unique_ptr<Integrator> make_integrator(const IntegratorSettings& settings) {
  switch (settings.type) {
    case IntegratorType::Direct: return make_direct_integrator(settings);
    case IntegratorType::Bdpt: return make_bdpt_integrator(settings);
    case IntegratorType::Ptracer: return make_ptracer_integrator(settings);
    case IntegratorType::Sppm:
    case IntegratorType::Vcm:
      throw std::invalid_argument(std::string("the ") + integrator_name(settings.type) +
                                  " integrator renders by passes of light and camera units (sequence/photon_program.h), "
                                  "not by a radiance per camera ray");
    case IntegratorType::Path:
    case IntegratorType::VolPath: break;
  }
  return make_path_integrator(settings);
}

}  // namespace tessera

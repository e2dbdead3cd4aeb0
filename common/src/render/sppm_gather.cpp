// The gather half of an sppm pass (sppm.h): visible points, their direct light, the photons near
// them and the per-pixel update.
#include "tessera/render/sppm.h"

#include "render/bdpt_subpath.h"
#include "render/bounce_samples.h"
#include "render/octahedral.h"
#include "tessera/core/check.h"
#include "tessera/render/bsdf.h"
#include "tessera/render/camera.h"
#include "tessera/render/light.h"
#include "tessera/render/render_tile.h"
#include "tessera/render/sampler.h"

#include <cmath>

namespace tessera {
namespace {

// A chain of mirrors facing each other must end even without a depth limit.
constexpr int kMaxSpecularSegments = 256;

// Where a pixel sample's camera path stops: its radiance so far and, at a non-delta surface, the
// visible point.
struct VisiblePoint {
  Rgb direct;           // emitters hit on the way and next-event estimation at the point
  Rgb beta;             // throughput to the point
  SurfaceInteraction si;
  const Bsdf* bsdf = nullptr;  // null: no visible point
  Vec3 wo;              // local
  int length = 0;       // camera segments to the point
};

Rgb environment(const Scene& scene, Vec3 d) {
  Rgb sum;
  for (const Light* env : scene.infinite_lights()) sum += env->le_env(d);
  return sum;
}

// Next-event estimation at full weight: nothing else samples direct light at a visible point.
Rgb direct_light(const Scene& scene, const VisiblePoint& vp, const BounceSamples& u, float time, RenderCounters& counters) {
  bdpt::DirectSample d;
  if (!bdpt::sample_direct(scene, vp.si, u.u_pick, u.u_light, d)) return {};
  const Rgb f = vp.bsdf->eval(vp.si, vp.wo, d.wi);
  if (f.is_black()) return {};
  const float tr = bdpt::direct_transmittance(scene, vp.si, d.ls, time, counters);
  return tr > 0.f ? f * d.li() * (tr / (d.pmf * d.ls.pdf)) : Rgb();
}

// The camera ray through delta BSDFs to its first non-delta surface.
void find_visible_point(const Scene& scene, Ray ray, Sampler& sampler, VisiblePoint& vp, RenderCounters& counters) {
  const IntegratorSettings& s = scene.integrator;
  vp.direct = Rgb();
  vp.beta = Rgb(1.f);
  vp.bsdf = nullptr;
  for (int c = 1; c <= kMaxSpecularSegments; ++c) {
    const bool shown = c > 1 || !s.hide_emitters;
    if (!scene.intersect(ray, vp.si)) {
      if (shown) vp.direct += vp.beta * environment(scene, normalize(ray.d));
      return;
    }
    const Vec3 wo_world = normalize(-ray.d);
    if (const Light* area = vp.si.area_light(); area && shown) vp.direct += vp.beta * area->le(vp.si, wo_world);
    if (s.max_depth >= 0 && c >= s.max_depth) return;
    if (!reconcile_shading_frame(vp.si, wo_world, s.strict_normals)) return;
    const Bsdf* bsdf = vp.si.bsdf();
    if (!bsdf) return;
    const BounceSamples u = BounceSamples::draw(sampler);
    vp.wo = vp.si.to_local(wo_world);
    if (!bsdf->is_delta()) {
      vp.bsdf = bsdf;
      vp.length = c;
      if (!s.photon_direct && (s.max_depth < 0 || c + 1 <= s.max_depth))
        vp.direct += vp.beta * direct_light(scene, vp, u, ray.time, counters);
      return;
    }
    BsdfSample bs;
    if (!bsdf->sample(vp.si, vp.wo, u.u_lobe, u.u_dir, bs)) return;
    const Vec3 wi = vp.si.to_world(bs.wi);
    if (!consistent_side(vp.si, wi, bs.wi)) return;
    vp.beta *= bs.weight;
    if (vp.beta.is_black()) return;
    const float time = ray.time;
    ray = spawn_ray(vp.si, wi);
    ray.time = time;
    ++counters.bounce_rays;
  }
}

// Phi and M at a visible point (sppm.h): photons within `radius` on a surface facing its side.
Rgb gather(const Scene& scene, const PhotonMap& map, const VisiblePoint& vp, float radius, uint32_t& found) {
  const int max_depth = scene.integrator.max_depth;
  const Vec3 wo_world = vp.si.to_world(vp.wo);
  const Vec3 n_side = dot(vp.si.ng, wo_world) >= 0.f ? vp.si.ng : -vp.si.ng;
  Rgb phi;
  found = 0;
  map.for_each_near(vp.si.p, radius, [&](const Photon& ph) {
    if (max_depth >= 0 && vp.length + int(ph.length) > max_depth) return;
    if (dot(bdpt::record_normal(ph.n), n_side) < bdpt::kMinMergeNormalCos) return;
    const Vec3 wi_world = octahedral::decode(ph.wi, 16);
    const Vec3 wi = vp.si.to_local(wi_world);
    ++found;
    if (!consistent_side(vp.si, wi_world, wi) || !(std::abs(wi.z) > 1e-6f)) return;
    const Rgb f = vp.bsdf->eval(vp.si, vp.wo, wi) * (1.f / std::abs(wi.z));  // (eval has the cosine)
    phi += f * Rgb(ph.power[0], ph.power[1], ph.power[2]);
  });
  return phi;
}

// I = tau / (photon_count pi r^2): the film's running indirect term (sppm.h).
double indirect_sum(const SppmPixel& px, int c, double photons) {
  return px.radius > 0.f ? px.tau[c] / (photons * M_PI * double(px.radius) * double(px.radius)) : 0.0;
}

}  // namespace

void sppm_gather(const Scene& scene, const PhotonMap& map, const TileRect& rect, uint32_t pass, uint32_t seed,
                 std::span<SppmPixel> state, FilmTile& tile) {
  TESSERA_CHECK(scene.camera != nullptr && state.size() == size_t(rect.area()));
  const IntegratorSettings& s = scene.integrator;
  const Filter* filter = scene.film.filter.get();
  const double photons = double(std::max<uint64_t>(s.photon_count, 1));
  tile.reset(rect);
  Sampler sampler(scene.sampler.type, seed);
  VisiblePoint vp;
  for (int y = rect.y0; y < rect.y1; ++y)
    for (int x = rect.x0; x < rect.x1; ++x) {
      SppmPixel& px = state[size_t(y - rect.y0) * size_t(rect.width()) + size_t(x - rect.x0)];
      if (px.radius == 0.f) px.radius = map.max_radius();
      sampler.start_pixel_sample({x, y}, pass);
      const Vec2 u_film = sampler.next_2d(), u_lens = sampler.next_2d();
      const Vec2 offset = filter ? filter->sample(u_film) : Vec2(u_film.x - 0.5f, u_film.y - 0.5f);
      const Ray ray = scene.camera->generate_ray_at({float(x) + 0.5f + offset.x, float(y) + 0.5f + offset.y}, u_lens,
                                                    camera_sample_time(scene, sampler));
      ++tile.counters.camera_rays;
      find_visible_point(scene, ray, sampler, vp, tile.counters);
      double before[3], sample[3];
      for (int c = 0; c < 3; ++c) before[c] = indirect_sum(px, c, photons);
      uint32_t m = 0;
      const Rgb phi = vp.bsdf ? gather(scene, map, vp, px.radius, m) * vp.beta : Rgb();
      if (m > 0 && phi.is_finite()) {
        const double n_new = double(px.n) + double(s.alpha) * double(m);
        const double ratio = n_new / (double(px.n) + double(m));  // (r'/r)^2
        for (int c = 0; c < 3; ++c) px.tau[c] = (px.tau[c] + double(phi[c])) * ratio;
        px.n = float(n_new);
        px.radius = float(double(px.radius) * std::sqrt(ratio));
      }
      for (int c = 0; c < 3; ++c) sample[c] = double(vp.direct[c]) + indirect_sum(px, c, photons) - before[c];
      tile.add_sample({x, y}, Rgb(float(sample[0]), float(sample[1]), float(sample[2])));
    }
}

}  // namespace tessera

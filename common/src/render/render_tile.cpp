#include "tessera/render/render_tile.h"

#include "tessera/core/check.h"
#include "tessera/render/sampler.h"

namespace tessera {

float camera_sample_time(const Scene& scene, Sampler& sampler) {
  if (!scene.has_shutter_interval()) return scene.shutter_open;
  return scene.shutter_open + (scene.shutter_close - scene.shutter_open) * sampler.sample_1d_at(Sampler::kTimeDimension);
}

void render_tile(const Scene& scene, const Integrator& integrator, const TileRect& rect, const PassSamples& samples,
                 uint32_t seed, FilmTile& tile, const PathGuide* guide, bool aovs) {
  TESSERA_CHECK(samples.rect.contains(rect));
  const Filter* filter = scene.film.filter.get();
  TESSERA_CHECK(scene.camera != nullptr);
  tile.reset(rect, aovs);
  Sampler sampler(scene.sampler.type, seed);
  for (int y = rect.y0; y < rect.y1; ++y) {
    for (int x = rect.x0; x < rect.x1; ++x) {
      const size_t i = samples.index({x, y});
      const uint32_t sample_begin = samples.first[i], sample_end = sample_begin + samples.count[i];
      for (uint32_t s = sample_begin; s < sample_end; ++s) {
        sampler.start_pixel_sample({x, y}, s);
        Vec2 u_film = sampler.next_2d();
        Vec2 u_lens = sampler.next_2d();
        // Without a filter (scenes built in code): a box over the pixel.
        Vec2 offset = filter ? filter->sample(u_film) : Vec2(u_film.x - 0.5f, u_film.y - 0.5f);
        Vec2 raster(float(x) + 0.5f + offset.x, float(y) + 0.5f + offset.y);
        // Motion blur: a time in the shutter from a dedicated dimension (sampler.h); without it,
        // the layout and every value are the same as before.
        Ray ray = scene.camera->generate_ray_at(raster, u_lens, camera_sample_time(scene, sampler));
        ++tile.counters.camera_rays;
        if (tile.has_aovs()) {
          SampleFeatures features;
          const Rgb L = integrator.li(scene, ray, sampler, tile.counters, guide, &features);
          tile.add_sample({x, y}, L, s, features);
        } else {
          tile.add_sample({x, y}, integrator.li(scene, ray, sampler, tile.counters, guide, nullptr));
        }
      }
    }
  }
}

void render_tile(const Scene& scene, const TileRect& rect, uint32_t sample_begin, uint32_t sample_end,
                 uint32_t seed, FilmTile& tile) {
  render_tile(scene, rect, PassSamples::uniform(rect, sample_begin, sample_end), seed, tile);
}

void render_tile(const Scene& scene, const TileRect& rect, const PassSamples& samples, uint32_t seed, FilmTile& tile,
                 const PathGuide* guide, bool aovs) {
  auto integrator = make_integrator(scene.integrator);
  render_tile(scene, *integrator, rect, samples, seed, tile, guide, aovs);
}

}  // namespace tessera

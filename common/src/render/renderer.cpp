#include "tessera/render/renderer.h"

#include "tessera/core/check.h"
#include "tessera/render/adaptive.h"
#include "tessera/render/integrator.h"
#include "tessera/render/noise_estimate.h"
#include "tessera/render/sampler.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>

namespace tessera {

std::vector<uint32_t> pass_schedule(uint32_t spp) {
  std::vector<uint32_t> passes;
  uint32_t done = 0, next = 1;
  while (done < spp) {
    uint32_t n = std::min(next, spp - done);
    passes.push_back(n);
    done += n;
    next = std::min(next * 2, 64u);
  }
  return passes;
}

bool guiding_trains_pass(const std::vector<uint32_t>& passes, size_t pass, uint32_t spp) {
  uint32_t end = 0;
  for (size_t p = 0; p <= pass && p < passes.size(); ++p) end += passes[p];
  return pass < passes.size() && end <= spp / 2;
}

std::vector<TileRect> make_tiles(const TileRect& window, int tile_size) {
  TESSERA_CHECK(tile_size > 0);
  std::vector<TileRect> tiles;
  for (int y = window.y0; y < window.y1; y += tile_size)
    for (int x = window.x0; x < window.x1; x += tile_size)
      tiles.push_back({x, y, std::min(x + tile_size, window.x1), std::min(y + tile_size, window.y1)});
  return tiles;
}

namespace {

void render_tile_with(const Scene& scene, const Integrator& integrator, const Filter* filter,
                      const TileRect& rect, const PassSamples& samples, uint32_t seed,
                      const PathGuide* guide, bool aovs, FilmTile& tile) {
  TESSERA_CHECK(scene.camera != nullptr);
  tile.reset(rect, aovs);
  Sampler sampler(scene.sampler.type, seed);
  const bool timed = scene.has_shutter_interval();
  const float open = scene.shutter_open, shutter = scene.shutter_close - scene.shutter_open;
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
        const float time = timed ? open + shutter * sampler.sample_1d_at(Sampler::kTimeDimension) : open;
        Ray ray = scene.camera->generate_ray_at(raster, u_lens, time);
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

}  // namespace

void render_tile(const Scene& scene, const TileRect& rect, uint32_t sample_begin, uint32_t sample_end,
                 uint32_t seed, FilmTile& tile) {
  render_tile(scene, rect, PassSamples::uniform(rect, sample_begin, sample_end), seed, tile);
}

void render_tile(const Scene& scene, const TileRect& rect, const PassSamples& samples, uint32_t seed, FilmTile& tile,
                 const PathGuide* guide, bool aovs) {
  TESSERA_CHECK(samples.rect.contains(rect));
  auto integrator = make_integrator(scene.integrator);
  render_tile_with(scene, *integrator, scene.film.filter.get(), rect, samples, seed, guide, aovs, tile);
}

Film render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
            RenderStats* stats) {
  auto start = std::chrono::steady_clock::now();
  TESSERA_CHECK(settings.spp >= 0 && settings.tile_size > 0);
  Film film(scene.film, settings.aovs);
  const std::vector<TileRect> tiles = make_tiles(film.window(), settings.tile_size);
  const std::vector<uint32_t> passes = pass_schedule(uint32_t(settings.spp));
  auto integrator = make_integrator(scene.integrator);
  const Filter* filter = scene.film.filter.get();

  RenderProgress prog;
  prog.num_passes = int(passes.size());
  prog.tiles_total = int64_t(tiles.size() * passes.size());
  prog.spp = uint32_t(settings.spp);
  std::mutex mutex;  // guards counters and progress; taken once per tile
  RenderCounters counters;
  double noise = 0;
  std::optional<SpatialTree> tree;
  if (settings.guiding && scene.integrator.type != IntegratorType::Direct && !scene.bounds().empty())
    tree.emplace(scene.bounds(), settings.guiding_settings.bsdf_fraction);
  size_t trained = 0;  // training passes so far
  std::vector<uint32_t> taken(size_t(film.window().area()), 0);  // per pixel: its next sample index

  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    uint32_t begin = 0;
    for (size_t p = 0; p < passes.size(); ++p) {
      prog.pass = int(p);
      // A pass samples with what earlier passes learned, and trains if it is a training pass.
      SpatialTree* pass_tree = tree ? &*tree : nullptr;
      PathGuide guide{pass_tree, pass_tree, trained > 0, guiding_trains_pass(passes, p, uint32_t(settings.spp))};
      const PathGuide* pass_guide = guide.tree && (guide.sample || guide.train) ? &guide : nullptr;
      const PassSamples samples = plan_pass(film, taken, begin, passes[p], uint32_t(settings.spp),
                                            settings.adaptive ? &settings.adaptive_settings : nullptr);
      // Tiles are disjoint, so adding their sums concurrently touches distinct pixels; passes are
      // separated by the parallel_for barrier, which fixes the per-pixel order of pass sums.
      tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
        FilmTile tile;
        for (size_t i = r.begin(); i != r.end(); ++i) {
          render_tile_with(scene, *integrator, filter, tiles[i], samples, settings.seed, pass_guide, settings.aovs, tile);
          if (!(guide.train && tree && settings.guiding_settings.discard_training)) film.add_tile(tile);
          std::lock_guard<std::mutex> lock(mutex);
          counters += tile.counters;
          ++prog.tiles_done;
          if (progress) progress(prog);
        }
      });
      if (pass_guide && guide.train) tree->end_iteration(int(trained++), settings.guiding_settings);  // (at the barrier)
      for (size_t i = 0; i < taken.size(); ++i) taken[i] += samples.count[i];
      begin += passes[p];
      prog.samples_done = begin;
      if (settings.target_error > 0 && p + 1 < passes.size()) {
        noise = estimate_noise(film).rel_mse;
        if (noise <= settings.target_error) break;
      }
    }
  });
  film.add_counters(counters);
  if (stats) {
    stats->counters = counters;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats->spp_done = prog.samples_done;
    if (tree) {
      stats->guide_leaves = tree->leaf_count();
      stats->guide_bytes = tree->bytes();
    }
    stats->noise_estimate = settings.target_error > 0 ? (prog.samples_done == uint32_t(settings.spp) ? estimate_noise(film).rel_mse : noise) : 0;
  }
  return film;
}

}  // namespace tessera

// Helpers of the hard-case tests: moving a loaded scene description in the world, rendering
// small and deterministically, and the checks every hard case makes (nothing non-finite anywhere).
#pragma once

#include "tessera/image/image.h"
#include "tessera/image/image_compare.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

namespace tessera::test {

/// Premultiplies `world` onto the to_world of every shape, emitter and sensor of the description
/// (so camera, geometry and lights move together; a perspective camera's clip distances follow
/// its to_world's scale, see perspective_camera.cpp). A node without a to_world gets one. Only for
/// scenes whose placement lives in to_world: a node placed otherwise (sphere `center`, point
/// `position`, directional `direction`) fails the test rather than being silently left behind.
inline void apply_world_transform(SceneDesc& desc, const Transform& world) {
  std::set<const SceneNode*> done;  // a <ref>'d node appears under several parents
  for (const auto& node : desc.root->children) {
    if (node->tag != "shape" && node->tag != "emitter" && node->tag != "sensor") continue;
    if (!done.insert(node.get()).second) continue;
    for (const char* other : {"center", "position", "direction", "radius"})
      for (const Property& p : node->props)
        if (p.name == other) ADD_FAILURE() << node->describe() << " is placed by '" << other << "'";
    bool found = false;
    for (Property& p : node->props) {
      if (p.name != "to_world") continue;
      found = true;
      if (p.type == PropType::Animation) {
        for (auto& k : p.keyframes) k.xf = world * k.xf;
      }
      p.xf = world * p.xf;
    }
    if (!found) {
      Property p;
      p.name = p.written_name = "to_world";
      p.type = PropType::Transform;
      p.loc = node->loc;
      p.xf = world;
      node->props.push_back(p);
    }
  }
}

/// The Cornell box of ../shared, moved by `world`, at `size`^2 pixels (callers check the file).
inline LoadResult load_cornell(const std::string& path, const Transform& world, int size, int spp) {
  SceneDesc desc = parse_scene_file(path);
  apply_world_transform(desc, world);
  LoadOptions options;
  options.width = size;
  options.height = size;
  options.spp = spp;
  return load_scene(desc, options);
}

inline RenderSettings hard_settings(int spp, uint32_t seed = 7) {
  RenderSettings s;
  s.spp = spp;
  s.seed = seed;
  s.threads = 2;
  s.tile_size = 16;
  return s;
}

/// The invariant of every hard case: no sample was non-finite (the film drops and counts them) and
/// no pixel of the image is NaN or infinite.
inline void expect_all_finite(const Film& film, const RenderStats& stats, const std::string& what) {
  EXPECT_EQ(stats.counters.nonfinite, 0u) << what << ": non-finite samples dropped by the film";
  EXPECT_EQ(film.counters().nonfinite, 0u) << what;
  EXPECT_EQ(count_non_finite(film.to_image()), 0u) << what << ": non-finite pixels";
  for (int y = film.window().y0; y < film.window().y1; ++y)
    for (int x = film.window().x0; x < film.window().x1; ++x) {
      const PixelSums& p = film.pixel({x, y});
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(p.sum[c]) || !std::isfinite(p.sum_sq[c])) {
          ADD_FAILURE() << what << ": pixel sums at " << x << "," << y << " not finite";
          return;
        }
    }
}

/// Renders and checks finiteness; returns the film.
inline Film render_checked(const Scene& scene, const RenderSettings& settings, const std::string& what,
                           RenderStats* out = nullptr) {
  RenderStats stats;
  Film film = render(scene, settings, {}, &stats);
  expect_all_finite(film, stats, what);
  if (out) *out = stats;
  return film;
}

inline double mean_luminance(const Image& img) {
  auto m = channel_means(img);
  return 0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2];
}

/// Fraction of pixels whose every channel is exactly 0 (holes show as black pixels).
inline double black_fraction(const Image& img) {
  size_t black = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      bool all_zero = true;
      for (int c = 0; c < 3; ++c) all_zero = all_zero && img.at(x, y, c) == 0.f;
      black += all_zero;
    }
  return double(black) / double(size_t(img.width()) * size_t(img.height()));
}

}  // namespace tessera::test

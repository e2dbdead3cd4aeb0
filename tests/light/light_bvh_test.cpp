// Light selection (render/light_sampler.h): the light BVH's choices follow light_pmf (chi-square),
// light_pmf equals the pmf sample_light returned, the pmfs sum to one (less the probability of
// choosing nothing), the importance bound never excludes a light that can reach the point, cone
// merging is conservative; power selection is exactly power / total; meshes are split per triangle.
#include "support/discrete_chi2.h"
#include "test_support.h"
#include "tessera/core/hash.h"
#include "tessera/light/area.h"
#include "tessera/light/constant.h"
#include "tessera/render/light_bounds.h"
#include "tessera/light/point.h"
#include "tessera/render/scene.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

Vec3 random_unit(Pcg32& rng) {
  float z = 1.f - 2.f * rng.next_float(), phi = 2.f * kPi * rng.next_float();
  float r = std::sqrt(std::max(0.f, 1.f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// `count` random triangles in [-10, 10]^3, edges 0.05 .. 2, random orientations.
std::shared_ptr<MeshData> random_triangles(Pcg32& rng, int count) {
  auto m = std::make_shared<MeshData>();
  for (int t = 0; t < count; ++t) {
    Vec3 c(20.f * rng.next_float() - 10.f, 20.f * rng.next_float() - 10.f, 20.f * rng.next_float() - 10.f);
    float edge = 0.05f * std::pow(40.f, rng.next_float());
    for (int k = 0; k < 3; ++k) {
      m->positions.push_back(c + random_unit(rng) * edge);
      m->indices.push_back(uint32_t(m->positions.size() - 1));
    }
  }
  return m;
}

// Two emissive meshes (400 triangles), point lights, sphere lights and, optionally, a constant
// environment: every kind of light the sampler handles.
std::unique_ptr<Scene> synthetic_scene(bool with_environment) {
  auto scene = std::make_unique<Scene>();
  Pcg32 rng(2024);
  const Rgb radiance[2] = {Rgb(1.f, 2.f, 3.f), Rgb(40.f, 30.f, 20.f)};
  for (int m = 0; m < 2; ++m) {
    scene->shapes.push_back(std::make_unique<TriangleMeshShape>(random_triangles(rng, m ? 100 : 300), m == 1, true));
    scene->lights.push_back(make_area_light(*scene->shapes.back(), radiance[m]));
    scene->shapes.back()->light = scene->lights.back().get();
  }
  for (int s = 0; s < 3; ++s) {
    Vec3 c(16.f * rng.next_float() - 8.f, 16.f * rng.next_float() - 8.f, 16.f * rng.next_float() - 8.f);
    scene->shapes.push_back(std::make_unique<SphereShape>(c, 0.3f + rng.next_float(), false));
    scene->lights.push_back(make_area_light(*scene->shapes.back(), Rgb(5.f * (s + 1))));
    scene->shapes.back()->light = scene->lights.back().get();
  }
  for (int p = 0; p < 6; ++p) {
    Vec3 c(24.f * rng.next_float() - 12.f, 24.f * rng.next_float() - 12.f, 24.f * rng.next_float() - 12.f);
    scene->lights.push_back(make_point_light(c, Rgb(3.f * float(p + 1))));
  }
  if (with_environment) scene->lights.push_back(std::make_unique<ConstantLight>(Rgb(0.2f)));
  scene->finalize();
  return scene;
}

std::unique_ptr<Scene> many_lights_scene() {
  const std::string path = test::source_dir() + "/scenes/many-lights/scene.xml";
  LoadOptions options;
  return load_scene(parse_scene_file(path), options).scene;
}

std::vector<LightSampleContext> synthetic_contexts() {
  Pcg32 rng(99);
  std::vector<LightSampleContext> out;
  for (int i = 0; i < 8; ++i) {
    Vec3 p(30.f * rng.next_float() - 15.f, 30.f * rng.next_float() - 15.f, 30.f * rng.next_float() - 15.f);
    out.push_back({p, i % 4 == 3 ? Vec3(0.f) : random_unit(rng)});  // every fourth in a medium
  }
  out.push_back({Vec3(0.f), Vec3(0.f, 1.f, 0.f)});  // among the lights
  return out;
}

std::vector<LightSampleContext> many_lights_contexts() {
  const Vec3 up(0.f, 1.f, 0.f);
  return {{{0.f, 0.f, 0.f}, up},         {{-15.f, 0.f, 12.f}, up},  {{17.f, 0.f, -17.f}, up},
          {{4.f, 2.f, 3.4f}, {0.f, 0.f, -1.f}}, {{3.f, 3.f, 19.99f}, {0.f, 0.f, -1.f}},
          {{-6.f, 2.5f, -4.f}, Vec3(0.f)},  {{30.f, 0.f, 30.f}, up}};
}

constexpr int kSamples = 200000;

// Chi-square of sample_light's choices at ctx against light_pmf, with the "nothing" category; and
// the bitwise equality of the two pmfs.
void check_selection(const Scene& scene, const LightSampleContext& ctx, int test_count, const char* what) {
  const auto& lights = scene.light_sampler().lights();
  std::vector<double> probs(lights.size());
  double sum = 0;
  for (size_t i = 0; i < lights.size(); ++i) sum += probs[i] = scene.light_pmf(ctx, lights[i]);
  ASSERT_LE(sum, 1.0 + 1e-4) << what;
  std::vector<uint64_t> counts(lights.size(), 0);
  uint64_t misses = 0;
  Pcg32 rng(hash_values(uint64_t(std::bit_cast<uint32_t>(ctx.p.x)), uint64_t(std::bit_cast<uint32_t>(ctx.p.z))));
  for (int k = 0; k < kSamples; ++k) {
    float pmf = -1.f;
    const Light* l = scene.sample_light(ctx, rng.next_float(), pmf);
    if (!l) {
      ASSERT_EQ(pmf, 0.f);
      ++misses;
      continue;
    }
    ASSERT_EQ(l->selection_index < lights.size() ? lights[l->selection_index] : nullptr, l);
    ASSERT_GT(pmf, 0.f);
    ASSERT_EQ(pmf, scene.light_pmf(ctx, l)) << what << ": light " << l->selection_index;
    ++counts[l->selection_index];
  }
  auto r = test::discrete_chi2(counts, probs, misses, std::max(0.0, 1.0 - sum), 0.01, test_count);
  EXPECT_TRUE(r.passed) << what << " at (" << ctx.p.x << "," << ctx.p.y << "," << ctx.p.z << "): " << r.message;
}

TEST(LightBvh, SyntheticSelectionFollowsPmf) {
  for (bool env : {false, true}) {
    auto scene = synthetic_scene(env);
    ASSERT_EQ(scene->light_sampler().strategy(), LightSelection::Bvh);
    EXPECT_EQ(scene->light_sampler().lights().size(), 400u + 3 + 6 + (env ? 1 : 0));
    const auto ctxs = synthetic_contexts();
    for (const auto& ctx : ctxs) check_selection(*scene, ctx, int(2 * ctxs.size()), "synthetic");
  }
}

TEST(LightBvh, ManyLightsSceneSelectionFollowsPmf) {
  auto scene = many_lights_scene();
  ASSERT_GE(scene->light_sampler().lights().size(), 500u);
  const auto ctxs = many_lights_contexts();
  for (const auto& ctx : ctxs) {
    check_selection(*scene, ctx, int(ctxs.size()), "many-lights");
    double sum = 0;
    for (const Light* l : scene->light_sampler().lights()) sum += scene->light_pmf(ctx, l);
    EXPECT_GT(sum, 0.5);  // these points see some light; the tree rarely dead-ends there
  }
  EXPECT_LE(scene->light_sampler().bvh().depth(), 40);
}

TEST(LightBvh, EnvironmentGetsPbrtsFixedShare) {
  auto scene = synthetic_scene(true);
  const Light* env = scene->infinite_lights().at(0);
  for (const auto& ctx : synthetic_contexts()) EXPECT_EQ(scene->light_pmf(ctx, env), 0.5f);
}

// Whatever can send light to p must keep a non-zero probability, or light sampling alone (the
// direct integrator without BSDF samples) would be biased.
TEST(LightBvh, ImportanceNeverExcludesAReachableLight) {
  auto scene = synthetic_scene(false);
  Pcg32 rng(5);
  int reachable = 0;
  for (int c = 0; c < 40; ++c) {
    LightSampleContext ctx{{30.f * rng.next_float() - 15.f, 30.f * rng.next_float() - 15.f, 30.f * rng.next_float() - 15.f},
                           c % 5 == 0 ? Vec3(0.f) : random_unit(rng)};
    for (const Light* l : scene->light_sampler().lights()) {
      for (int k = 0; k < 8; ++k) {
        LightSample ls;
        if (!l->sample_li(ctx.p, {rng.next_float(), rng.next_float()}, ls) || ls.li.is_black()) continue;
        if (ctx.n != Vec3(0.f) && !(std::abs(dot(ls.wi, ctx.n)) > 1e-4f)) continue;
        ++reachable;
        ASSERT_GT(scene->light_pmf(ctx, l), 0.f) << "light " << l->selection_index << " context " << c;
        break;
      }
    }
  }
  EXPECT_GT(reachable, 1000);
}

TEST(LightBvh, OneSidedTriangleSeenFromBehindIsNeverChosen) {
  Scene scene;
  auto m = std::make_shared<MeshData>();
  m->positions = {{0.f, 0.f, 0.f}, {0.f, 0.f, 1.f}, {1.f, 0.f, 0.f}};  // normal +y
  m->indices = {0, 1, 2};
  scene.shapes.push_back(std::make_unique<TriangleMeshShape>(m, false, true));
  scene.lights.push_back(make_area_light(*scene.shapes[0], Rgb(1.f)));
  scene.shapes[0]->light = scene.lights[0].get();
  scene.finalize();
  const Light* tri = scene.shapes[0]->area_light(0);
  float pmf = -1.f;
  EXPECT_EQ(scene.sample_light({{0.3f, -1.f, 0.3f}, {0.f, 1.f, 0.f}}, 0.5f, pmf), nullptr);
  EXPECT_EQ(pmf, 0.f);
  EXPECT_EQ(scene.light_pmf({{0.3f, -1.f, 0.3f}, {0.f, 1.f, 0.f}}, tri), 0.f);
  EXPECT_EQ(scene.sample_light({{0.3f, 1.f, 0.3f}, {0.f, -1.f, 0.f}}, 0.5f, pmf), tri);
  EXPECT_EQ(pmf, 1.f);
  scene.set_light_selection(LightSelection::Power);  // power ignores the point
  EXPECT_EQ(scene.light_pmf({{0.3f, -1.f, 0.3f}, {0.f, 1.f, 0.f}}, tri), 1.f);
}

TEST(LightSelectionPower, PmfIsPowerOverTotalAndSamplesFollowIt) {
  auto scene = synthetic_scene(true);
  scene->set_light_selection(LightSelection::Power);
  const auto& lights = scene->light_sampler().lights();
  double total = 0;
  for (const Light* l : lights) total += std::max(l->power(), 0.f);
  for (const Light* l : lights)
    EXPECT_NEAR(scene->light_pmf({Vec3(1.f), Vec3(0.f)}, l), std::max(l->power(), 0.f) / total, 1e-7);
  check_selection(*scene, {Vec3(1.f, 2.f, 3.f), Vec3(0.f, 0.f, 1.f)}, 1, "power");
}

TEST(LightSampler, MeshesAreSplitPerTriangle) {
  auto scene = synthetic_scene(false);
  const Shape& mesh = *scene->shapes[0];
  const Light* mesh_light = mesh.light;
  ASSERT_EQ(mesh.prim_lights.size(), mesh.num_primitives());
  double power = 0;
  for (uint32_t t = 0; t < mesh.num_primitives(); ++t) {
    const Light* l = mesh.area_light(t);
    ASSERT_NE(l, mesh_light);
    EXPECT_EQ(l->scene_index, mesh_light->scene_index);
    power += l->power();
  }
  EXPECT_NEAR(power, mesh_light->power(), 1e-4 * mesh_light->power());
  EXPECT_EQ(mesh_light->selection_index, Light::kNotSelectable);
  EXPECT_EQ(scene->light_pmf({Vec3(0.f), Vec3(0.f)}, mesh_light), 0.f);
  // Spheres stay whole.
  const Shape& sphere = *scene->shapes[2];
  EXPECT_TRUE(sphere.prim_lights.empty());
  EXPECT_EQ(sphere.area_light(0), sphere.light);
  // Hits report the triangle's light.
  SurfaceInteraction si;
  si.shape = &mesh;
  si.prim = 7;
  EXPECT_EQ(si.area_light(), mesh.prim_lights[7]);
}

TEST(LightBounds, MergedConeContainsBoth) {
  Pcg32 rng(3);
  for (int i = 0; i < 2000; ++i) {
    DirectionCone a{random_unit(rng), 2.f * rng.next_float() - 1.f};
    DirectionCone b{random_unit(rng), i % 3 == 0 ? 1.f : 2.f * rng.next_float() - 1.f};
    DirectionCone m = merge(a, b);
    auto angle = [](Vec3 x, Vec3 y) { return std::acos(std::clamp(dot(x, y), -1.f, 1.f)); };
    if (m.cos_theta <= -1.f) continue;  // the whole sphere contains anything
    const float theta_m = std::acos(std::clamp(m.cos_theta, -1.f, 1.f));
    for (const auto& c : {a, b})
      ASSERT_LE(angle(m.w, c.w) + std::acos(std::clamp(c.cos_theta, -1.f, 1.f)), theta_m + 2e-3f) << i;
  }
}

TEST(LightBounds, ImportanceFallsWithDistanceAndFacing) {
  LightBounds b;
  b.bounds.extend(Vec3(-0.1f, 0.f, -0.1f));
  b.bounds.extend(Vec3(0.1f, 0.f, 0.1f));
  b.w = Vec3(0.f, -1.f, 0.f);  // facing down
  b.phi = 1.f;
  const Vec3 up(0.f, 1.f, 0.f);
  float near = b.importance({0.f, -1.f, 0.f}, up), far = b.importance({0.f, -4.f, 0.f}, up);
  EXPECT_GT(near, 0.f);
  EXPECT_NEAR(far / near, 1.f / 16.f, 0.01f);
  EXPECT_EQ(b.importance({0.f, 1.f, 0.f}, up), 0.f);  // behind a one-sided emitter
  b.two_sided = true;
  EXPECT_GT(b.importance({0.f, 1.f, 0.f}, up), 0.f);
}

}  // namespace
}  // namespace tessera

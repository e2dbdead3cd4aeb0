// The `directional` emitter: delta sampling, irradiance E cos(theta) on a plane, shadows through a
// Scene, power from the scene bounds, factory parameters and errors.
#include "render/scene_builders.h"
#include "tessera/light/directional.h"
#include "tessera/render/scene.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

TEST(DirectionalLight, SamplesTheOppositeOfItsDirection) {
  auto light = make_directional_light(Vec3(0.f, -2.f, 0.f), Rgb(1.f, 2.f, 3.f));
  EXPECT_TRUE(light->is_delta());
  EXPECT_FALSE(light->is_infinite());
  for (Vec3 p : {Vec3(0.f), Vec3(5.f, -3.f, 100.f)}) {
    LightSample ls;
    ASSERT_TRUE(light->sample_li(p, Vec2(0.3f, 0.7f), ls));
    EXPECT_EQ(ls.wi, Vec3(0.f, 1.f, 0.f));
    EXPECT_EQ(ls.li, Rgb(1.f, 2.f, 3.f));
    EXPECT_EQ(ls.pdf, 1.f);
    EXPECT_TRUE(ls.delta);
    EXPECT_EQ(ls.dist, kInfinity);
    EXPECT_GT(ls.p_light.y, p.y);
  }
  // Not reachable by BSDF sampling.
  EXPECT_EQ(light->le_env(Vec3(0.f, 1.f, 0.f)), Rgb(0.f));
  EXPECT_EQ(light->pdf_env(Vec3(0.f, 1.f, 0.f)), 0.f);
}

TEST(DirectionalLight, IrradianceOnAPlaneIsECosTheta) {
  const Rgb e(2.f, 1.f, 0.5f);
  const Vec3 n(0.f, 0.f, 1.f);
  for (float deg : {0.f, 30.f, 60.f, 85.f, 120.f}) {
    const float t = deg * kPi / 180.f;
    auto light = make_directional_light(-Vec3(std::sin(t), 0.f, std::cos(t)), e);
    LightSample ls;
    ASSERT_TRUE(light->sample_li(Vec3(0.f), Vec2(0.5f, 0.5f), ls));
    // Delta light: the estimator li |cos| / pdf is the irradiance itself.
    const float irradiance = ls.li.r * std::max(0.f, dot(ls.wi, n)) / ls.pdf;
    EXPECT_NEAR(irradiance, e.r * std::max(0.f, std::cos(t)), 1e-6f) << deg;
  }
}

TEST(DirectionalLight, PowerUsesTheSceneBoundingSphere) {
  auto light = make_directional_light(Vec3(0.f, 0.f, -1.f), Rgb(2.f));
  EXPECT_NEAR(light->power(), kPi * 2.f, 1e-5f);  // radius 1 before preprocess
  Bounds3 b;
  b.extend(Vec3(-1.f, -2.f, -2.f));
  b.extend(Vec3(1.f, 2.f, 2.f));  // half diagonal 3
  light->preprocess(b);
  EXPECT_NEAR(light->power(), kPi * 9.f * 2.f, 1e-4f);
}

TEST(DirectionalLight, ShadowsThroughTheScene) {
  // A sphere above the origin blocks light coming straight down, not light from 45 degrees.
  for (bool slanted : {false, true}) {
    Scene scene;
    test::add_sphere(scene, Vec3(0.f, 0.f, 3.f), 1.f, false, test::add_diffuse(scene, Rgb(0.5f)));
    Vec3 dir = slanted ? normalize(Vec3(-1.f, 0.f, -1.f)) : Vec3(0.f, 0.f, -1.f);
    scene.lights.push_back(make_directional_light(dir, Rgb(1.f)));
    scene.finalize();
    LightSample ls;
    ASSERT_TRUE(scene.lights[0]->sample_li(Vec3(0.f), Vec2(0.5f, 0.5f), ls));
    Ray shadow{Vec3(0.f), ls.wi};
    shadow.tmax = ls.dist;
    EXPECT_EQ(scene.transmittance(shadow), slanted ? 1.f : 0.f) << slanted;
    EXPECT_GT(scene.lights[0]->power(), kPi);  // preprocess gave it the scene's bounds
  }
}

std::unique_ptr<Light> load_directional(const std::string& body, Scene& scene, SceneDesc& desc) {
  desc = parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", "mem/directional.xml");
  LoadContext ctx(desc, LoadOptions{}, scene);
  auto node = desc.root->children_with_tag("emitter").at(0);
  return find_light_factory("directional")(*node, ctx);
}

TEST(DirectionalFactory, DirectionToWorldIrradianceAndErrors) {
  Scene scene;
  SceneDesc desc;
  LightSample ls;
  auto a = load_directional(R"(<emitter type="directional"><vector name="direction" x="0" y="0" z="-3"/>
      <rgb name="irradiance" value="1 2 3"/></emitter>)", scene, desc);
  ASSERT_TRUE(a->sample_li(Vec3(0.f), Vec2(0.f, 0.f), ls));
  EXPECT_NEAR(ls.wi.z, 1.f, 1e-6f);
  EXPECT_EQ(ls.li, Rgb(1.f, 2.f, 3.f));

  // toWorld maps local +z (the way the light travels); 0.6 spelling, default irradiance 1.
  auto b = load_directional(R"(<emitter type="directional"><transform name="toWorld">
      <rotate x="1" angle="90"/></transform></emitter>)", scene, desc);
  ASSERT_TRUE(b->sample_li(Vec3(0.f), Vec2(0.f, 0.f), ls));
  EXPECT_NEAR(ls.wi.y, 1.f, 1e-6f);  // +z rotated 90 deg about +x is -y: light comes from +y
  EXPECT_EQ(ls.li, Rgb(1.f));

  // Mitsuba 3 spelling.
  auto c = load_directional(R"(<emitter type="directional"><transform name="to_world">
      <lookat origin="0,0,0" target="1,0,0" up="0,1,0"/></transform><float name="irradiance" value="4"/></emitter>)",
                            scene, desc);
  ASSERT_TRUE(c->sample_li(Vec3(0.f), Vec2(0.f, 0.f), ls));
  EXPECT_NEAR(ls.wi.x, -1.f, 1e-5f);
  EXPECT_EQ(ls.li, Rgb(4.f));

  std::string both = test::scene_error_of([&] {
    load_directional(R"(<emitter type="directional"><vector name="direction" x="0" y="0" z="-1"/>
        <transform name="toWorld"><rotate x="1" angle="90"/></transform></emitter>)", scene, desc);
  });
  EXPECT_NE(both.find("mem/directional.xml:2"), std::string::npos) << both;
  std::string zero = test::scene_error_of([&] {
    load_directional(R"(<emitter type="directional"><vector name="direction" x="0" y="0" z="0"/></emitter>)", scene,
                     desc);
  });
  EXPECT_NE(zero.find("non-zero"), std::string::npos) << zero;
  std::string negative = test::scene_error_of([&] {
    load_directional(R"(<emitter type="directional"><float name="irradiance" value="-1"/></emitter>)", scene, desc);
  });
  EXPECT_NE(negative.find("non-negative"), std::string::npos) << negative;
}

}  // namespace
}  // namespace tessera

// Loading `envmap` and `constant` emitters from scene XML through the factory table.
#include "image/image_test_util.h"
#include "tessera/light/envmap.h"
#include "tessera/render/scene.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

struct Loaded {
  SceneDesc desc;
  Scene scene;
  std::unique_ptr<LoadContext> ctx;
  std::shared_ptr<SceneNode> emitter;
};

// Parses `body` as the content of a scene placed at `virtual_path` and returns its first emitter.
std::unique_ptr<Loaded> parse_emitter(const std::string& body, const std::string& virtual_path) {
  auto l = std::make_unique<Loaded>();
  l->desc = parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", virtual_path);
  l->ctx = std::make_unique<LoadContext>(l->desc, LoadOptions{}, l->scene);
  auto emitters = l->desc.root->children_with_tag("emitter");
  EXPECT_EQ(emitters.size(), 1u);
  l->emitter = emitters.at(0);
  return l;
}

std::unique_ptr<Light> make(Loaded& l) {
  LightFactory f = find_light_factory(l.emitter->type);
  EXPECT_NE(f, nullptr) << l.emitter->type;
  return f(*l.emitter, *l.ctx);
}

TEST(InfiniteLightFactory, EnvmapWithASpaceInItsFileNameScaleAndToWorld) {
  std::string dir = test::shared_path("scenes/living-room");
  TESSERA_REQUIRE_FILE(dir + "/textures/Sky 19.exr");
  auto l = parse_emitter(R"(<emitter type="envmap">
      <transform name="toWorld"><rotate y="1" angle="90"/></transform>
      <string name="filename" value="textures/Sky 19.exr"/>
      <float name="scale" value="2"/>
    </emitter>)",
                         dir + "/virtual.xml");
  auto light = make(*l);
  ASSERT_NE(light, nullptr);
  EXPECT_TRUE(light->is_infinite());
  for (const char* p : {"filename", "scale", "to_world"}) {
    ASSERT_NE(l->emitter->find(p), nullptr) << p;
    EXPECT_TRUE(l->emitter->find(p)->used) << p;
  }
  EnvmapLight direct(read_image(dir + "/textures/Sky 19.exr"), 2.f, Transform::rotate({0, 1, 0}, 90.f));
  for (Vec3 d : {Vec3(0, 1, 0), normalize(Vec3(1, 0.2f, 0)), normalize(Vec3(-0.3f, 0.5f, 0.8f))}) {
    Rgb a = light->le_env(d), b = direct.le_env(d);
    EXPECT_NEAR(a.r, b.r, 1e-4f * b.r + 1e-6f);
    EXPECT_NEAR(a.b, b.b, 1e-4f * b.b + 1e-6f);
    EXPECT_NEAR(light->pdf_env(d), direct.pdf_env(d), 1e-4f * direct.pdf_env(d));
  }
}

TEST(InfiniteLightFactory, EnvmapFileErrorsNameTheSceneAndTheImage) {
  auto dir = test::scratch_dir();
  std::string xml = (dir / "scene.xml").string();
  {
    auto l = parse_emitter(R"(<emitter type="envmap"><string name="filename" value="missing.exr"/></emitter>)", xml);
    try {
      make(*l);
      FAIL() << "no error for a missing envmap";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("scene.xml"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("missing.exr"), std::string::npos) << e.what();
    }
  }
  test::write_bytes(dir / "garbage.exr", "not an exr");
  {
    auto l = parse_emitter(R"(<emitter type="envmap"><string name="filename" value="garbage.exr"/></emitter>)", xml);
    try {
      make(*l);
      FAIL() << "no error for a garbage envmap";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("scene.xml:"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("garbage.exr"), std::string::npos) << e.what();
    }
  }
  write_image((dir / "tiny.exr").string(), Image(2, 2, 3));
  {
    auto l = parse_emitter(R"(<emitter type="envmap"><string name="filename" value="tiny.exr"/></emitter>)", xml);
    EXPECT_THROW(make(*l), SceneError);
  }
  {
    auto l = parse_emitter(R"(<emitter type="envmap"/>)", xml);
    EXPECT_THROW(make(*l), SceneError);
  }
}

TEST(InfiniteLightFactory, ConstantRadianceAndDefault) {
  auto dir = test::scratch_dir();
  std::string xml = (dir / "scene.xml").string();
  auto l = parse_emitter(R"(<emitter type="constant"><rgb name="radiance" value="1, 2, 3"/></emitter>)", xml);
  auto light = make(*l);
  EXPECT_EQ(light->le_env(Vec3(0, 0, 1)), Rgb(1, 2, 3));
  EXPECT_TRUE(l->emitter->find("radiance")->used);
  auto d = parse_emitter(R"(<emitter type="constant"/>)", xml);
  EXPECT_EQ(make(*d)->le_env(Vec3(1, 0, 0)), Rgb(1.f));
}

}  // namespace
}  // namespace tessera

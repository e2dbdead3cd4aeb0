// The `checkerboard` and `scale` textures.
#include "tessera/texture/bitmap.h"

#include "texture/texture_test_util.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

using test::at_uv;
using test::scene_error_of;
using test::TextureScene;

std::string in_bsdf(const std::string& texture_xml, const std::string& id = "m") {
  return "<bsdf type=\"diffuse\" id=\"" + id + "\">" + texture_xml + "</bsdf>";
}

TEST(CheckerboardTexture, DefaultColoursAndPattern) {
  TextureScene s(in_bsdf("<texture type=\"checkerboard\" name=\"reflectance\"/>"), "0.6.0");
  auto tex = s.texture("m");
  // color0 (0.4) where the half-unit cells in u and v have equal parity, color1 (0.2) elsewhere.
  EXPECT_EQ(tex->eval(at_uv(0.25f, 0.25f)), Rgb(0.4f));
  EXPECT_EQ(tex->eval(at_uv(0.75f, 0.25f)), Rgb(0.2f));
  EXPECT_EQ(tex->eval(at_uv(0.25f, 0.75f)), Rgb(0.2f));
  EXPECT_EQ(tex->eval(at_uv(0.75f, 0.75f)), Rgb(0.4f));
  EXPECT_EQ(tex->eval(at_uv(1.25f, 2.25f)), Rgb(0.4f));
  EXPECT_EQ(tex->eval(at_uv(0.5f, 0.25f)), Rgb(0.2f));  // a cell starts at its lower edge
  EXPECT_EQ(tex->eval(at_uv(-0.25f, 0.25f)), Rgb(0.2f));
  EXPECT_EQ(tex->eval(at_uv(-0.25f, -0.25f)), Rgb(0.4f));
  EXPECT_FLOAT_EQ(tex->eval_1(at_uv(0.75f, 0.25f)), 0.2f);
  EXPECT_EQ(tex->mean(), Rgb(0.3f));
}

TEST(CheckerboardTexture, ColoursAndUvScale) {
  TextureScene s(in_bsdf("<texture type=\"checkerboard\" name=\"reflectance\">"
                         "<rgb name=\"color0\" value=\"1, 0, 0\"/><rgb name=\"color1\" value=\"0, 0, 1\"/>"
                         "<float name=\"uscale\" value=\"4\"/><float name=\"vscale\" value=\"4\"/></texture>"),
                 "0.6.0");
  auto tex = s.texture("m");
  EXPECT_EQ(tex->eval(at_uv(0.05f, 0.05f)), Rgb(1, 0, 0));   // uv' = (0.2, 0.2)
  EXPECT_EQ(tex->eval(at_uv(0.15f, 0.05f)), Rgb(0, 0, 1));   // uv' = (0.6, 0.2)
  EXPECT_EQ(tex->eval(at_uv(0.15f, 0.15f)), Rgb(1, 0, 0));
  EXPECT_EQ(tex->mean(), Rgb(0.5f, 0.f, 0.5f));
}

TEST(ScaleTexture, ScalesANestedTexture) {
  TextureScene s(in_bsdf("<texture type=\"scale\" name=\"reflectance\"><float name=\"scale\" value=\"0.5\"/>"
                         "<texture type=\"checkerboard\"/></texture>"),
                 "0.6.0");
  auto tex = s.texture("m");
  EXPECT_EQ(tex->eval(at_uv(0.25f, 0.25f)), Rgb(0.2f));
  EXPECT_EQ(tex->eval(at_uv(0.75f, 0.25f)), Rgb(0.1f));
  EXPECT_FLOAT_EQ(tex->mean().g, 0.15f);
}

TEST(ScaleTexture, ValueAndSpectralScale) {
  TextureScene s(in_bsdf("<texture type=\"scale\" name=\"reflectance\"><rgb name=\"value\" value=\"0.5, 1, 2\"/>"
                         "<rgb name=\"scale\" value=\"2, 0.5, 0.25\"/></texture>"),
                 "0.6.0");
  auto tex = s.texture("m");
  EXPECT_EQ(tex->eval(at_uv(0.3f, 0.3f)), Rgb(1.f, 0.5f, 0.5f));
  EXPECT_EQ(tex->mean(), Rgb(1.f, 0.5f, 0.5f));
}

TEST(ScaleTexture, NeedsSomethingToScale) {
  TextureScene s(in_bsdf("\n<texture type=\"scale\" name=\"reflectance\"><float name=\"scale\" value=\"2\"/></texture>"),
                 "0.6.0");
  std::string msg = scene_error_of([&] { s.texture("m"); });
  EXPECT_NE(msg.find("scene.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("nested texture"), std::string::npos) << msg;
}

}  // namespace
}  // namespace tessera

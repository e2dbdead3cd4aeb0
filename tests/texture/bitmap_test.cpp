// The `bitmap` texture: texel placement and v orientation, bilinear and nearest filtering, wrap
// modes, decoding (sRGB / gamma / raw / float files), to_uv, alpha, the per-scene image cache,
// a real texture from ../shared, and errors naming file and line.
#include "tessera/texture/bitmap.h"

#include "test_support.h"
#include "texture/texture_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace tessera {
namespace {

using test::at_uv;
using test::scene_error_of;
using test::TextureScene;
using test::TextureTempDir;

// 4 x 2 texels, all different; row 0 is the file's top row.
Rgb texel_value(int x, int y) {
  float k = float(x + 10 * y + 1);
  return {k, 2.f * k, 0.5f};
}

std::string write_test_exr(const TextureTempDir& dir, bool alpha = false) {
  Image im(4, 2, alpha ? 4 : 3);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      im.set_rgb(x, y, texel_value(x, y));
      if (alpha) im.at(x, y, 3) = 0.25f * float(x);
    }
  std::string path = dir.file("grid.exr");
  write_exr(path, im);
  return path;
}

std::string bitmap_xml(const std::string& path, const std::string& extra = "", const std::string& id = "m") {
  return "<bsdf type=\"diffuse\" id=\"" + id + "\"><texture type=\"bitmap\" name=\"reflectance\">" +
         "<string name=\"filename\" value=\"" + path + "\"/>" + extra + "</texture></bsdf>";
}

const BitmapTexture& as_bitmap(const std::shared_ptr<Texture>& t) {
  auto* b = dynamic_cast<const BitmapTexture*>(t.get());
  EXPECT_NE(b, nullptr);
  return *b;
}

void expect_rgb_near(Rgb a, Rgb b, float tol = 1e-5f) {
  EXPECT_NEAR(a.r, b.r, tol);
  EXPECT_NEAR(a.g, b.g, tol);
  EXPECT_NEAR(a.b, b.b, tol);
}

TEST(BitmapTexture, TexelCentresReturnTexelsWithRowZeroAtVZero) {
  TextureTempDir dir;
  TextureScene s(bitmap_xml(write_test_exr(dir)));
  auto tex = s.texture("m");
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      expect_rgb_near(tex->eval(at_uv((float(x) + 0.5f) / 4.f, (float(y) + 0.5f) / 2.f)), texel_value(x, y));
  // Mean of all texels (k = 1..4 and 11..14).
  expect_rgb_near(tex->mean(), Rgb(7.5f, 15.f, 0.5f));
  EXPECT_NEAR(tex->eval_1(at_uv(0.125f, 0.25f)), (1.f + 2.f + 0.5f) / 3.f, 1e-5f);
}

TEST(BitmapTexture, BilinearInterpolatesBetweenTexelCentres) {
  TextureTempDir dir;
  TextureScene s(bitmap_xml(write_test_exr(dir)));
  auto tex = s.texture("m");
  // Halfway between texels (0,0) and (1,0) in u.
  expect_rgb_near(tex->eval(at_uv(0.25f, 0.25f)), (texel_value(0, 0) + texel_value(1, 0)) * 0.5f);
  // Centre of the four texels (1,0),(2,0),(1,1),(2,1).
  Rgb four = (texel_value(1, 0) + texel_value(2, 0) + texel_value(1, 1) + texel_value(2, 1)) * 0.25f;
  expect_rgb_near(tex->eval(at_uv(0.5f, 0.5f)), four);
  // A quarter of the way from (2,1) towards (3,1).
  expect_rgb_near(tex->eval(at_uv((2.5f + 0.25f) / 4.f, 0.75f)),
                  texel_value(2, 1) * 0.75f + texel_value(3, 1) * 0.25f);
}

TEST(BitmapTexture, NearestFilterPicksTheTexelUnderUv) {
  TextureTempDir dir;
  TextureScene s(bitmap_xml(write_test_exr(dir), "<string name=\"filterType\" value=\"nearest\"/>"), "0.6.0");
  auto tex = s.texture("m");
  expect_rgb_near(tex->eval(at_uv(0.26f, 0.9f)), texel_value(1, 1));
  expect_rgb_near(tex->eval(at_uv(0.24f, 0.1f)), texel_value(0, 0));
}

TEST(BitmapTexture, MipMapFiltersAreLeftForTheNeutralNoteAndUnknownOnesFail) {
  TextureTempDir dir;
  std::string path = write_test_exr(dir);
  TextureScene s(bitmap_xml(path, "<string name=\"filterType\" value=\"trilinear\"/>"), "0.6.0");
  auto tex = s.texture("m");
  const Property* p = s.desc.root->children.at(0)->children.at(0)->find("filter_type");
  ASSERT_NE(p, nullptr);
  EXPECT_FALSE(p->used);  // the loader's final walk notes it as image-neutral
  expect_rgb_near(tex->eval(at_uv(0.25f, 0.25f)), (texel_value(0, 0) + texel_value(1, 0)) * 0.5f);

  TextureScene bad(bitmap_xml(path, "\n<string name=\"filterType\" value=\"cubic\"/>"), "0.6.0");
  std::string msg = scene_error_of([&] { bad.texture("m"); });
  EXPECT_NE(msg.find("scene.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cubic"), std::string::npos) << msg;
}

TEST(BitmapTexture, WrapModes) {
  TextureTempDir dir;
  std::string path = write_test_exr(dir);
  auto make = [&](const std::string& extra) {
    return std::make_unique<TextureScene>(bitmap_xml(path, extra), "0.6.0");
  };
  float v0 = 0.25f;  // row 0 centre
  {
    auto s = make("");  // default repeat
    auto tex = s->texture("m");
    expect_rgb_near(tex->eval(at_uv(0.125f + 3.f, v0 - 2.f)), texel_value(0, 0));
    expect_rgb_near(tex->eval(at_uv(-0.125f, v0)), texel_value(3, 0));
    // At u = 0 the lookup straddles the last and the first column.
    expect_rgb_near(tex->eval(at_uv(0.f, v0)), (texel_value(3, 0) + texel_value(0, 0)) * 0.5f);
  }
  {
    auto s = make("<string name=\"wrapMode\" value=\"clamp\"/>");
    auto tex = s->texture("m");
    expect_rgb_near(tex->eval(at_uv(0.f, v0)), texel_value(0, 0));
    expect_rgb_near(tex->eval(at_uv(7.f, -3.f)), texel_value(3, 0));
  }
  {
    auto s = make("<string name=\"wrapMode\" value=\"mirror\"/>");
    auto tex = s->texture("m");
    expect_rgb_near(tex->eval(at_uv(0.f, v0)), texel_value(0, 0));
    // u = 1.3 -> texel coordinate 5.2 - 0.5: columns 4 and 5 mirror to 3 and 2.
    expect_rgb_near(tex->eval(at_uv(1.3f, v0)), texel_value(3, 0) * 0.3f + texel_value(2, 0) * 0.7f, 1e-4f);
    expect_rgb_near(tex->eval(at_uv(-0.125f, v0)), texel_value(0, 0));
  }
  {
    auto s = make("<string name=\"wrapModeU\" value=\"black\"/><string name=\"wrapModeV\" value=\"one\"/>");
    auto tex = s->texture("m");
    const auto& b = as_bitmap(tex);
    EXPECT_EQ(b.wrap_u(), WrapMode::Zero);
    EXPECT_EQ(b.wrap_v(), WrapMode::One);
    expect_rgb_near(tex->eval(at_uv(-0.5f, v0)), Rgb(0.f));
    expect_rgb_near(tex->eval(at_uv(0.125f, 1.5f)), Rgb(1.f));
    // Half of the lookup falls outside in u: half of texel (0,0).
    expect_rgb_near(tex->eval(at_uv(0.f, v0)), texel_value(0, 0) * 0.5f);
  }
  {
    TextureScene bad(bitmap_xml(path, "\n\n<string name=\"wrapMode\" value=\"wrap\"/>"), "0.6.0");
    std::string msg = scene_error_of([&] { bad.texture("m"); });
    EXPECT_NE(msg.find("scene.xml:4"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'wrap'"), std::string::npos) << msg;
  }
}

TEST(BitmapTexture, UvScaleAndOffsetOfMitsuba06) {
  TextureTempDir dir;
  std::string path = write_test_exr(dir);
  TextureScene plain(bitmap_xml(path), "0.6.0");
  TextureScene moved(bitmap_xml(path, "<float name=\"uscale\" value=\"2\"/><float name=\"vscale\" value=\"0.5\"/>"
                                      "<float name=\"uoffset\" value=\"0.25\"/><float name=\"voffset\" value=\"0.5\"/>"),
                     "0.6.0");
  auto a = plain.texture("m"), b = moved.texture("m");
  for (Vec2 uv : {Vec2(0.1f, 0.2f), Vec2(0.3f, 0.7f), Vec2(0.05f, 0.95f)}) {
    Vec2 mapped(uv.x * 2.f + 0.25f, uv.y * 0.5f + 0.5f);  // 0.6: uv * scale + offset
    expect_rgb_near(b->eval(at_uv(uv.x, uv.y)), a->eval(at_uv(mapped.x, mapped.y)));
  }
  // The mapped lookup lands on a texel centre: u = 0.0625*2+0.25 = 0.375 -> column 1, v -> row 1.
  expect_rgb_near(b->eval(at_uv(0.0625f, 0.5f)), texel_value(1, 1));
}

TEST(BitmapTexture, ToUvTransformOfMitsuba3) {
  TextureTempDir dir;
  TextureScene s(bitmap_xml(write_test_exr(dir), "<transform name=\"to_uv\"><scale x=\"0.5\" y=\"1\"/>"
                                                 "<translate x=\"0.5\" y=\"0\"/></transform>"));
  auto tex = s.texture("m");
  // u' = 0.5 u + 0.5: u = 0.25 -> 0.625, the centre of column 2.
  expect_rgb_near(tex->eval(at_uv(0.25f, 0.75f)), texel_value(2, 1));
}

TEST(BitmapTexture, EightBitDecoding) {
  TextureTempDir dir;
  // One row of stored bytes 0, 64, 128, 255 (written with gamma 1 so the bytes are exact).
  Image im(4, 1, 3);
  const int bytes[4] = {0, 64, 128, 255};
  for (int x = 0; x < 4; ++x) im.set_rgb(x, 0, Rgb(float(bytes[x]) / 255.f));
  std::string path = dir.file("ramp.png");
  write_png(path, im, LdrSettings{1.f, 0.f});

  auto value = [&](const std::string& extra, int x) {
    TextureScene s(bitmap_xml(path, extra), "0.6.0");
    return s.texture("m")->eval(at_uv((float(x) + 0.5f) / 4.f, 0.5f)).g;
  };
  for (int x = 0; x < 4; ++x) {
    float stored = float(bytes[x]) / 255.f;
    EXPECT_NEAR(value("", x), srgb_to_linear(stored), 1e-5f) << x;  // automatic: sRGB
    EXPECT_NEAR(value("<float name=\"gamma\" value=\"-1\"/>", x), srgb_to_linear(stored), 1e-5f) << x;
    EXPECT_NEAR(value("<float name=\"gamma\" value=\"1\"/>", x), stored, 1e-5f) << x;
    EXPECT_NEAR(value("<float name=\"gamma\" value=\"2.2\"/>", x), std::pow(stored, 2.2f), 1e-5f) << x;
    EXPECT_NEAR(value("<boolean name=\"raw\" value=\"true\"/>", x), stored, 1e-5f) << x;
  }
  EXPECT_NE(srgb_to_linear(64.f / 255.f), 64.f / 255.f);  // the cases above are distinguishable

  TextureScene bad(bitmap_xml(path, "\n<float name=\"gamma\" value=\"-2\"/>"), "0.6.0");
  std::string msg = scene_error_of([&] { bad.texture("m"); });
  EXPECT_NE(msg.find("scene.xml:3"), std::string::npos) << msg;
}

TEST(BitmapTexture, FloatFilesAreLinearUnlessGammaSaysOtherwise) {
  TextureTempDir dir;
  std::string path = write_test_exr(dir);
  TextureScene lin(bitmap_xml(path), "0.6.0");
  TextureScene g2(bitmap_xml(path, "<float name=\"gamma\" value=\"2\"/>"), "0.6.0");
  SurfaceInteraction si = at_uv(0.375f, 0.25f);
  expect_rgb_near(lin.texture("m")->eval(si), texel_value(1, 0));
  Rgb t = texel_value(1, 0);
  expect_rgb_near(g2.texture("m")->eval(si), t * t);
}

TEST(BitmapTexture, AlphaChannelIsKeptAndNotDecoded) {
  TextureTempDir dir;
  TextureScene s(bitmap_xml(write_test_exr(dir, true)));
  const auto& b = as_bitmap(s.texture("m"));
  EXPECT_TRUE(b.texels()->has_alpha());
  EXPECT_NEAR(b.alpha(at_uv(0.625f, 0.25f)), 0.5f, 1e-6f);
  EXPECT_NEAR(b.alpha(at_uv(0.5f, 0.25f)), 0.375f, 1e-6f);  // filtered like colour
  expect_rgb_near(b.eval(at_uv(0.625f, 0.25f)), texel_value(2, 0));

  // 8-bit RGBA: colour decoded from sRGB, alpha stays as stored.
  Image im(1, 1, 4);
  im.set_rgb(0, 0, Rgb(0.5f));
  im.at(0, 0, 3) = 0.5f;
  std::string png = dir.file("rgba.png");
  write_png(png, im, LdrSettings{1.f, 0.f});
  TextureScene p(bitmap_xml(png));
  const auto& pb = as_bitmap(p.texture("m"));
  float stored = std::round(0.5f * 255.f) / 255.f;
  EXPECT_NEAR(pb.alpha(at_uv(0.5f, 0.5f)), stored, 1e-5f);
  EXPECT_NEAR(pb.eval(at_uv(0.5f, 0.5f)).r, srgb_to_linear(stored), 1e-5f);

  // Without alpha the mask is opaque.
  TextureScene opaque(bitmap_xml(write_test_exr(dir)));
  EXPECT_EQ(as_bitmap(opaque.texture("m")).alpha(at_uv(0.3f, 0.3f)), 1.f);
}

TEST(BitmapTexture, EachFileIsDecodedOncePerScene) {
  TextureTempDir dir;
  std::string path = write_test_exr(dir);
  TextureScene s(bitmap_xml(path, "", "a") + bitmap_xml(path, "<string name=\"wrapMode\" value=\"clamp\"/>", "b") +
                 bitmap_xml(path, "<float name=\"gamma\" value=\"2\"/>", "c"));
  auto a = s.texture("a"), b = s.texture("b");
  EXPECT_NE(a, b);  // two texture nodes, two textures...
  EXPECT_EQ(as_bitmap(a).texels(), as_bitmap(b).texels());  // ...one decoded image
  auto c = s.texture("c");  // other decoding: another image
  EXPECT_NE(as_bitmap(c).texels(), as_bitmap(a).texels());
  EXPECT_EQ(s.ctx.num_resources<DecodedBitmap>(), 2u);
}

TEST(BitmapTexture, RealSceneTextureLoadsAsSrgb) {
  std::string path = test::shared_path("scenes/bathroom/textures/wood.jpg");
  TESSERA_REQUIRE_FILE(path);
  TextureScene s(bitmap_xml(path, "<string name=\"filterType\" value=\"trilinear\"/>"), "0.6.0");
  const auto& b = as_bitmap(s.texture("m"));
  Image stored = read_image(path);
  ASSERT_EQ(b.texels()->width(), stored.width());
  ASSERT_EQ(b.texels()->height(), stored.height());
  EXPECT_TRUE(stored.srgb_encoded());
  EXPECT_EQ(b.texels()->format(), TexelStorage::Format::U8);  // 8-bit file: 8-bit texels
  int x = stored.width() / 3, y = stored.height() / 5;
  Vec2 uv((float(x) + 0.5f) / float(stored.width()), (float(y) + 0.5f) / float(stored.height()));
  expect_rgb_near(b.eval(at_uv(uv.x, uv.y)), stored.linearized().rgb(x, y), 1e-4f);
  Rgb m = b.mean();
  EXPECT_GT(m.average(), 0.f);
  EXPECT_LT(m.max_value(), 1.f);
}

TEST(BitmapTexture, SharedSceneLoadsWithoutUnsupportedBitmapItems) {
  TextureTempDir dir;
  std::string path = write_test_exr(dir);
  std::string body = bitmap_xml(path, "<string name=\"filterType\" value=\"ewa\"/><float name=\"maxAnisotropy\" value=\"8\"/>") +
                     "<shape type=\"rectangle\"><ref id=\"m\"/></shape>";
  SceneDesc desc = parse_scene_string("<scene version=\"0.6.0\">" + body + "</scene>", "mem/scene.xml");
  LoadResult r = load_scene(desc, LoadOptions{});  // throws UnsupportedError if anything is left
  ASSERT_NE(r.scene, nullptr);
  EXPECT_EQ(r.scene->textures.size(), 1u);
}

TEST(BitmapTexture, ErrorsNameFileAndLine) {
  TextureScene missing(bitmap_xml("no_such_texture.png"), "0.6.0", "dir/scene.xml");
  std::string msg = scene_error_of([&] { missing.texture("m"); });
  EXPECT_NE(msg.find("no_such_texture.png"), std::string::npos) << msg;
  EXPECT_NE(msg.find("dir/scene.xml:2"), std::string::npos) << msg;

  TextureScene no_name("<bsdf type=\"diffuse\" id=\"m\">\n<texture type=\"bitmap\" name=\"reflectance\"/></bsdf>");
  msg = scene_error_of([&] { no_name.texture("m"); });
  EXPECT_NE(msg.find("scene.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("filename"), std::string::npos) << msg;

  TextureTempDir dir;
  std::string garbage = dir.file("broken.png");
  { std::ofstream(garbage) << "not a png"; }
  TextureScene broken(bitmap_xml(garbage));
  msg = scene_error_of([&] { broken.texture("m"); });
  EXPECT_NE(msg.find("scene.xml:2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("broken.png"), std::string::npos) << msg;
}

}  // namespace
}  // namespace tessera

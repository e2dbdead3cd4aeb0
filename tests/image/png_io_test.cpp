#include "image/image_test_util.h"
#include "tessera/image/image.h"
#include "tessera/scene/error.h"
#include "test_support.h"

#include <gtest/gtest.h>
// stb's implementation is in libstb (linked through tessera_common); only its declarations here.
#include <stb/stb_image_write.h>

#include <cmath>

namespace tessera {
namespace {

using test::scratch_dir;

TEST(LdrEncoding, SrgbCurveGammaExposureClampAndRounding) {
  LdrSettings srgb;
  EXPECT_EQ(to_ldr_byte(0.f, srgb), 0);
  EXPECT_EQ(to_ldr_byte(1.f, srgb), 255);
  EXPECT_EQ(to_ldr_byte(7.f, srgb), 255);
  EXPECT_EQ(to_ldr_byte(-1.f, srgb), 0);
  EXPECT_EQ(to_ldr_byte(std::nanf(""), srgb), 0);
  EXPECT_EQ(to_ldr_byte(0.5f, srgb), 188);  // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 187.5 -> 188
  // Round to nearest: just below and above the midpoint between codes 100 and 101.
  EXPECT_EQ(to_ldr_byte(srgb_to_linear(100.45f / 255.f), srgb), 100);
  EXPECT_EQ(to_ldr_byte(srgb_to_linear(100.55f / 255.f), srgb), 101);
  // Linear segment of the sRGB curve.
  EXPECT_EQ(to_ldr_byte(0.002f, srgb), int(std::floor(0.002f * 12.92f * 255.f + 0.5f)));

  LdrSettings gamma22{2.2f, 0.f};
  EXPECT_EQ(to_ldr_byte(0.5f, gamma22), 186);  // 0.5^(1/2.2) = 0.7297 -> 186.08
  LdrSettings plus_one{-1.f, 1.f};
  EXPECT_EQ(to_ldr_byte(0.25f, plus_one), 188);  // exposure +1 stop doubles
  LdrSettings minus_two{-1.f, -2.f};
  EXPECT_EQ(to_ldr_byte(2.f, minus_two), 188);
}

TEST(PngIo, WriteThenReadBackGivesTheEncodedBytes) {
  auto dir = scratch_dir();
  Image img = test::test_pattern(17, 9, 3, 5, /*allow_negative=*/true);
  img.at(0, 0, 0) = 0.5f;
  std::string path = (dir / "out.png").string();
  write_image(path, img);
  Image back = read_image(path);
  ASSERT_EQ(back.width(), 17);
  ASSERT_EQ(back.height(), 9);
  ASSERT_EQ(back.channels(), 3);
  EXPECT_TRUE(back.srgb_encoded());
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 17; ++x)
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(back.at(x, y, c), to_ldr_byte(img.at(x, y, c), {}) / 255.f) << x << "," << y << "," << c;
  // Linearised, values in (0,1) come back to within half a code step.
  Image lin = back.linearized();
  EXPECT_FALSE(lin.srgb_encoded());
  EXPECT_NEAR(lin.at(0, 0, 0), 0.5f, 0.003f);
}

TEST(PngIo, GammaAndExposureSettingsAreApplied) {
  auto dir = scratch_dir();
  Image img(1, 1, 3);
  img.set_rgb(0, 0, Rgb(0.5f, 0.25f, 0.125f));
  std::string path = (dir / "g.png").string();
  LdrSettings s{2.2f, 1.f};
  write_png(path, img, s);
  Image back = read_stb(path);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(back.at(0, 0, c), to_ldr_byte(img.at(0, 0, c), s) / 255.f);
  EXPECT_EQ(back.at(0, 0, 0), 1.f);  // 0.5 * 2 = 1
}

TEST(PngIo, AlphaIsWrittenLinearlyAndGreyStaysGrey) {
  auto dir = scratch_dir();
  Image rgba(2, 1, 4);
  rgba.set_rgb(0, 0, Rgb(0.5f));
  rgba.at(0, 0, 3) = 0.5f;
  rgba.at(1, 0, 3) = 1.f;
  std::string p4 = (dir / "rgba.png").string();
  write_png(p4, rgba);
  Image back = read_image(p4);
  ASSERT_EQ(back.channels(), 4);
  EXPECT_EQ(back.at(0, 0, 3), 128.f / 255.f);
  EXPECT_EQ(back.at(0, 0, 0), 188.f / 255.f);
  // linearized() leaves alpha alone.
  EXPECT_EQ(back.linearized().at(0, 0, 3), 128.f / 255.f);

  Image grey(3, 2, 1);
  grey.at(1, 1, 0) = 1.f;
  std::string p1 = (dir / "grey.png").string();
  write_png(p1, grey);
  Image gback = read_image(p1);
  ASSERT_EQ(gback.channels(), 1);
  EXPECT_EQ(gback.at(1, 1, 0), 1.f);
  EXPECT_EQ(gback.at(0, 0, 0), 0.f);
}

TEST(StbIo, ReadsBmpTgaAndJpeg) {
  auto dir = scratch_dir();
  const int w = 8, h = 4;
  std::vector<unsigned char> px(w * h * 3);
  for (size_t i = 0; i < px.size(); ++i) px[i] = (unsigned char)((i * 37) % 256);
  std::string bmp = (dir / "a.bmp").string(), tga = (dir / "a.TGA").string(), jpg = (dir / "a.jpg").string();
  ASSERT_TRUE(stbi_write_bmp(bmp.c_str(), w, h, 3, px.data()));
  ASSERT_TRUE(stbi_write_tga(tga.c_str(), w, h, 3, px.data()));
  ASSERT_TRUE(stbi_write_jpg(jpg.c_str(), w, h, 3, px.data(), 95));
  for (const auto& p : {bmp, tga}) {
    Image img = read_image(p);
    ASSERT_EQ(img.width(), w);
    ASSERT_EQ(img.height(), h);
    ASSERT_EQ(img.channels(), 3);
    EXPECT_TRUE(img.srgb_encoded());
    for (size_t i = 0; i < px.size(); ++i) ASSERT_EQ(img.data()[i], px[i] / 255.f) << p << " value " << i;
  }
  Image j = read_image(jpg);
  EXPECT_EQ(j.width(), w);
  EXPECT_EQ(j.height(), h);
}

TEST(StbIo, ReadsRadianceHdr) {
  std::string path = test::shared_path("scenes/envmaps/bitterli_envmap.hdr");
  TESSERA_REQUIRE_FILE(path);
  Image img = read_image(path);
  EXPECT_GT(img.width(), 0);
  EXPECT_EQ(img.width(), 2 * img.height());  // a latitude-longitude map
  EXPECT_EQ(img.channels(), 3);
  EXPECT_FALSE(img.srgb_encoded());
  double sum = 0, max = 0;
  for (float v : img.values()) {
    ASSERT_TRUE(std::isfinite(v));
    ASSERT_GE(v, 0.f);
    sum += v;
    max = std::max(max, double(v));
  }
  EXPECT_GT(sum, 0.0);
  EXPECT_GT(max, 1.0);  // HDR: values beyond the LDR range survive
}

TEST(StbIo, HdrWriteRoundTripWithinRgbePrecision) {
  auto dir = scratch_dir();
  Image img = test::test_pattern(6, 3, 3, 9, /*allow_negative=*/false);
  std::string path = (dir / "x.hdr").string();
  write_image(path, img);
  Image back = read_image(path);
  ASSERT_EQ(back.width(), 6);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 6; ++x) {
      // RGBE keeps 8 mantissa bits relative to the pixel's largest channel.
      float m = img.rgb(x, y).max_value();
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(back.at(x, y, c), img.at(x, y, c), m / 128.f + 1e-30f);
    }
}

}  // namespace
}  // namespace tessera

// Compact bitmap texels against the all-float path they replace: for 8-bit PNG, 16-bit PNG, half
// EXR and float EXR files written here, a texture loaded through the scene loader must give the
// values of a float texture made from decode_bitmap_values(read_image(file)) — bit for bit for
// 8-bit and float files, within half precision for 16-bit and half files — for every wrap mode,
// both filters, a rotated and scaled to_uv, every channel, alpha, the gradient and the mean.
#include "tessera/image/packed_image.h"
#include "tessera/texture/bitmap.h"

#include "texture/test_image_files.h"
#include "texture/texture_test_util.h"

#include <gtest/gtest.h>

#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace tessera {
namespace {

using test::at_uv;
using test::TextureScene;
using test::TextureTempDir;

constexpr int kW = 11, kH = 7;  // odd sizes: mirror and repeat wrap at different texels

// 8-bit codes covering 0..255 in every channel (kW*kH*4 = 308 values, a permutation of codes).
std::string write_png8(const TextureTempDir& dir, int channels) {
  Image im(kW, kH, channels);
  for (size_t i = 0; i < im.values().size(); ++i) im.data()[i] = float((i * 97 + 13) % 256) / 255.f;
  const std::string path = dir.file("codes8_" + std::to_string(channels) + ".png");
  write_png(path, im, LdrSettings{1.f, 0.f});  // gamma 1: the codes are written as given
  return path;
}

// 16-bit codes spread over the range, small ones included (subnormal halves after sRGB decoding).
std::string write_png16_file(const TextureTempDir& dir) {
  std::vector<uint16_t> codes(size_t(kW * kH * 4));
  for (size_t i = 0; i < codes.size(); ++i) codes[i] = uint16_t(i < 4 ? i : (i * 40503u + 7u) % 65536u);
  const std::string path = dir.file("codes16.png");
  test::write_png16(path, kW, kH, 4, codes);
  return path;
}

// Positive values over 31 octaves (half subnormals included), as half.
std::string write_half_file(const TextureTempDir& dir) {
  std::vector<float> v(size_t(kW * kH * 4));
  for (size_t i = 0; i < v.size(); ++i) v[i] = std::exp2(float(int(i % 31) - 20)) * (1.f + float(i % 11) / 11.f);
  const std::string path = dir.file("half.exr");
  test::write_half_exr(path, kW, kH, 4, v);
  return path;
}

std::string write_float_file(const TextureTempDir& dir) {
  Image im(kW, kH, 4);
  for (size_t i = 0; i < im.values().size(); ++i) im.data()[i] = 0.37f * float(i % 23) + 1e-3f * float(i);
  const std::string path = dir.file("float.exr");
  write_exr(path, im);
  return path;
}

std::string bitmap_xml(const std::string& path, const std::string& extra) {
  return "<bsdf type=\"diffuse\" id=\"m\"><texture type=\"bitmap\" name=\"reflectance\">"
         "<string name=\"filename\" value=\"" + path + "\"/>"
         "<transform name=\"to_uv\"><rotate z=\"1\" angle=\"23\"/><scale x=\"1.7\" y=\"-0.8\"/>"
         "<translate x=\"0.31\" y=\"0.12\"/></transform>" + extra + "</texture></bsdf>";
}

// How far the compact value may be from the float one: 0 for exact storage; for half, half's
// rounding (at most 2^-12 relative, 2^-25 absolute below half's normal range) with a margin.
struct Tolerance {
  float relative = 0.f, absolute = 0.f;
  bool ok(float got, float want) const {
    if (relative == 0.f && absolute == 0.f) return got == want || (std::isnan(got) && std::isnan(want));
    return std::abs(got - want) <= relative * std::abs(want) + absolute;
  }
};
constexpr Tolerance kExact{};
constexpr Tolerance kHalf{0x1p-11f, 0x1p-24f};

// Counts mismatches over many look-ups and reports the first few.
struct Checker {
  Tolerance tol;
  std::string what;
  int failures = 0;
  void expect(float got, float want, const std::string& where, float scale = 1.f) {
    Tolerance t = tol;
    t.absolute *= scale;
    if (t.ok(got, want)) return;
    if (++failures <= 5) ADD_FAILURE() << what << " " << where << ": got " << got << ", float path " << want;
  }
};

void compare_textures(const BitmapTexture& compact, const BitmapTexture& ref, Checker& check, float grad_tol) {
  for (int j = 0; j < 29; ++j)
    for (int i = 0; i < 31; ++i) {
      // A grid over [-1.4, 2.4]^2 that also crosses texel centres and edges after the mapping.
      const float u = -1.4f + 3.8f * float(i) / 30.f, v = -1.4f + 3.8f * float(j) / 28.f;
      const SurfaceInteraction si = at_uv(u, v);
      const std::string at = "at uv (" + std::to_string(u) + ", " + std::to_string(v) + ")";
      const Rgb a = compact.eval(si), b = ref.eval(si);
      for (int c = 0; c < 3; ++c) check.expect(a[c], b[c], "eval[" + std::to_string(c) + "] " + at);
      check.expect(compact.eval_1(si), ref.eval_1(si), "eval_1 " + at);
      check.expect(compact.alpha(si), ref.alpha(si), "alpha " + at);
      for (int c = 0; c < 4; ++c)
        check.expect(compact.lookup_channel(Vec2(u, v), c), ref.lookup_channel(Vec2(u, v), c),
                     "lookup_channel " + std::to_string(c) + " " + at);
      const Vec2 ga = compact.eval_1_gradient(si), gb = ref.eval_1_gradient(si);
      if (grad_tol == 0.f) {
        check.expect(ga.x, gb.x, "gradient u " + at);
        check.expect(ga.y, gb.y, "gradient v " + at);
      } else if (std::abs(ga.x - gb.x) > grad_tol || std::abs(ga.y - gb.y) > grad_tol) {
        if (++check.failures <= 5) ADD_FAILURE() << check.what << " gradient " << at;
      }
    }
  const Rgb ma = compact.mean(), mb = ref.mean();
  for (int c = 0; c < 3; ++c) check.expect(ma[c], mb[c], "mean");
}

struct Decoding {
  std::string xml;  // parameters as a scene writes them
  float gamma;
  bool raw;
  int channel;
};

const std::vector<Decoding>& decodings() {
  static const std::vector<Decoding> d = {
      {"", 0.f, false, -1},
      {"<float name=\"gamma\" value=\"-1\"/>", -1.f, false, -1},
      {"<float name=\"gamma\" value=\"2.2\"/>", 2.2f, false, -1},
      {"<float name=\"gamma\" value=\"1\"/>", 1.f, false, -1},
      {"<boolean name=\"raw\" value=\"true\"/>", 0.f, true, -1},
      {"<string name=\"channel\" value=\"a\"/>", 0.f, false, 3},
      {"<string name=\"channel\" value=\"g\"/><float name=\"gamma\" value=\"2.2\"/>", 2.2f, false, 1},
  };
  return d;
}

// The float path as the bitmap factory took it before compact storage: decode, cut out the
// channel, read non-finite values as 0.
Image reference(const Image& stored, const Decoding& d) {
  Image ref = decode_bitmap_values(stored, d.gamma, d.raw);
  if (d.channel >= 0) ref = extract_channel(ref, d.channel);
  for (float* v = ref.data(), *end = v + ref.values().size(); v != end; ++v)
    if (!std::isfinite(*v)) *v = 0.f;
  return ref;
}

// Every decoding x wrap mode x filter: the compact texture against the float one.
void check_file(const std::string& path, Tolerance tol, TexelStorage::Format expected_format) {
  const Image stored = read_image(path);
  float max_value = 0.f;
  for (const Decoding& d : decodings()) {
    if (d.channel == 3 && !stored.has_alpha()) continue;
    const Image ref = reference(stored, d);
    for (float v : ref.values()) max_value = std::max(max_value, std::abs(v));
    // Decoded values past half's range (gamma 2.2 on a bright half file) keep the image float.
    const bool past_half = std::any_of(ref.values().begin(), ref.values().end(),
                                       [](float v) { return std::abs(v) > 65504.f; });
    const TexelStorage::Format format = past_half ? TexelStorage::Format::F32 : expected_format;
    auto ref_image = std::make_shared<const Image>(ref);
    for (const char* wrap : {"repeat", "mirror", "clamp", "zero", "one"})
      for (const char* filter : {"bilinear", "nearest"}) {
        const std::string extra = d.xml + "<string name=\"wrap_mode\" value=\"" + wrap + "\"/>" +
                                  "<string name=\"filter_type\" value=\"" + filter + "\"/>";
        TextureScene s(bitmap_xml(path, extra));
        auto tex = s.texture("m");
        const auto& compact = dynamic_cast<const BitmapTexture&>(*tex);
        ASSERT_EQ(compact.texels()->format(), format) << path << " " << d.xml;
        ASSERT_EQ(compact.texels()->channels(), ref.channels()) << path;
        const Property* to_uv = s.desc.root->children.at(0)->children.at(0)->peek("to_uv");
        ASSERT_NE(to_uv, nullptr);
        const BitmapTexture want(ref_image, compact.wrap_u(), compact.wrap_v(),
                                 std::string(filter) == "nearest" ? TextureFilter::Nearest : TextureFilter::Bilinear,
                                 UvMapping(to_uv->xf));
        Checker check{tol, path + " [" + d.xml + " " + wrap + " " + filter + "]"};
        // The gradient multiplies texel differences by the resolution and the mapping's scale.
        const float grad_tol = tol.relative == 0.f ? 0.f : 4.f * tol.relative * max_value * float(kW + kH) * 2.f;
        compare_textures(compact, want, check, grad_tol);
        EXPECT_EQ(check.failures, 0) << check.what;
      }
  }
}

TEST(CompactBitmap, EightBitPngGivesTheFloatPathBitForBit) {
  TextureTempDir dir;
  check_file(write_png8(dir, 4), kExact, TexelStorage::Format::U8);
  check_file(write_png8(dir, 3), kExact, TexelStorage::Format::U8);
}

TEST(CompactBitmap, EightBitGreyPngGivesTheFloatPathBitForBit) {
  TextureTempDir dir;
  const std::string path = write_png8(dir, 1);
  const Image stored = read_image(path);
  for (const Decoding& d : decodings()) {
    if (d.channel == 3) continue;  // a grey file has no alpha to take
    const Image ref = reference(stored, d);
    TextureScene s(bitmap_xml(path, d.xml));
    const auto& compact = dynamic_cast<const BitmapTexture&>(*s.texture("m"));
    const BitmapTexture want(std::make_shared<const Image>(ref), WrapMode::Repeat, WrapMode::Repeat,
                             TextureFilter::Bilinear, UvMapping(s.desc.root->children[0]->children[0]->peek("to_uv")->xf));
    Checker check{kExact, "grey " + d.xml};
    compare_textures(compact, want, check, 0.f);
    EXPECT_EQ(check.failures, 0) << check.what;
  }
}

TEST(CompactBitmap, SixteenBitPngIsWithinHalfPrecision) {
  TextureTempDir dir;
  check_file(write_png16_file(dir), kHalf, TexelStorage::Format::Half);
}

TEST(CompactBitmap, HalfExrIsWithinHalfPrecision) {
  TextureTempDir dir;
  check_file(write_half_file(dir), kHalf, TexelStorage::Format::Half);
}

TEST(CompactBitmap, FloatExrGivesTheFloatPathBitForBit) {
  TextureTempDir dir;
  check_file(write_float_file(dir), kExact, TexelStorage::Format::F32);
}

TEST(CompactBitmap, TexelsTakeTheFileBitDepth) {
  TextureTempDir dir;
  struct Case {
    std::string path;
    size_t bytes_per_value;
  };
  for (const Case& c : {Case{write_png8(dir, 4), 1}, Case{write_png8(dir, 3), 1}, Case{write_png16_file(dir), 2},
                        Case{write_half_file(dir), 2}, Case{write_float_file(dir), 4}}) {
    TextureScene s(bitmap_xml(c.path, ""));
    const auto& t = *dynamic_cast<const BitmapTexture&>(*s.texture("m")).texels();
    const size_t values = size_t(kW * kH * t.channels());
    const size_t tables = t.format() == TexelStorage::Format::U8 ? 2 * 256 * sizeof(float) : 0;
    EXPECT_EQ(t.bytes(), values * c.bytes_per_value + tables) << c.path;
    EXPECT_EQ(t.float_bytes(), values * sizeof(float)) << c.path;
  }
}

TEST(CompactBitmap, HalfValuesPastHalfRangeStayFloat) {
  // gamma 3 on a half file with values near half's maximum would overflow half: kept as float.
  TextureTempDir dir;
  std::vector<float> v(size_t(2 * 2 * 3), 60000.f);
  const std::string path = dir.file("big.exr");
  test::write_half_exr(path, 2, 2, 3, v);
  TextureScene s(bitmap_xml(path, "<float name=\"gamma\" value=\"3\"/>"));
  const auto& t = *dynamic_cast<const BitmapTexture&>(*s.texture("m")).texels();
  EXPECT_EQ(t.format(), TexelStorage::Format::F32);
  EXPECT_EQ(t.at(0, 0, 0), std::pow(60000.f, 3.f));
}

TEST(PackedImage, KeepsTheFileValuesAndWidensAsReadImage) {
  TextureTempDir dir;
  const PackedImage p8 = read_packed_image(write_png8(dir, 4));
  ASSERT_EQ(p8.format, PixelFormat::U8);
  for (size_t i = 0; i < p8.u8.size(); ++i) ASSERT_EQ(p8.u8[i], (i * 97 + 13) % 256) << i;
  EXPECT_EQ(p8.to_image().values()[5], float(p8.u8[5]) / 255.f);

  const std::string png16 = write_png16_file(dir);
  const PackedImage p16 = read_packed_image(png16);
  ASSERT_EQ(p16.format, PixelFormat::U16);
  EXPECT_EQ(p16.u16[2], 2);
  EXPECT_EQ(p16.u16[100], (100u * 40503u + 7u) % 65536u);
  EXPECT_TRUE(p16.srgb_encoded);

  // OpenEXR's own widening (read_exr reads into float slices) against ours.
  for (const std::string& exr : {write_half_file(dir), write_float_file(dir)}) {
    const PackedImage p = read_packed_image(exr);
    EXPECT_EQ(p.format, exr == dir.file("half.exr") ? PixelFormat::Half : PixelFormat::F32);
    EXPECT_TRUE(p.to_image().values() == read_exr(exr).values()) << exr;
  }
}

TEST(HalfFloat, PortableConversionMatchesImathForEveryHalf) {
  for (uint32_t h = 0; h < 65536; ++h) {
    Imath::half half_value;
    half_value.setBits(uint16_t(h));
    const float want = float(half_value);
    for (float got : {half_to_float_portable(uint16_t(h)), half_to_float(uint16_t(h))}) {
      if (std::isnan(want)) {
        ASSERT_TRUE(std::isnan(got)) << h;
        continue;
      }
      uint32_t a, b;
      std::memcpy(&a, &got, 4);
      std::memcpy(&b, &want, 4);
      ASSERT_EQ(a, b) << "half bits " << h;
    }
  }
}

}  // namespace
}  // namespace tessera

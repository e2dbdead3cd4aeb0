// 8-bit output through stb_image_write (PNG) and everything stb_image reads (PNG, JPEG, TGA, BMP,
// Radiance .hdr), plus Radiance .hdr output. stb's implementation is compiled into libstb.
#include "tessera/image/image.h"
#include "tessera/image/packed_image.h"

#include "image/io_util.h"

#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

namespace tessera {

namespace {

using image_detail::fail;

std::string stb_reason() {
  const char* r = stbi_failure_reason();
  return r ? r : "unknown error";
}

struct StbFree {
  void operator()(void* p) const { stbi_image_free(p); }
};

}  // namespace

uint8_t to_ldr_byte(float linear, const LdrSettings& settings) {
  float v = linear * std::exp2(settings.exposure);
  if (!(v > 0.f)) return 0;  // negatives and NaN
  if (v >= 1.f) return 255;
  float e = settings.gamma < 0.f ? linear_to_srgb(v) : std::pow(v, 1.f / settings.gamma);
  e = std::clamp(e, 0.f, 1.f);
  return uint8_t(std::floor(e * 255.f + 0.5f));
}

void write_png(const std::string& path, const Image& image_in, const LdrSettings& settings) {
  if (image_in.empty()) fail(path, "cannot write an empty image");
  const Image image = image_in.srgb_encoded() ? image_in.linearized() : image_in;
  int n = image.channels();
  std::vector<uint8_t> bytes(image.num_pixels() * size_t(n));
  const float* src = image.data();
  for (size_t i = 0; i < image.num_pixels(); ++i)
    for (int c = 0; c < n; ++c) {
      float v = src[i * size_t(n) + size_t(c)];
      uint8_t b;
      if (c == 3) b = std::isfinite(v) ? uint8_t(std::floor(std::clamp(v, 0.f, 1.f) * 255.f + 0.5f)) : 0;
      else b = to_ldr_byte(v, settings);
      bytes[i * size_t(n) + size_t(c)] = b;
    }
  if (!stbi_write_png(path.c_str(), image.width(), image.height(), n, bytes.data(), image.width() * n))
    fail(path, "cannot write PNG");
}

void write_hdr(const std::string& path, const Image& image_in) {
  if (image_in.empty()) fail(path, "cannot write an empty image");
  const Image image = image_in.srgb_encoded() ? image_in.linearized() : image_in;
  const Image rgb = image.channels() == 3 ? image : image.to_rgb();
  if (!stbi_write_hdr(path.c_str(), rgb.width(), rgb.height(), 3, rgb.data()))
    fail(path, "cannot write Radiance HDR");
}

namespace {

// stb's n channels -> ours: grey+alpha becomes RGBA (grey replicated), others stay.
int stored_channels(int n) { return n == 1 ? 1 : (n == 3 ? 3 : 4); }

template <typename T>
std::vector<T> expand_channels(const T* src, size_t pixels, int n, T opaque) {
  const int channels = stored_channels(n);
  if (channels == n) return std::vector<T>(src, src + pixels * size_t(n));
  std::vector<T> out(pixels * size_t(channels));
  for (size_t i = 0; i < pixels; ++i) {
    T px[4] = {0, 0, 0, opaque};
    for (int c = 0; c < n; ++c) px[c] = src[i * size_t(n) + size_t(c)];
    if (n == 2) px[3] = px[1], px[1] = px[2] = px[0];
    for (int c = 0; c < channels; ++c) out[i * size_t(channels) + size_t(c)] = px[c];
  }
  return out;
}

}  // namespace

PackedImage read_stb_packed(const std::string& path) {
  image_detail::require_readable_file(path);
  int w = 0, h = 0, n = 0;
  PackedImage img;
  if (stbi_is_hdr(path.c_str())) {
    std::unique_ptr<float, StbFree> data(stbi_loadf(path.c_str(), &w, &h, &n, 0));
    if (!data) fail(path, "cannot read image: " + stb_reason());
    img.width = w, img.height = h, img.channels = stored_channels(n), img.format = PixelFormat::F32;
    img.f32 = expand_channels(data.get(), img.num_pixels(), n, 1.f);
    return img;
  }
  if (stbi_is_16_bit(path.c_str())) {
    std::unique_ptr<uint16_t, StbFree> data(stbi_load_16(path.c_str(), &w, &h, &n, 0));
    if (!data) fail(path, "cannot read image: " + stb_reason());
    img.width = w, img.height = h, img.channels = stored_channels(n), img.format = PixelFormat::U16;
    img.u16 = expand_channels(data.get(), img.num_pixels(), n, uint16_t(65535));
  } else {
    std::unique_ptr<uint8_t, StbFree> data(stbi_load(path.c_str(), &w, &h, &n, 0));
    if (!data) fail(path, "cannot read image: " + stb_reason());
    img.width = w, img.height = h, img.channels = stored_channels(n), img.format = PixelFormat::U8;
    img.u8 = expand_channels(data.get(), img.num_pixels(), n, uint8_t(255));
  }
  img.srgb_encoded = true;
  return img;
}

Image read_stb(const std::string& path) { return read_stb_packed(path).to_image(); }

}  // namespace tessera

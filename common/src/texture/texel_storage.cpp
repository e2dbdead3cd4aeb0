// Building compact texel storage from a file's stored values. The 8-bit tables come from running
// every code through decode_bitmap_values, so they cannot drift from the float path.
#include "tessera/texture/texel_storage.h"

#include "tessera/texture/bitmap_decode.h"

#include <Imath/half.h>

#include <algorithm>
#include <cmath>

namespace tessera {

namespace {

// Non-finite texels would turn every path touching them into a dropped sample: read as 0.
size_t zero_nonfinite(float* v, size_t n) {
  size_t bad = 0;
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) {
      v[i] = 0.f;
      ++bad;
    }
  return bad;
}

}  // namespace

TexelStorage::TexelStorage(const Image& linear)
    : width_(linear.width()), height_(linear.height()), channels_(linear.channels()), f32_(linear.values()) {
  compute_mean();
}

TexelStorage TexelStorage::decode(PackedImage stored, float gamma, bool raw, int channel, size_t* nonfinite) {
  if (stored.format == PixelFormat::U8) return decode_u8(std::move(stored), gamma, raw, channel, nonfinite);
  Image decoded = decode_bitmap_values(stored.to_image(), gamma, raw);
  if (channel >= 0) decoded = extract_channel(decoded, channel);
  const size_t bad = zero_nonfinite(decoded.data(), decoded.values().size());
  if (nonfinite) *nonfinite = bad;
  const bool as_half = stored.format == PixelFormat::U16 || stored.format == PixelFormat::Half;
  stored = PackedImage();  // the file's values are no longer needed: free them before packing
  return from_decoded(std::move(decoded), as_half);
}

TexelStorage TexelStorage::decode_u8(PackedImage stored, float gamma, bool raw, int channel, size_t* nonfinite) {
  // Every code through the float path at once: a 256 x 1 RGBA ramp, colour decoded, alpha not.
  Image ramp(256, 1, 4);
  ramp.set_srgb_encoded(stored.srgb_encoded);
  for (int k = 0; k < 256; ++k)
    for (int c = 0; c < 4; ++c) ramp.at(k, 0, c) = float(k) / 255.f;  // as PackedImage::to_image
  const Image decoded = decode_bitmap_values(ramp, gamma, raw);
  TexelStorage out;
  bool bad_code[2][256] = {};
  bool any_bad = false;
  for (int k = 0; k < 256; ++k)
    for (int t = 0; t < 2; ++t) {
      float v = decoded.at(k, 0, t == 0 ? 0 : 3);
      if (!std::isfinite(v)) v = 0.f, bad_code[t][k] = any_bad = true;
      out.tables_[size_t(t)][size_t(k)] = v;
    }

  out.width_ = stored.width, out.height_ = stored.height, out.format_ = Format::U8;
  if (channel < 0) {
    out.channels_ = stored.channels;
    out.u8_ = std::move(stored.u8);
  } else {
    const int src = source_channel(stored.channels, channel);
    out.channels_ = 1;
    out.table_of_[0] = src == 3 ? 1 : 0;
    out.u8_.resize(stored.num_pixels());
    for (size_t i = 0; i < out.u8_.size(); ++i) out.u8_[i] = stored.u8[i * size_t(stored.channels) + size_t(src)];
  }
  if (nonfinite) {
    *nonfinite = 0;
    for (size_t i = 0; any_bad && i < out.u8_.size(); ++i)
      *nonfinite += bad_code[out.table_of_[i % size_t(out.channels_)]][out.u8_[i]];
  }
  out.compute_mean();
  return out;
}

TexelStorage TexelStorage::from_decoded(Image decoded, bool as_half) {
  TexelStorage out;
  out.width_ = decoded.width(), out.height_ = decoded.height(), out.channels_ = decoded.channels();
  const std::vector<float>& v = decoded.values();
  // A value past half's range would become infinite: such an image stays float.
  as_half = as_half && std::all_of(v.begin(), v.end(), [](float x) { return std::abs(x) <= 65504.f; });
  if (as_half) {
    out.format_ = Format::Half;
    out.u16_.resize(v.size());
    for (size_t i = 0; i < v.size(); ++i) out.u16_[i] = Imath::half(v[i]).bits();
  } else {
    out.format_ = Format::F32;
    out.f32_ = v;
  }
  out.compute_mean();
  return out;
}

void TexelStorage::compute_mean() {
  // Summed in double: large textures would otherwise lose the small texels.
  double sum[3] = {0, 0, 0};
  visit([&](auto f) {
    for (int y = 0; y < height_; ++y)
      for (int x = 0; x < width_; ++x) {
        const Rgb c = rgb_as<decltype(f)::value>(x, y);
        for (int i = 0; i < 3; ++i) sum[i] += double(c[i]);
      }
  });
  const double n = double(num_pixels());
  mean_ = n > 0 ? Rgb(float(sum[0] / n), float(sum[1] / n), float(sum[2] / n)) : Rgb(0.f);
}

size_t TexelStorage::bytes() const {
  size_t values = u8_.size() * sizeof(uint8_t) + u16_.size() * sizeof(uint16_t) + f32_.size() * sizeof(float);
  return values + (format_ == Format::U8 ? sizeof(tables_) : 0);
}

Image TexelStorage::to_image() const {
  Image out(width_, height_, channels_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x)
      for (int c = 0; c < channels_; ++c) out.at(x, y, c) = at(x, y, c);
  return out;
}

}  // namespace tessera

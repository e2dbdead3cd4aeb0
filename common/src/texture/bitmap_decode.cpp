// Decoding a bitmap's stored values (gamma, raw, channel): the float reference, and a file read
// into compact texels through it.
#include "tessera/texture/bitmap_decode.h"

#include "tessera/core/error.h"
#include "tessera/image/packed_image.h"

#include <cmath>

namespace tessera {

std::string bitmap_cache_key(const std::string& path, const BitmapDecodeSettings& settings) {
  const std::string channel = settings.channel >= 0 ? std::string(1, "rgba"[settings.channel]) : "";
  return path + "|gamma=" + std::to_string(settings.gamma) + "|raw=" + (settings.raw ? "1" : "0") +
         "|channel=" + channel;
}

DecodedBitmap decode_bitmap_file(const std::string& path, const BitmapDecodeSettings& settings) {
  PackedImage stored = read_packed_image(path);
  if (stored.empty()) throw SceneError("image has no pixels");
  DecodedBitmap out;
  out.texels = TexelStorage::decode(std::move(stored), settings.gamma, settings.raw, settings.channel, &out.nonfinite);
  return out;
}

Image decode_bitmap_values(const Image& stored, float gamma, bool raw) {
  if (gamma == 0.f) {
    if (!raw) return stored.linearized();
    Image out = stored;
    out.set_srgb_encoded(false);
    return out;
  }
  Image out = stored;
  out.set_srgb_encoded(false);
  int colour_channels = out.channels() == 4 ? 3 : out.channels();
  float* px = out.data();
  for (size_t i = 0; i < out.num_pixels(); ++i)
    for (int c = 0; c < colour_channels; ++c) {
      float& v = px[i * size_t(out.channels()) + size_t(c)];
      if (gamma < 0.f)
        v = srgb_to_linear(v);
      else
        v = std::copysign(std::pow(std::abs(v), gamma), v);
    }
  return out;
}

int source_channel(int channels, int channel) {
  const int c = channels == 1 && channel < 3 ? 0 : channel;
  if (c >= channels)
    throw SceneError("has no channel '" + std::string(1, "rgba"[channel]) + "' (" + std::to_string(channels) +
                     " channel(s))");
  return c;
}

Image extract_channel(const Image& image, int channel) {
  const int c = source_channel(image.channels(), channel);
  Image out(image.width(), image.height(), 1);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) out.at(x, y, 0) = image.at(x, y, c);
  return out;
}

}  // namespace tessera

// How a `bitmap` texture turns a file's stored values into linear ones (Mitsuba's gamma / raw /
// channel parameters), in float (the reference the compact storage is built from and checked
// against) and from a file into compact texels.
#pragma once

#include "tessera/image/image.h"
#include "tessera/texture/texel_storage.h"

#include <cstddef>
#include <string>

namespace tessera {

/// The parameters of a bitmap that change its decoded texels.
struct BitmapDecodeSettings {
  /// 0 = automatic (sRGB for 8/16-bit files, linear for float files, unless `raw`), -1 = sRGB
  /// curve, g > 0 = v^g.
  float gamma = 0.f;
  bool raw = false;
  /// 0..3 = r, g, b, a: that channel alone as a grey texture; -1 = all channels.
  int channel = -1;
};

/// The decode cache's key: the resolved path and every setting that changes the texels.
std::string bitmap_cache_key(const std::string& path, const BitmapDecodeSettings& settings);

/// A decoded bitmap file: its texels, and how many non-finite values were read as 0.
struct DecodedBitmap {
  TexelStorage texels;
  size_t nonfinite = 0;
};

/// Reads and decodes a bitmap file. Throws SceneError naming the file (unreadable, no pixels,
/// no such channel).
DecodedBitmap decode_bitmap_file(const std::string& path, const BitmapDecodeSettings& settings);

/// How Mitsuba decodes a bitmap's stored values into linear ones: `gamma` 0 = automatic (sRGB for
/// 8-bit files, linear for float files, unless `raw`), -1 = sRGB curve, g > 0 = v^g. Alpha is
/// never decoded.
Image decode_bitmap_values(const Image& stored, float gamma, bool raw);
/// Channel `channel` (0..3 = r, g, b, a) of `image` as a one-channel image; a one-channel image
/// serves r, g and b. Throws SceneError (without a location) when the image lacks the channel.
Image extract_channel(const Image& image, int channel);
/// The channel of an image with `channels` channels that extract_channel reads for `channel`;
/// throws as extract_channel does.
int source_channel(int channels, int channel);

}  // namespace tessera

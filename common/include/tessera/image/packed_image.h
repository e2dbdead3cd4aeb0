// An image as its file stores it: 8-bit or 16-bit integer codes, half or float values, without
// the conversion to float that `Image` makes. Textures read through this to keep their texels
// compact; everything else (environment maps, comparisons) keeps using `read_image`.
//
// Layout as `Image`: row-major, top row first, channels interleaved (1 = grey, 3 = RGB, 4 = RGBA;
// grey+alpha files become RGBA, as read_image makes them).
#pragma once

#include "tessera/image/image.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tessera {

enum class PixelFormat {
  U8,    ///< codes 0..255, meaning code / 255
  U16,   ///< codes 0..65535, meaning code / 65535
  Half,  ///< IEEE binary16 bits
  F32,
};

struct PackedImage {
  int width = 0, height = 0, channels = 0;
  PixelFormat format = PixelFormat::F32;
  /// As Image::srgb_encoded(): the integer formats of stb's readers carry the sRGB curve.
  bool srgb_encoded = false;
  std::vector<uint8_t> u8;    ///< U8
  std::vector<uint16_t> u16;  ///< U16 codes or Half bits
  std::vector<float> f32;     ///< F32

  size_t num_pixels() const { return size_t(width) * size_t(height); }
  size_t num_values() const { return num_pixels() * size_t(channels); }
  bool empty() const { return num_values() == 0; }
  /// Bytes the pixel values take.
  size_t bytes() const;
  /// The float image read_image gives for the same file, value for value (code / 255 and
  /// code / 65535 as divisions, halves converted exactly).
  Image to_image() const;
};

/// By extension, as read_image: .exr keeps half channels as Half (when every channel read is
/// half) and float ones as F32; .png/.jpg/.tga/.bmp give U8 or U16 (16-bit PNG); .hdr and .pfm
/// give F32. Throws SceneError naming the file.
PackedImage read_packed_image(const std::string& path);
/// EXR channels as read_exr chooses them (R,G,B[,A] or Y).
PackedImage read_exr_packed(const std::string& path);
/// stb_image formats as read_stb reads them.
PackedImage read_stb_packed(const std::string& path);

}  // namespace tessera

// A float image in memory, and reading/writing it in the formats the renderer meets: OpenEXR and
// PFM (HDR, linear), PNG (8-bit output through a tone curve), Radiance .hdr and the stb LDR formats
// (input, for textures and environment maps).
//
// Layout: row-major, top row first, channels interleaved (1 = grey, 3 = RGB, 4 = RGBA). Pixel
// values are linear unless `srgb_encoded()` says they still carry the sRGB curve (8-bit inputs,
// as stored in the file; call `linearized()` to remove it, as Mitsuba's bitmap texture does unless
// `raw` is set). Alpha is never curve-encoded.
#pragma once

#include "tessera/core/check.h"
#include "tessera/core/rgb.h"

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace tessera {

class Image {
 public:
  Image() = default;
  /// Zero-filled. `channels` must be 1, 3 or 4.
  Image(int width, int height, int channels);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  bool empty() const { return pixels_.empty(); }
  size_t num_pixels() const { return size_t(width_) * size_t(height_); }
  bool has_alpha() const { return channels_ == 4; }

  float* data() { return pixels_.data(); }
  const float* data() const { return pixels_.data(); }
  /// All values, num_pixels() * channels() of them.
  const std::vector<float>& values() const { return pixels_; }

  float& at(int x, int y, int c) {
    TESSERA_DCHECK(x >= 0 && x < width_ && y >= 0 && y < height_ && c >= 0 && c < channels_);
    return pixels_[(size_t(y) * size_t(width_) + size_t(x)) * size_t(channels_) + size_t(c)];
  }
  float at(int x, int y, int c) const { return const_cast<Image*>(this)->at(x, y, c); }

  /// Colour of a pixel: grey images give (v, v, v); alpha is ignored.
  Rgb rgb(int x, int y) const {
    if (channels_ == 1) return Rgb(at(x, y, 0));
    return {at(x, y, 0), at(x, y, 1), at(x, y, 2)};
  }
  /// Writes a colour; grey images store its average, alpha is left as it was.
  void set_rgb(int x, int y, Rgb v);
  /// 1 for images without alpha.
  float alpha(int x, int y) const { return channels_ == 4 ? at(x, y, 3) : 1.f; }

  bool srgb_encoded() const { return srgb_encoded_; }
  void set_srgb_encoded(bool v) { srgb_encoded_ = v; }
  /// A copy with the sRGB curve removed from the colour channels (no-op copy when already linear).
  Image linearized() const;
  /// A 3-channel copy (grey replicated, alpha dropped).
  Image to_rgb() const;
  void flip_vertical();

 private:
  int width_ = 0, height_ = 0, channels_ = 0;
  bool srgb_encoded_ = false;
  std::vector<float> pixels_;
};

/// Extra header entries of an EXR file (the CLI stores seed, spp, scene, version). Values that are
/// a plain decimal int32 ("42", "-7") are written as EXR int attributes, everything else as strings;
/// reading turns both back into their decimal/string text.
using ImageAttributes = std::map<std::string, std::string>;

/// How linear radiance becomes 8-bit (Mitsuba's ldrfilm): multiply by 2^exposure, apply the sRGB
/// curve (gamma < 0) or v^(1/gamma), clamp to [0,1], round to nearest of 0..255.
struct LdrSettings {
  float gamma = -1.f;
  float exposure = 0.f;
};
uint8_t to_ldr_byte(float linear, const LdrSettings& settings);

// Every reader and writer throws SceneError naming the file (missing, unreadable, truncated,
// malformed, unsupported extension).

/// By extension, case-insensitive: .exr .pfm .hdr .png .jpg .jpeg .tga .bmp
Image read_image(const std::string& path);
/// By extension: .exr (float32; attributes stored), .pfm, .png (sRGB curve, exposure 0), .hdr.
void write_image(const std::string& path, const Image& image, const ImageAttributes& attributes = {});

/// EXR with R,G,B[,A] (half or float) -> 3/4 channels; Y only (optionally with A) -> 1 channel.
/// `attributes`, if given, receives the header's string and int attributes.
Image read_exr(const std::string& path, ImageAttributes* attributes = nullptr);
/// float32, ZIP compression, channels Y / RGB / RGBA by channel count.
void write_exr(const std::string& path, const Image& image, const ImageAttributes& attributes = {});

/// A named layer of a multi-layer EXR: channels "<name>.<channel>" (albedo.R, normal.X, depth.Z),
/// the layer convention OpenEXR documents and OpenImageIO, Mitsuba 3 and Blender follow.
/// `image` has one channel per name in `channels`.
struct ImageLayer {
  std::string name;
  std::vector<std::string> channels;
  Image image;
};
/// float32, ZIP: `beauty` as R,G,B (as write_exr) and every layer, all of one size.
void write_exr_layers(const std::string& path, const Image& beauty, const std::vector<ImageLayer>& layers,
                      const ImageAttributes& attributes = {});
/// Layer `name`'s `channels`, in that order; the error names the file and every missing channel.
Image read_exr_layer(const std::string& path, const std::string& name, const std::vector<std::string>& channels);

/// PF (RGB) or Pf (grey); either byte order; values multiplied by |scale| when it is not 1.
Image read_pfm(const std::string& path);
/// Little-endian (scale -1), rows bottom to top as the format says; alpha dropped.
void write_pfm(const std::string& path, const Image& image);

/// 8-bit PNG: grey, RGB or RGBA (alpha written linearly, not curve-encoded).
void write_png(const std::string& path, const Image& image, const LdrSettings& settings = {});
/// Radiance RGBE.
void write_hdr(const std::string& path, const Image& image);
/// stb_image formats: .hdr gives linear floats; 8/16-bit formats give values in [0,1], sRGB
/// encoded (see srgb_encoded()). Grey+alpha becomes RGBA.
Image read_stb(const std::string& path);

}  // namespace tessera

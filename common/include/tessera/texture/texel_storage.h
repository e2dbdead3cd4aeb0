// The texels of an image texture, kept as compact as the file allows: 8-bit files stay 8 bits a
// channel and are decoded at lookup through a 256-entry table per channel kind (colour or alpha),
// 16-bit integer and half files are kept as half, float files as float. Channel counts stay as
// the file has them (1, 3 or 4).
//
// The tables hold exactly what decode_bitmap_values gives for each code, so an 8-bit texel reads
// as the same float bits as the all-float path; half storage is within half precision of it.
#pragma once

#include "tessera/core/half.h"
#include "tessera/core/rgb.h"
#include "tessera/image/image.h"
#include "tessera/image/packed_image.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace tessera {

class TexelStorage {
 public:
  enum class Format { U8, Half, F32 };
  template <Format F>
  using FormatTag = std::integral_constant<Format, F>;

  TexelStorage() = default;
  /// Float texels, taken as already decoded (tests and generated textures).
  explicit TexelStorage(const Image& linear);
  /// A file's stored values decoded as Mitsuba's bitmap does (decode_bitmap_values with `gamma`
  /// and `raw`), reduced to one channel when `channel` is 0..3 (extract_channel; -1 keeps all).
  /// Non-finite values become 0; `nonfinite`, if given, receives how many there were. Throws
  /// SceneError (without a location) when the image lacks `channel`.
  static TexelStorage decode(PackedImage stored, float gamma, bool raw, int channel,
                             size_t* nonfinite = nullptr);

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  bool has_alpha() const { return channels_ == 4; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  size_t num_pixels() const { return size_t(width_) * size_t(height_); }
  Format format() const { return format_; }
  /// Memory the texels take (values and decode tables).
  size_t bytes() const;
  /// What the same texels take as float (the layout of Image).
  size_t float_bytes() const { return num_pixels() * size_t(channels_) * sizeof(float); }
  /// Mean colour over all texels (as Image::rgb reads them), summed in double in texel order.
  Rgb mean() const { return mean_; }
  /// The texel values widened to float.
  Image to_image() const;

  /// Calls `fn(FormatTag<F>{})` with this storage's format as a constant, so that a filter
  /// dispatches on the format once per lookup instead of once per texel.
  template <typename Fn>
  decltype(auto) visit(Fn&& fn) const {
    switch (format_) {
      case Format::U8: return fn(FormatTag<Format::U8>{});
      case Format::Half: return fn(FormatTag<Format::Half>{});
      case Format::F32: break;
    }
    return fn(FormatTag<Format::F32>{});
  }

  /// Channel c of texel (x, y), in range, for storage of format F.
  template <Format F>
  float at_as(int x, int y, int c) const {
    return value<F>(index(x, y) + size_t(c), c);
  }
  /// Colour of texel (x, y): grey gives (v, v, v); alpha is ignored.
  template <Format F>
  Rgb rgb_as(int x, int y) const {
    const size_t i = index(x, y);
    if (channels_ == 1) return Rgb(value<F>(i, 0));
    return {value<F>(i, 0), value<F>(i + 1, 1), value<F>(i + 2, 2)};
  }
  float at(int x, int y, int c) const {
    return visit([&](auto f) { return at_as<decltype(f)::value>(x, y, c); });
  }
  Rgb rgb(int x, int y) const {
    return visit([&](auto f) { return rgb_as<decltype(f)::value>(x, y); });
  }

 private:
  size_t index(int x, int y) const {
    TESSERA_DCHECK(x >= 0 && x < width_ && y >= 0 && y < height_);
    return (size_t(y) * size_t(width_) + size_t(x)) * size_t(channels_);
  }
  template <Format F>
  float value(size_t i, int c) const {
    if constexpr (F == Format::U8)
      return tables_[table_of_[c]][u8_[i]];
    else if constexpr (F == Format::Half)
      return half_to_float(u16_[i]);
    else
      return f32_[i];
  }
  static TexelStorage decode_u8(PackedImage stored, float gamma, bool raw, int channel, size_t* nonfinite);
  static TexelStorage from_decoded(Image decoded, bool as_half);
  void compute_mean();

  int width_ = 0, height_ = 0, channels_ = 0;
  Format format_ = Format::F32;
  std::vector<uint8_t> u8_;
  std::vector<uint16_t> u16_;  // half bits
  std::vector<float> f32_;
  // U8 only: decoded value of each code for colour channels (0) and alpha (1), and which table
  // each channel reads (a grey image cut from an alpha channel reads the alpha table).
  std::array<std::array<float, 256>, 2> tables_{};
  std::array<uint8_t, 4> table_of_{0, 0, 0, 1};
  Rgb mean_;
};

}  // namespace tessera

// Reading an image file without widening its values to float (the texture path), and the
// widening itself, which read_image's readers share so that both paths agree value for value.
#include "tessera/image/packed_image.h"

#include "tessera/core/half.h"

#include "image/io_util.h"

namespace tessera {

size_t PackedImage::bytes() const {
  return u8.size() * sizeof(uint8_t) + u16.size() * sizeof(uint16_t) + f32.size() * sizeof(float);
}

Image PackedImage::to_image() const {
  Image img(width, height, channels);
  img.set_srgb_encoded(srgb_encoded);
  float* out = img.data();
  const size_t n = num_values();
  switch (format) {
    // Divisions, not multiplications by 1/255: code k reads as exactly the float nearest k/255.
    case PixelFormat::U8:
      for (size_t i = 0; i < n; ++i) out[i] = float(u8[i]) / 255.f;
      break;
    case PixelFormat::U16:
      for (size_t i = 0; i < n; ++i) out[i] = float(u16[i]) / 65535.f;
      break;
    case PixelFormat::Half:
      for (size_t i = 0; i < n; ++i) out[i] = half_to_float(u16[i]);
      break;
    case PixelFormat::F32:
      for (size_t i = 0; i < n; ++i) out[i] = f32[i];
      break;
  }
  return img;
}

PackedImage read_packed_image(const std::string& path) {
  using namespace image_detail;
  std::string ext = lower_extension(path);
  if (ext == ".exr") return read_exr_packed(path);
  if (ext == ".hdr" || ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tga" || ext == ".bmp")
    return read_stb_packed(path);
  if (ext == ".pfm") {
    const Image img = read_pfm(path);
    PackedImage out;
    out.width = img.width(), out.height = img.height(), out.channels = img.channels();
    out.format = PixelFormat::F32;
    out.f32 = img.values();
    return out;
  }
  fail(path, "unsupported image format '" + ext + "' (readable: .exr .pfm .hdr .png .jpg .jpeg .tga .bmp)");
}

}  // namespace tessera

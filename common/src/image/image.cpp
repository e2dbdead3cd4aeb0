#include "tessera/image/image.h"

#include "image/io_util.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

namespace tessera {

Image::Image(int width, int height, int channels) : width_(width), height_(height), channels_(channels) {
  TESSERA_CHECK(width >= 0 && height >= 0);
  TESSERA_CHECK(channels == 1 || channels == 3 || channels == 4);
  pixels_.assign(size_t(width) * size_t(height) * size_t(channels), 0.f);
}

void Image::set_rgb(int x, int y, Rgb v) {
  if (channels_ == 1) {
    at(x, y, 0) = v.average();
    return;
  }
  at(x, y, 0) = v.r;
  at(x, y, 1) = v.g;
  at(x, y, 2) = v.b;
}

Image Image::linearized() const {
  Image out = *this;
  if (!srgb_encoded_) return out;
  int colour_channels = channels_ == 4 ? 3 : channels_;
  for (size_t i = 0; i < num_pixels(); ++i)
    for (int c = 0; c < colour_channels; ++c) {
      float& v = out.pixels_[i * size_t(channels_) + size_t(c)];
      v = srgb_to_linear(v);
    }
  out.srgb_encoded_ = false;
  return out;
}

Image Image::to_rgb() const {
  Image out(width_, height_, 3);
  out.srgb_encoded_ = srgb_encoded_;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) out.set_rgb(x, y, rgb(x, y));
  return out;
}

void Image::flip_vertical() {
  size_t row = size_t(width_) * size_t(channels_);
  for (int y = 0; y < height_ / 2; ++y)
    std::swap_ranges(pixels_.begin() + std::ptrdiff_t(size_t(y) * row),
                     pixels_.begin() + std::ptrdiff_t(size_t(y + 1) * row),
                     pixels_.begin() + std::ptrdiff_t(size_t(height_ - 1 - y) * row));
}

namespace image_detail {

void require_readable_file(const std::string& path) {
  std::error_code ec;
  auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) fail(path, "image file not found");
  if (!std::filesystem::is_regular_file(status)) fail(path, "not a regular file");
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace image_detail

Image read_image(const std::string& path) {
  using namespace image_detail;
  std::string ext = lower_extension(path);
  if (ext == ".exr") return read_exr(path);
  if (ext == ".pfm") return read_pfm(path);
  if (ext == ".hdr" || ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tga" || ext == ".bmp")
    return read_stb(path);
  fail(path, "unsupported image format '" + ext +
                 "' (readable: .exr .pfm .hdr .png .jpg .jpeg .tga .bmp)");
}

void write_image(const std::string& path, const Image& image, const ImageAttributes& attributes) {
  using namespace image_detail;
  if (image.empty()) fail(path, "cannot write an empty image");
  std::string ext = lower_extension(path);
  if (ext == ".exr") return write_exr(path, image, attributes);
  if (ext == ".pfm") return write_pfm(path, image);
  if (ext == ".png") return write_png(path, image);
  if (ext == ".hdr") return write_hdr(path, image);
  fail(path, "unsupported output image format '" + ext + "' (writable: .exr .pfm .png .hdr)");
}

}  // namespace tessera

// Portable Float Map: "PF" (RGB) or "Pf" (grey), then "width height", then a scale whose sign gives
// the byte order (negative = little-endian), each followed by one whitespace byte; then raw float32
// rows from the BOTTOM of the image to the top.
#include "tessera/image/image.h"

#include "image/io_util.h"

#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

namespace tessera {

namespace {

using image_detail::fail;

// One whitespace-delimited header token; stops after the single whitespace byte that ends it.
std::string next_token(std::istream& in) {
  std::string tok;
  int c = in.get();
  while (c != EOF && std::isspace(c)) c = in.get();
  while (c != EOF && !std::isspace(c)) {
    tok.push_back(char(c));
    if (tok.size() > 64) break;
    c = in.get();
  }
  return tok;
}

uint32_t byteswap32(uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

}  // namespace

Image read_pfm(const std::string& path) {
  image_detail::require_readable_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  std::string magic = next_token(in);
  int channels = magic == "PF" ? 3 : (magic == "Pf" ? 1 : 0);
  if (!channels) fail(path, "not a PFM file (header must start with PF or Pf)");
  std::string ws = next_token(in), hs = next_token(in), ss = next_token(in);
  long long w = 0, h = 0;
  double scale = 0;
  try {
    size_t pos = 0;
    w = std::stoll(ws, &pos);
    if (pos != ws.size()) throw std::invalid_argument("w");
    h = std::stoll(hs, &pos);
    if (pos != hs.size()) throw std::invalid_argument("h");
    scale = std::stod(ss, &pos);
    if (pos != ss.size()) throw std::invalid_argument("scale");
  } catch (const std::exception&) {
    fail(path, "malformed PFM header");
  }
  if (w <= 0 || h <= 0 || w > (1 << 20) || h > (1 << 20) || w * h > (1LL << 30))
    fail(path, "PFM size " + ws + "x" + hs + " is invalid");
  if (scale == 0 || !std::isfinite(scale)) fail(path, "PFM scale must be a non-zero number");
  bool file_little = scale < 0;
  bool swap = file_little != (std::endian::native == std::endian::little);

  Image img(int(w), int(h), channels);
  size_t row_values = size_t(w) * size_t(channels);
  std::vector<uint32_t> row(row_values);
  float mul = float(std::abs(scale));
  for (long long r = 0; r < h; ++r) {
    if (!in.read(reinterpret_cast<char*>(row.data()), std::streamsize(row_values * 4)))
      fail(path, "PFM file is truncated (expected " + std::to_string(w * h * channels * 4) + " bytes of pixels)");
    float* dst = img.data() + size_t(h - 1 - r) * row_values;  // bottom row comes first
    for (size_t i = 0; i < row_values; ++i) {
      uint32_t bits = swap ? byteswap32(row[i]) : row[i];
      float v;
      std::memcpy(&v, &bits, 4);
      dst[i] = mul == 1.f ? v : v * mul;
    }
  }
  return img;
}

void write_pfm(const std::string& path, const Image& image_in) {
  if (image_in.empty()) fail(path, "cannot write an empty image");
  const Image image = image_in.srgb_encoded() ? image_in.linearized() : image_in;
  int out_channels = image.channels() == 1 ? 1 : 3;
  std::ofstream out(path, std::ios::binary);
  if (!out) fail(path, "cannot open file for writing");
  std::ostringstream header;
  header << (out_channels == 3 ? "PF" : "Pf") << '\n' << image.width() << ' ' << image.height() << '\n'
         << "-1.0\n";
  out << header.str();
  std::vector<float> row(size_t(image.width()) * size_t(out_channels));
  for (int y = image.height() - 1; y >= 0; --y) {
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < out_channels; ++c) {
        float v = image.at(x, y, c);
        if constexpr (std::endian::native != std::endian::little) {
          uint32_t bits;
          std::memcpy(&bits, &v, 4);
          bits = byteswap32(bits);
          std::memcpy(&v, &bits, 4);
        }
        row[size_t(x) * size_t(out_channels) + size_t(c)] = v;
      }
    out.write(reinterpret_cast<const char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
  }
  if (!out.flush()) fail(path, "write failed");
}

}  // namespace tessera

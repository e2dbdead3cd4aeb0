// Writers for the file kinds the texture tests read back: 16-bit PNG (stb_image_write writes 8-bit
// only, so this writes the chunks itself through zlib) and half-float EXR (OpenEXR's RGBA file).
#pragma once

#include <OpenEXR/ImfRgbaFile.h>
#include <zlib.h>

#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace tessera::test {

namespace png16_detail {

inline void put_u32(std::string& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(char((v >> s) & 0xff));
}

inline void put_chunk(std::ofstream& f, const char* type, const std::string& data) {
  std::string chunk(type, 4);
  chunk += data;
  std::string len;
  put_u32(len, uint32_t(data.size()));
  std::string crc;
  put_u32(crc, uint32_t(::crc32(0, reinterpret_cast<const Bytef*>(chunk.data()), uInt(chunk.size()))));
  f << len << chunk << crc;
}

}  // namespace png16_detail

/// A 16-bit PNG of `channels` (1 grey, 3 RGB, 4 RGBA) interleaved codes, top row first.
inline void write_png16(const std::string& path, int width, int height, int channels,
                        const std::vector<uint16_t>& codes) {
  using namespace png16_detail;
  const int colour_type = channels == 1 ? 0 : channels == 3 ? 2 : 6;
  std::string ihdr;
  put_u32(ihdr, uint32_t(width));
  put_u32(ihdr, uint32_t(height));
  ihdr += std::string{char(16), char(colour_type), 0, 0, 0};
  std::string raw;  // each row: filter type 0, then big-endian samples
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    for (int i = 0; i < width * channels; ++i) {
      uint16_t v = codes[size_t(y) * size_t(width * channels) + size_t(i)];
      raw.push_back(char(v >> 8));
      raw.push_back(char(v & 0xff));
    }
  }
  uLongf size = compressBound(uLong(raw.size()));
  std::string z(size, '\0');
  if (compress(reinterpret_cast<Bytef*>(z.data()), &size, reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size())) != Z_OK)
    throw std::runtime_error("zlib compress failed");
  z.resize(size);
  std::ofstream f(path, std::ios::binary);
  f << std::string("\x89PNG\r\n\x1a\n", 8);
  put_chunk(f, "IHDR", ihdr);
  put_chunk(f, "IDAT", z);
  put_chunk(f, "IEND", "");
}

/// A half-float EXR with R,G,B (and A when `channels` is 4) from interleaved float values.
inline void write_half_exr(const std::string& path, int width, int height, int channels,
                           const std::vector<float>& values) {
  std::vector<Imf::Rgba> px(size_t(width) * size_t(height));
  for (size_t i = 0; i < px.size(); ++i) {
    const float* v = &values[i * size_t(channels)];
    px[i] = Imf::Rgba(v[0], v[1], v[2], channels == 4 ? v[3] : 1.f);
  }
  Imf::RgbaOutputFile file(path.c_str(), width, height, channels == 4 ? Imf::WRITE_RGBA : Imf::WRITE_RGB);
  file.setFrameBuffer(px.data(), 1, size_t(width));
  file.writePixels(height);
}

}  // namespace tessera::test

// What the farm's binary results (tile results, splat results) share: fields appended and read
// as they lie in memory (little-endian), an XXH3-128 checksum in its canonical big-endian form,
// and concatenated zstd frames whose stated sizes bound what is decompressed.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace tessera::result_bytes {

inline constexpr size_t kChecksumBytes = 16;

/// XXH3-128 of `bytes` (against corruption in transit and on disk, not an adversary).
std::array<char, kChecksumBytes> checksum(std::string_view bytes);

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

/// Reads fields in order; the caller checks the size first.
struct Reader {
  std::string_view in;
  size_t pos = 0;
  template <class T>
  T get() {
    T v;
    std::memcpy(&v, in.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
};

/// What `raw_bytes` may weigh compressed, also as frames compressed apart and concatenated (a
/// generous margin over one frame's bound).
uint64_t max_compressed_bytes(uint64_t raw_bytes);

/// `raw` compressed as one zstd frame at `level` (kUncompressed of tile_result.h: `raw` itself).
std::string compress(std::string raw, int level);

/// The concatenated frames of `bytes` (an encoder may compress parts apart) decompressed into
/// `raw`, refused before any is decompressed when a frame does not state its size or they add up
/// to more than `max_size`; false with `error` starting with `what`.
bool decompress(std::string_view bytes, uint64_t max_size, std::string& raw, std::string& error, const char* what);

}  // namespace tessera::result_bytes

// SHA-256 (OpenSSL) for content addressing: scene bundles are stored and cached by the hex digest
// of their bytes. (Tile results carry a cheaper checksum: tile_result.h.)
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace tessera {

using Sha256Digest = std::array<uint8_t, 32>;

Sha256Digest sha256(const void* data, size_t size);
inline Sha256Digest sha256(std::string_view bytes) { return sha256(bytes.data(), bytes.size()); }
/// 64 lowercase hex digits.
std::string to_hex(const Sha256Digest& digest);
inline std::string sha256_hex(std::string_view bytes) { return to_hex(sha256(bytes)); }
/// Hash of a file's bytes; throws std::runtime_error naming the file if it cannot be read.
std::string sha256_file_hex(const std::string& path);
/// True for exactly 64 lowercase hex digits (a hash that is safe to use as a file name).
bool is_sha256_hex(std::string_view s);

}  // namespace tessera

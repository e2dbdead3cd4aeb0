#include "unit_upload.h"

#include <openssl/evp.h>

namespace tessera::server {

Sha256Digest UnitUpload::digest() const {
  if (tile) return sha256(tile->film.pixels().data(), tile->film.pixels().size() * sizeof(PixelSums));
  // A splat result's sums: its pixels and values, in order.
  Sha256Digest out{};
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr);
  EVP_DigestUpdate(ctx, splats->splats.pixel.data(), splats->splats.pixel.size() * sizeof(uint32_t));
  EVP_DigestUpdate(ctx, splats->splats.value.data(), splats->splats.value.size() * sizeof(splats->splats.value[0]));
  unsigned int n = 0;
  EVP_DigestFinal_ex(ctx, out.data(), &n);
  EVP_MD_CTX_free(ctx);
  return out;
}

Result<UnitUpload> decode_upload(std::string_view bytes, int64_t max_pixels) {
  UnitUpload upload;
  std::string error;
  if (is_splat_result(bytes)) {
    upload.splats = std::make_shared<SplatResult>();
    if (!decode_splat_result(bytes, *upload.splats, error, max_pixels))
      return make_error(Code::BadRequest, "bad_result", error);
    return upload;
  }
  upload.tile = std::make_shared<TileResult>();
  if (!decode_tile_result(bytes, *upload.tile, error, max_pixels)) return make_error(Code::BadRequest, "bad_result", error);
  return upload;
}

}  // namespace tessera::server

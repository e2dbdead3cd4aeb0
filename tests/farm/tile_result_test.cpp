// The tile-result wire format: exact round trip (compressed, in concatenated frames, or stored as it
// is), and every kind of damage refused.
#include "tessera/farm/tile_result.h"
#include "tessera/farm/sha256.h"

#include <gtest/gtest.h>
#define XXH_INLINE_ALL
#include <xxhash.h>
#include <zstd.h>

#include <cstring>
#include <random>

namespace tessera {
namespace {

TileResult sample_result() {
  TileResult r;
  r.job_id = 77;
  r.tile = 5;
  r.pass = 3;
  r.sample_begin = 7;
  r.sample_end = 15;
  r.seconds = 0.25;
  r.film.reset({10, 20, 23, 29});
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.f, 10.f);
  for (int y = 20; y < 29; ++y)
    for (int x = 10; x < 23; ++x)
      for (int s = 0; s < 8; ++s) r.film.add_sample({x, y}, Rgb(u(rng), u(rng), u(rng)));
  r.film.add_sample({12, 21}, Rgb(std::nanf(""), 0, 0));  // counted, not summed
  r.film.counters.bounce_rays = 123;
  return r;
}

TEST(TileResult, RoundTripsEveryBit) {
  TileResult in = sample_result();
  std::string bytes = encode_tile_result(in);
  TileResult out;
  std::string error;
  ASSERT_TRUE(decode_tile_result(bytes, out, error)) << error;
  EXPECT_EQ(out.job_id, 77u);
  EXPECT_EQ(out.tile, 5u);
  EXPECT_EQ(out.pass, 3u);
  EXPECT_EQ(out.sample_begin, 7u);
  EXPECT_EQ(out.sample_end, 15u);
  EXPECT_EQ(out.seconds, 0.25);
  EXPECT_EQ(out.film.rect(), in.film.rect());
  EXPECT_EQ(out.film.counters.samples, in.film.counters.samples);
  EXPECT_EQ(out.film.counters.nonfinite, 1u);
  EXPECT_EQ(out.film.counters.bounce_rays, 123u);
  ASSERT_EQ(out.film.pixels().size(), in.film.pixels().size());
  EXPECT_EQ(std::memcmp(out.film.pixels().data(), in.film.pixels().data(), in.film.pixels().size() * sizeof(PixelSums)), 0);
  std::printf("13x9 tile: %zu bytes raw, %zu compressed\n", size_t(13 * 9 * 56 + 128), bytes.size());
  EXPECT_TRUE(out.training.empty());
  // A guide-training unit's records travel with it, byte for byte.
  in.training = std::string("TSDR\0\x01\0\0", 8) + std::string(300, '\x07');
  ASSERT_TRUE(decode_tile_result(encode_tile_result(in), out, error)) << error;
  EXPECT_EQ(out.training, in.training);
}

TEST(TileResult, RefusesDamage) {
  const std::string bytes = encode_tile_result(sample_result());
  TileResult out;
  std::string error;
  EXPECT_FALSE(decode_tile_result("", out, error));
  EXPECT_FALSE(decode_tile_result(bytes.substr(0, bytes.size() - 1), out, error));
  EXPECT_FALSE(decode_tile_result(bytes.substr(0, 10), out, error));
  EXPECT_FALSE(decode_tile_result(std::string(1000, 'x'), out, error));
  // A flipped byte is refused (zstd's framing or the checksum), or, where it only touches framing
  // that does not change the content (a few header bits), decodes to exactly the original: the
  // SHA-256 covers the decompressed content, so damaged sums can never be accepted.
  const TileResult original = sample_result();
  int refused = 0, harmless = 0;
  for (size_t i = 0; i < bytes.size(); ++i) {
    std::string bad = bytes;
    bad[i] ^= 0x10;
    if (!decode_tile_result(bad, out, error)) {
      ++refused;
      continue;
    }
    ASSERT_EQ(std::memcmp(out.film.pixels().data(), original.film.pixels().data(),
                          original.film.pixels().size() * sizeof(PixelSums)), 0) << "byte " << i;
    ++harmless;
  }
  EXPECT_GT(refused, int(bytes.size()) * 99 / 100);
  std::printf("flipped bytes: %d refused, %d harmless framing\n", refused, harmless);
  // A rect larger than the limit is refused before anything is allocated for it.
  EXPECT_FALSE(decode_tile_result(bytes, out, error, 100));
  EXPECT_NE(error.find("over the limit"), std::string::npos) << error;
}

bool same_result(const TileResult& a, const TileResult& b) {
  return a.job_id == b.job_id && a.tile == b.tile && a.pass == b.pass && a.sample_end == b.sample_end &&
         a.film.rect() == b.film.rect() && a.film.counters.samples == b.film.counters.samples &&
         std::memcmp(a.film.pixels().data(), b.film.pixels().data(), a.film.pixels().size() * sizeof(PixelSums)) == 0;
}

std::string zstd_frame(std::string_view raw) {
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  out.resize(ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 1));
  return out;
}

// Uncompressed bytes as an older `version` wrote them: without the last `cut` bytes before the
// checksum (the sections that version lacks), with its number and its XXH3-128 checksum.
std::string as_older_version(std::string raw, uint32_t version, size_t cut) {
  raw.erase(raw.size() - kTileResultDigestBytes - cut);
  std::memcpy(raw.data() + 4, &version, 4);
  XXH128_canonical_t c;
  XXH128_canonicalFromHash(&c, XXH3_128bits(raw.data(), raw.size()));
  raw.append(reinterpret_cast<const char*>(c.digest), sizeof(c.digest));
  return raw;
}

TEST(TileResult, StoredUncompressedRoundTripsAndIsChecked) {
  const TileResult in = sample_result();
  const std::string raw = encode_tile_result(in, kUncompressed);
  EXPECT_EQ(raw.size(), size_t(96 + 13 * 9 * 56 + 8 + 8 + 8 + kTileResultDigestBytes));
  EXPECT_EQ(raw.substr(0, 4), "TSTR");
  TileResult out;
  std::string error;
  ASSERT_TRUE(decode_tile_result(raw, out, error)) << error;
  EXPECT_TRUE(same_result(in, out));
  // Stored bytes are still verified: a flipped bit of the sums fails the checksum.
  std::string bad = raw;
  bad[200] ^= 0x01;
  EXPECT_FALSE(decode_tile_result(bad, out, error));
  EXPECT_NE(error.find("checksum"), std::string::npos) << error;
  EXPECT_FALSE(decode_tile_result(raw.substr(0, raw.size() - 8), out, error));
}

// A data directory written before the format's checksum became XXH3-128 holds version-1 results
// and checkpoints, which end in a SHA-256: they are still read, and still checked.
TEST(TileResult, ReadsVersionOneWithSha256) {
  const TileResult in = sample_result();
  std::string v1 = encode_tile_result(in, kUncompressed);
  v1.resize(v1.size() - kTileResultDigestBytes - 24);  // (without 3's training records, 4's AOVs and 5's state)
  const uint32_t version = 1;
  std::memcpy(v1.data() + 4, &version, 4);
  const Sha256Digest digest = sha256(v1);
  v1.append(reinterpret_cast<const char*>(digest.data()), digest.size());
  TileResult out;
  std::string error;
  ASSERT_TRUE(decode_tile_result(v1, out, error)) << error;
  EXPECT_TRUE(same_result(in, out));
  v1[300] ^= 0x04;
  EXPECT_FALSE(decode_tile_result(v1, out, error));
  EXPECT_NE(error.find("checksum"), std::string::npos) << error;
  std::memcpy(v1.data() + 4, "\x09\0\0\0", 4);
  EXPECT_FALSE(decode_tile_result(v1, out, error));
  EXPECT_NE(error.find("version 9"), std::string::npos) << error;
}

// A denoised job's units carry the AOV sums (format version 4); version 3 results, without them,
// are still read.
TEST(TileResult, AovSumsRoundTripAndVersionThreeIsRead) {
  TileResult in = sample_result();
  FilmTile with_aovs({10, 20, 23, 29}, /*aovs=*/true);
  SampleFeatures f;
  f.albedo = Rgb(0.25f, 0.5f, 0.75f);
  f.normal = Vec3(0.f, 0.f, 1.f);
  f.depth = 3.5f;
  for (int y = 20; y < 29; ++y)
    for (int x = 10; x < 23; ++x)
      for (uint32_t s = 0; s < 3; ++s) with_aovs.add_sample({x, y}, Rgb(float(x), float(y), float(s)), s, f);
  in.film = with_aovs;
  const std::string raw = encode_tile_result(in, kUncompressed);
  EXPECT_EQ(raw.size(), size_t(96 + 13 * 9 * (56 + 88) + 8 + 8 + 8 + kTileResultDigestBytes));
  TileResult out;
  std::string error;
  ASSERT_TRUE(decode_tile_result(encode_tile_result(in), out, error)) << error;
  ASSERT_TRUE(out.film.has_aovs());
  EXPECT_EQ(std::memcmp(out.film.aovs().data(), in.film.aovs().data(), in.film.aovs().size() * sizeof(AovSums)), 0);
  EXPECT_EQ(out.film.aovs()[0].half_count, 2u);

  // A count of AOV pixels that is not the rectangle's is refused.
  std::string bad = raw;
  const size_t count_at = 96 + 13 * 9 * 56 + 8;
  const uint64_t wrong = 5;
  std::memcpy(bad.data() + count_at, &wrong, 8);
  EXPECT_FALSE(decode_tile_result(bad, out, error));

  // Version 3: the same without the AOV block and the state's (and its checksum over those bytes).
  const std::string v3 = as_older_version(encode_tile_result(sample_result(), kUncompressed), 3, 16);
  ASSERT_TRUE(decode_tile_result(v3, out, error)) << error;
  EXPECT_FALSE(out.film.has_aovs());
  EXPECT_TRUE(same_result(sample_result(), out));
}

// An sppm gather's result carries its pixels' state (format version 5); version 4 results, without
// it, are still read; a state larger than its bound per pixel is refused.
TEST(TileResult, TileStateRoundTripsAndVersionFourIsRead) {
  TileResult in = sample_result();
  in.tile_state.resize(13 * 9 * 32);
  for (size_t i = 0; i < in.tile_state.size(); ++i) in.tile_state[i] = char(i * 7);
  TileResult out;
  std::string error;
  ASSERT_TRUE(decode_tile_result(encode_tile_result(in), out, error)) << error;
  EXPECT_EQ(out.tile_state, in.tile_state);
  EXPECT_TRUE(same_result(in, out));

  TileResult huge = sample_result();
  huge.tile_state.assign(13 * 9 * (kMaxStateBytesPerPixel + 1), 'x');
  EXPECT_FALSE(decode_tile_result(encode_tile_result(huge), out, error));

  const std::string v4 = as_older_version(encode_tile_result(sample_result(), kUncompressed), 4, 8);
  ASSERT_TRUE(decode_tile_result(v4, out, error)) << error;
  EXPECT_TRUE(out.tile_state.empty());
  EXPECT_TRUE(same_result(sample_result(), out));
}

TEST(TileResult, ConcatenatedFramesDecodeAsOne) {
  const TileResult in = sample_result();
  const std::string raw = encode_tile_result(in, kUncompressed);
  // The raw bytes cut in three and compressed separately, as an encoder may do.
  const std::string bytes = zstd_frame(std::string_view(raw).substr(0, 100)) +
                            zstd_frame(std::string_view(raw).substr(100, 3000)) +
                            zstd_frame(std::string_view(raw).substr(3100));
  TileResult out;
  std::string error;
  ASSERT_TRUE(decode_tile_result(bytes, out, error)) << error;
  EXPECT_TRUE(same_result(in, out));
  // A missing or doubled frame is refused, and so is trailing junk after the last frame.
  const std::string first_two = zstd_frame(std::string_view(raw).substr(0, 100)) +
                                zstd_frame(std::string_view(raw).substr(100, 3000));
  EXPECT_FALSE(decode_tile_result(first_two, out, error));
  EXPECT_FALSE(decode_tile_result(bytes + zstd_frame(std::string_view(raw).substr(3100)), out, error));
  EXPECT_FALSE(decode_tile_result(bytes + "junk", out, error));
  // The rectangle's limit holds however the bytes were framed.
  EXPECT_FALSE(decode_tile_result(bytes, out, error, 100));
  EXPECT_NE(error.find("over the limit"), std::string::npos) << error;
}

}  // namespace
}  // namespace tessera

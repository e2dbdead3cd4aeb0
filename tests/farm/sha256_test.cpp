// SHA-256: FIPS 180-2 test vectors, file hashing across read chunks, and the hex-name check.
#include "tessera/farm/sha256.h"

#include "farm/archive_builder.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace tessera {
namespace {

TEST(Sha256, KnownVectors) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, DigestAndHexAgree) {
  Sha256Digest d = sha256("abc");
  EXPECT_EQ(d[0], 0xba);
  EXPECT_EQ(d[31], 0xad);
  EXPECT_EQ(to_hex(d), sha256_hex("abc"));
  EXPECT_NE(sha256_hex("abd"), sha256_hex("abc"));
}

TEST(Sha256, FileHashEqualsMemoryHash) {
  test::TempDir t;
  // Larger than the 1 MiB read chunk, and not a multiple of it.
  const std::string data = test::noise((size_t(5) << 19) + 17, 11);
  const std::string path = t.write("data.bin", data);
  EXPECT_EQ(sha256_file_hex(path), sha256_hex(data));
  EXPECT_EQ(sha256_file_hex(t.write("empty", "")), sha256_hex(""));
}

TEST(Sha256, MissingFileThrowsNamingIt) {
  try {
    (void)sha256_file_hex("/nonexistent/tessera/file.bin");
    ADD_FAILURE() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/tessera/file.bin"), std::string::npos) << e.what();
  }
}

TEST(Sha256, IsSha256Hex) {
  const std::string h = sha256_hex("abc");
  EXPECT_TRUE(is_sha256_hex(h));
  EXPECT_FALSE(is_sha256_hex(""));
  EXPECT_FALSE(is_sha256_hex(h.substr(1)));
  EXPECT_FALSE(is_sha256_hex(h + "0"));
  std::string upper = h;
  upper[0] = 'B';
  EXPECT_FALSE(is_sha256_hex(upper));
  std::string slash = h;
  slash[10] = '/';
  EXPECT_FALSE(is_sha256_hex(slash));
  EXPECT_FALSE(is_sha256_hex("../" + h.substr(3)));
  EXPECT_TRUE(is_sha256_hex(std::string(64, '0')));
  EXPECT_FALSE(is_sha256_hex(std::string(64, 'g')));
}

}  // namespace
}  // namespace tessera

#include "image/image_test_util.h"
#include "tessera/image/image.h"
#include "tessera/scene/error.h"

#include <gtest/gtest.h>

#include <cstring>

namespace tessera {
namespace {

using test::scratch_dir;
using test::test_pattern;

TEST(PfmIo, RgbRoundTripIsExact) {
  auto dir = scratch_dir();
  Image img = test_pattern(9, 5, 3);
  std::string path = (dir / "a.pfm").string();
  write_image(path, img);
  Image back = read_image(path);
  ASSERT_EQ(back.width(), 9);
  ASSERT_EQ(back.height(), 5);
  ASSERT_EQ(back.channels(), 3);
  EXPECT_EQ(back.values(), img.values());
}

TEST(PfmIo, GreyRoundTripIsExact) {
  auto dir = scratch_dir();
  Image img = test_pattern(4, 6, 1);
  std::string path = (dir / "g.pfm").string();
  write_pfm(path, img);
  EXPECT_EQ(test::read_bytes(path).substr(0, 3), "Pf\n");
  Image back = read_pfm(path);
  ASSERT_EQ(back.channels(), 1);
  EXPECT_EQ(back.values(), img.values());
}

TEST(PfmIo, FileLayoutIsLittleEndianBottomRowFirst) {
  auto dir = scratch_dir();
  Image img(2, 2, 3);
  img.set_rgb(0, 0, Rgb(1, 2, 3));  // top-left
  img.set_rgb(0, 1, Rgb(7, 8, 9));  // bottom-left
  std::string path = (dir / "layout.pfm").string();
  write_pfm(path, img);
  std::string bytes = test::read_bytes(path);
  const std::string header = "PF\n2 2\n-1.0\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 2 * 2 * 3 * 4);
  float first[3];
  std::memcpy(first, bytes.data() + header.size(), sizeof first);  // host is little-endian (x86-64)
  EXPECT_EQ(first[0], 7.f);
  EXPECT_EQ(first[2], 9.f);
}

TEST(PfmIo, ReadsBigEndianAndAppliesScale) {
  auto dir = scratch_dir();
  std::string bytes = "Pf\n2 1\n2.0\n";
  for (float v : {1.5f, -0.25f}) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    for (int s = 24; s >= 0; s -= 8) bytes.push_back(char((bits >> s) & 0xff));
  }
  std::string path = (dir / "be.pfm").string();
  test::write_bytes(path, bytes);
  Image img = read_pfm(path);
  ASSERT_EQ(img.width(), 2);
  ASSERT_EQ(img.channels(), 1);
  EXPECT_EQ(img.at(0, 0, 0), 3.f);
  EXPECT_EQ(img.at(1, 0, 0), -0.5f);
}

TEST(PfmIo, TruncatedAndMalformedFilesAreErrorsNamingTheFile) {
  auto dir = scratch_dir();
  std::string good = (dir / "good.pfm").string();
  write_pfm(good, test_pattern(8, 8, 3));
  std::string bytes = test::read_bytes(good);
  struct Case {
    const char* name;
    std::string content;
    const char* what;
  } cases[] = {
      {"cut.pfm", bytes.substr(0, bytes.size() - 5), "truncated"},
      {"magic.pfm", "P6\n2 2\n255\n", "not a PFM"},
      {"size.pfm", "PF\n-3 2\n-1.0\n", "invalid"},
      {"header.pfm", "PF\n2 x\n-1.0\n", "malformed"},
      {"scale.pfm", "PF\n1 1\n0\n............", "scale"},
  };
  for (const auto& c : cases) {
    std::string path = (dir / c.name).string();
    test::write_bytes(path, c.content);
    try {
      read_image(path);
      ADD_FAILURE() << "no error for " << c.name;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.what), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace tessera

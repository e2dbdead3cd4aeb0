#include "image/image_test_util.h"
#include "tessera/image/image.h"
#include "tessera/image/image_compare.h"
#include "tessera/scene/error.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>

namespace tessera {
namespace {

using test::scratch_dir;
using test::test_pattern;

void expect_identical(const Image& a, const Image& b) {
  ASSERT_EQ(a.width(), b.width());
  ASSERT_EQ(a.height(), b.height());
  ASSERT_EQ(a.channels(), b.channels());
  for (size_t i = 0; i < a.values().size(); ++i) ASSERT_EQ(a.values()[i], b.values()[i]) << "value " << i;
}

TEST(ExrIo, RoundTripIsExactForEveryChannelCount) {
  auto dir = scratch_dir();
  for (int channels : {1, 3, 4}) {
    Image img = test_pattern(13, 7, channels, uint64_t(channels));
    std::string path = (dir / ("pattern" + std::to_string(channels) + ".exr")).string();
    write_exr(path, img);
    expect_identical(read_exr(path), img);
  }
}

TEST(ExrIo, AttributesRoundTripAsStringsAndInts) {
  auto dir = scratch_dir();
  std::string path = (dir / "attrs.exr").string();
  ImageAttributes attrs = {{"seed", "42"},      {"spp", "256"},         {"scene", "cornell-box/scene.xml"},
                           {"version", "0.1.0"}, {"offset", "-7"},       {"padded", "007"},
                           {"big", "99999999999"}, {"empty", ""}};
  write_image(path, test_pattern(4, 3, 3), attrs);
  ImageAttributes back;
  read_exr(path, &back);
  for (const auto& [k, v] : attrs) {
    ASSERT_TRUE(back.count(k)) << k;
    EXPECT_EQ(back[k], v) << k;
  }
}

TEST(ExrIo, ReservedAttributeNameIsRejected) {
  auto dir = scratch_dir();
  std::string path = (dir / "reserved.exr").string();
  EXPECT_THROW(write_exr(path, test_pattern(2, 2, 3), {{"channels", "x"}}), SceneError);
}

TEST(ExrIo, CornellBoxReferenceMeansMatchItsReadme) {
  std::string path = test::shared_path("references/cornell-box/reference.exr");
  TESSERA_REQUIRE_FILE(path);
  Image ref = read_image(path);
  ASSERT_EQ(ref.width(), 256);
  ASSERT_EQ(ref.height(), 256);
  ASSERT_EQ(ref.channels(), 3);
  EXPECT_EQ(count_non_finite(ref), 0u);
  auto m = channel_means(ref);
  EXPECT_NEAR(m[0], 0.196333026, 1e-7);
  EXPECT_NEAR(m[1], 0.127586726, 1e-7);
  EXPECT_NEAR(m[2], 0.0361156448, 1e-8);
}

// Every reference's README states its resolution and channel means; the EXR must agree.
TEST(ExrIo, EveryReferenceMatchesItsReadme) {
  std::filesystem::path root = test::shared_path("references");
  TESSERA_REQUIRE_FILE(root.string());
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(root)) {
    auto readme = entry.path() / "README.md";
    auto exr = entry.path() / "reference.exr";
    auto var = entry.path() / "variance.exr";
    if (!std::filesystem::exists(readme) || !std::filesystem::exists(exr)) continue;
    SCOPED_TRACE(entry.path().filename().string());
    std::string text = test::read_bytes(readme);
    std::smatch res, means;
    ASSERT_TRUE(std::regex_search(text, res, std::regex(R"(Resolution (\d+)\D+(\d+))")));
    ASSERT_TRUE(std::regex_search(
        text, means, std::regex(R"(Channel means: R ([0-9.eE+-]+), G ([0-9.eE+-]+), B ([0-9.eE+-]+))")));
    Image img = read_image(exr.string());
    EXPECT_EQ(img.width(), std::stoi(res[1]));
    EXPECT_EQ(img.height(), std::stoi(res[2]));
    ASSERT_EQ(img.channels(), 3);
    auto m = channel_means(img);
    for (int c = 0; c < 3; ++c) {
      double expected = std::stod(means[size_t(c + 1)]);
      EXPECT_NEAR(m[size_t(c)], expected, 1e-6 * std::max(1.0, expected)) << "channel " << c;
    }
    Image v = read_image(var.string());
    EXPECT_EQ(v.width(), img.width());
    EXPECT_EQ(v.height(), img.height());
    EXPECT_EQ(count_non_finite(v), 0u);
    for (float x : v.values()) ASSERT_GE(x, 0.f);
    ++checked;
  }
  EXPECT_GE(checked, 7);
}

TEST(ExrIo, TruncatedFileIsAnErrorNamingIt) {
  auto dir = scratch_dir();
  std::string good = (dir / "good.exr").string(), cut = (dir / "cut.exr").string();
  write_exr(good, test_pattern(64, 64, 3));
  std::string bytes = test::read_bytes(good);
  test::write_bytes(cut, bytes.substr(0, bytes.size() / 2));
  try {
    read_image(cut);
    FAIL() << "no error for a truncated EXR";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(cut), std::string::npos) << e.what();
    EXPECT_EQ(e.loc().file, cut);
  }
}

TEST(ExrIo, WritingIntoAMissingDirectoryIsAnError) {
  auto dir = scratch_dir();
  std::string path = (dir / "no" / "such" / "dir.exr").string();
  try {
    write_image(path, test_pattern(2, 2, 3));
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera

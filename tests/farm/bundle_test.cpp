// Scene bundles as a security boundary: every hostile or broken archive is refused with a message
// naming the entry, and leaves nothing behind; good archives (tar.gz, tar, zip) list and unpack.
#include "tessera/farm/bundle.h"

#include "farm/archive_builder.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::ArchiveBuilder;
using test::TempDir;
using Format = ArchiveBuilder::Format;

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Nothing named `dest` or `dest.tmp-*` / `dest.old-*` exists next to it.
void expect_nothing_left(const fs::path& dest) {
  EXPECT_FALSE(fs::exists(dest)) << dest;
  for (const auto& e : fs::directory_iterator(dest.parent_path()))
    EXPECT_NE(e.path().filename().string().rfind(dest.filename().string() + ".", 0), 0u) << e.path();
}

/// Inspect and unpack must both refuse `bytes` with a message containing `expected`.
void expect_refused(const std::string& bytes, const std::string& expected, const BundleLimits& limits = {}) {
  BundleResult inspected = inspect_bundle(bytes, limits);
  EXPECT_FALSE(inspected.ok());
  EXPECT_NE(inspected.error.find(expected), std::string::npos) << inspected.error;
  TempDir t;
  const fs::path dest = t.path / "bundle";
  BundleResult unpacked = unpack_bundle(bytes, dest.string(), limits);
  EXPECT_FALSE(unpacked.ok());
  EXPECT_EQ(unpacked.error, inspected.error);
  EXPECT_TRUE(unpacked.files.empty());
  expect_nothing_left(dest);
}

std::string good_bundle(Format f) {
  ArchiveBuilder b(f);
  b.file("scene.xml", "<scene version=\"3.0.0\"/>").dir("textures/").file("textures/a.png", "png-bytes");
  b.file("meshes/m.obj", test::noise(3000, 1)).dir("empty/");
  return b.finish();
}

class GoodBundle : public ::testing::TestWithParam<Format> {};

TEST_P(GoodBundle, ListsAndUnpacks) {
  const std::string bytes = good_bundle(GetParam());
  BundleResult r = inspect_bundle(bytes);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.files.size(), 3u);  // folders are not listed
  EXPECT_EQ(r.files[0].path, "scene.xml");
  EXPECT_EQ(r.files[1].path, "textures/a.png");
  EXPECT_EQ(r.files[1].size, 9u);
  EXPECT_EQ(r.files[2].path, "meshes/m.obj");
  EXPECT_EQ(r.files[2].size, 3000u);

  TempDir t;
  const fs::path dest = t.path / "out" / "b1";  // parents created
  BundleResult u = unpack_bundle(bytes, dest.string());
  ASSERT_TRUE(u.ok()) << u.error;
  EXPECT_EQ(u.files.size(), 3u);
  EXPECT_EQ(read_file(dest / "textures/a.png"), "png-bytes");
  EXPECT_EQ(read_file(dest / "meshes/m.obj"), test::noise(3000, 1));
  EXPECT_TRUE(fs::is_directory(dest / "empty"));
  // No temporary sibling remains.
  EXPECT_EQ(std::distance(fs::directory_iterator(t.path / "out"), fs::directory_iterator()), 1);
}

INSTANTIATE_TEST_SUITE_P(Formats, GoodBundle, ::testing::Values(Format::TarGz, Format::Tar, Format::Zip));

TEST(Bundle, UnpackReplacesAnExistingDestination) {
  TempDir t;
  const fs::path dest = t.path / "b";
  ASSERT_TRUE(unpack_bundle(good_bundle(Format::TarGz), dest.string()).ok());
  BundleResult r = unpack_bundle(ArchiveBuilder(Format::Zip).file("other.xml", "x").finish(), dest.string() + "/");
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_TRUE(fs::exists(dest / "other.xml"));
  EXPECT_FALSE(fs::exists(dest / "scene.xml"));
  EXPECT_EQ(std::distance(fs::directory_iterator(t.path), fs::directory_iterator()), 1);
}

TEST(Bundle, FailedUnpackKeepsThePreviousTree) {
  TempDir t;
  const fs::path dest = t.path / "b";
  ASSERT_TRUE(unpack_bundle(good_bundle(Format::Tar), dest.string()).ok());
  std::string bad = ArchiveBuilder(Format::Tar).file("x.xml", "x").file("../y", "y").finish();
  EXPECT_FALSE(unpack_bundle(bad, dest.string()).ok());
  EXPECT_TRUE(fs::exists(dest / "scene.xml"));
  EXPECT_FALSE(fs::exists(dest / "x.xml"));
}

TEST(Bundle, OnlyWritesTheListedFiles) {
  TempDir t;
  const fs::path dest = t.path / "b";
  std::set<std::string> only = {"scene.xml", "textures/a.png"};
  BundleResult r = unpack_bundle(good_bundle(Format::TarGz), dest.string(), {}, only);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.files.size(), 2u);
  EXPECT_EQ(r.files[1].path, "textures/a.png");
  EXPECT_TRUE(fs::exists(dest / "textures/a.png"));
  EXPECT_FALSE(fs::exists(dest / "meshes"));
  EXPECT_FALSE(fs::exists(dest / "empty"));

  only.insert("textures/missing.png");
  const fs::path dest2 = t.path / "b2";
  BundleResult missing = unpack_bundle(good_bundle(Format::TarGz), dest2.string(), {}, only);
  EXPECT_FALSE(missing.ok());
  EXPECT_NE(missing.error.find("'textures/missing.png'"), std::string::npos) << missing.error;
  expect_nothing_left(dest2);
}

TEST(Bundle, NormalisesDotComponents) {
  BundleResult r = inspect_bundle(ArchiveBuilder(Format::Tar).dir("./").file("./a//b/./c.xml", "x").finish());
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.files.size(), 1u);
  EXPECT_EQ(r.files[0].path, "a/b/c.xml");
}

TEST(BundleRefused, PathLeavingTheBundle) {
  expect_refused(ArchiveBuilder(Format::TarGz).file("scene.xml", "x").file("../x.xml", "x").finish(),
                 "bundle entry '../x.xml': path leaves the bundle");
  expect_refused(ArchiveBuilder(Format::Zip).file("a/../../x.xml", "x").finish(),
                 "bundle entry 'a/../../x.xml': path leaves the bundle");
}

TEST(BundleRefused, AbsolutePath) {
  expect_refused(ArchiveBuilder(Format::Tar).file("/etc/x.xml", "x").finish(), "bundle entry '/etc/x.xml': absolute path");
  expect_refused(ArchiveBuilder(Format::Zip).file("C:/x.xml", "x").finish(), "'C:/x.xml': absolute path");
}

TEST(Bundle, ZipBackslashesAreFolderSeparators) {
  // libarchive reads a zip's '\\' as '/' (zips made on Windows), before the checks below.
  BundleResult r = inspect_bundle(ArchiveBuilder(Format::Zip).file("textures\\a.png", "x").finish());
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.files.at(0).path, "textures/a.png");
  expect_refused(ArchiveBuilder(Format::Zip).file("..\\x.xml", "x").finish(), "path leaves the bundle");
}

TEST(BundleRefused, BackslashEmptyNameAndControlCharacters) {
  expect_refused(ArchiveBuilder(Format::Tar).file("textures\\a.png", "x").finish(),
                 "bundle entry 'textures\\a.png': backslash in path");
  expect_refused(ArchiveBuilder(Format::Tar).file(".", "x").finish(), "bundle entry '.': empty name");
  expect_refused(ArchiveBuilder(Format::Tar).file("a\nb.xml", "x").finish(), "bundle entry 'a?b.xml': control character");
  std::string deep;
  for (int i = 0; i < 2100; ++i) deep += "a/";
  expect_refused(ArchiveBuilder(Format::TarGz).file(deep + "x.xml", "x").finish(), "path longer than 4096 bytes");
}

TEST(BundleRefused, LinksAndSpecialFiles) {
  expect_refused(ArchiveBuilder(Format::TarGz).symlink("scene.xml", "/etc/passwd").finish(),
                 "bundle entry 'scene.xml': symbolic link");
  expect_refused(ArchiveBuilder(Format::Zip).symlink("textures", "/etc").finish(), "'textures': symbolic link");
  expect_refused(ArchiveBuilder(Format::Tar).file("a.xml", "x").hardlink("b.xml", "a.xml").finish(),
                 "bundle entry 'b.xml': hard link");
  expect_refused(ArchiveBuilder(Format::Tar).fifo("pipe").finish(), "bundle entry 'pipe': device, fifo or socket");
  expect_refused(ArchiveBuilder(Format::Tar).char_device("null").finish(), "'null': device, fifo or socket");
}

TEST(BundleRefused, DuplicateAndConflictingPaths) {
  expect_refused(ArchiveBuilder(Format::Tar).file("a.xml", "x").file("./a.xml", "y").finish(),
                 "bundle entry './a.xml': duplicate path");
  expect_refused(ArchiveBuilder(Format::Zip).file("a", "x").file("a/b.xml", "y").finish(),
                 "bundle entry 'a/b.xml': path runs through file 'a'");
  expect_refused(ArchiveBuilder(Format::Tar).file("a/b.xml", "x").file("a", "y").finish(), "'a': duplicate path");
}

TEST(BundleRefused, TooManyEntries) {
  ArchiveBuilder b(Format::TarGz);
  for (const char* name : {"f0", "f1", "f2", "f3", "f4"}) b.file(name, "x");
  const std::string bytes = b.finish();
  BundleLimits limits;
  limits.max_files = 5;
  EXPECT_TRUE(inspect_bundle(bytes, limits).ok());
  limits.max_files = 4;
  expect_refused(bytes, "bundle has more than 4 entries", limits);
}

TEST(BundleRefused, UnpackedSizeOverTheLimit) {
  BundleLimits limits;
  limits.max_unpacked_bytes = 64 << 10;
  // One highly compressible entry (a bomb in miniature), refused by its header.
  const std::string zeros(1 << 20, '\0');
  for (Format f : {Format::TarGz, Format::Zip}) {
    const std::string bomb = ArchiveBuilder(f).file("scene.xml", "x").file("big.bin", zeros).finish();
    EXPECT_LT(bomb.size(), 20000u);
    expect_refused(bomb, "bundle entry 'big.bin': unpacked size exceeds the limit of 65536 bytes", limits);
  }
  // The limit is on the sum: each of these fits alone.
  const std::string half(40 << 10, 'a');
  expect_refused(ArchiveBuilder(Format::TarGz).file("a", half).file("b", half).finish(), "'b': unpacked size exceeds",
                 limits);
  EXPECT_TRUE(inspect_bundle(ArchiveBuilder(Format::TarGz).file("a", half).finish(), limits).ok());
}

TEST(BundleRefused, CompressionRatioOverTheDefaultLimit) {
  // Zeros inflate about 1000:1; real scenes stay under 10:1 (docs/api.md, Limits).
  const std::string zeros(20 << 20, '\0');
  for (Format f : {Format::TarGz, Format::Zip}) {
    const std::string bomb = ArchiveBuilder(f).file("scene.xml", "x").file("big.bin", zeros).finish();
    ASSERT_LT(bomb.size(), 100000u);
    expect_refused(bomb, "bundle entry 'big.bin': unpacked size exceeds " +
                             std::to_string(BundleLimits{}.unpacked_limit(bomb.size())) +
                             " bytes, the compression-ratio limit");
    BundleLimits no_ratio;
    no_ratio.max_ratio = 0;
    EXPECT_TRUE(inspect_bundle(bomb, no_ratio).ok());
  }
  // Under the floor the ratio does not matter: a tiny scene of zeros is fine.
  EXPECT_TRUE(inspect_bundle(ArchiveBuilder(Format::TarGz).file("a", std::string(4 << 20, '\0')).finish()).ok());
  // The smaller limit wins, and a huge ratio cannot overflow.
  BundleLimits limits;
  EXPECT_EQ(limits.unpacked_limit(1000), (uint64_t(8) << 20) + 200000);
  EXPECT_EQ(limits.unpacked_limit(uint64_t(4) << 30), limits.max_unpacked_bytes);
  limits.max_ratio = 1e300;
  EXPECT_EQ(limits.unpacked_limit(1), limits.max_unpacked_bytes);
}

/// Rewrites the uncompressed size of every zip header (local, central, data descriptor) that
/// holds `from` into `to`: a zip whose headers lie about how much its deflate stream inflates to.
std::string patch_zip_sizes(std::string zip, uint32_t from, uint32_t to) {
  auto u32 = [&](size_t at) {
    return uint32_t(uint8_t(zip[at])) | uint32_t(uint8_t(zip[at + 1])) << 8 | uint32_t(uint8_t(zip[at + 2])) << 16 |
           uint32_t(uint8_t(zip[at + 3])) << 24;
  };
  auto put = [&](size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i) zip[at + i] = char((v >> (8 * i)) & 0xFF);
  };
  int patched = 0;
  for (size_t i = 0; i + 30 < zip.size(); ++i) {
    if (zip.compare(i, 4, "PK\x03\x04") == 0 && u32(i + 22) == from) put(i + 22, to), ++patched;
    if (zip.compare(i, 4, "PK\x01\x02") == 0 && u32(i + 24) == from) put(i + 24, to), ++patched;
    if (zip.compare(i, 4, "PK\x07\x08") == 0 && u32(i + 12) == from) put(i + 12, to), ++patched;
  }
  EXPECT_GE(patched, 1);
  return zip;
}

TEST(BundleRefused, HeaderLyingAboutItsSize) {
  BundleLimits limits;
  limits.max_unpacked_bytes = 64 << 10;
  const std::string zip = ArchiveBuilder(Format::Zip).file("big.bin", std::string(1 << 20, 'z')).finish();
  const std::string lying = patch_zip_sizes(zip, 1 << 20, 100);
  // Whichever notices first (our byte count, or libarchive's own size check), the entry is named.
  BundleResult r = inspect_bundle(lying, limits);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error.find("'big.bin'"), std::string::npos) << r.error;
  expect_refused(lying, "'big.bin'", limits);
  // Without the limit it is still refused: the data does not match its header.
  EXPECT_FALSE(inspect_bundle(lying).ok());
}

TEST(BundleRefused, TruncatedArchives) {
  for (Format f : {Format::TarGz, Format::Tar, Format::Zip}) {
    const std::string bytes =
        ArchiveBuilder(f).file("scene.xml", "x").file("mesh.bin", test::noise(100000, 7)).finish();
    ASSERT_TRUE(inspect_bundle(bytes).ok());
    const std::string cut = bytes.substr(0, bytes.size() / 2);
    BundleResult r = inspect_bundle(cut);
    EXPECT_FALSE(r.ok()) << "format " << int(f);
    expect_refused(cut, "");
  }
  // Only the end of the gzip stream missing (a plain tar or zip cut there still holds all its data).
  const std::string gz = ArchiveBuilder(Format::TarGz).file("mesh.bin", test::noise(1000, 7)).finish();
  expect_refused(gz.substr(0, gz.size() - 4), "corrupt or truncated bundle");
}

TEST(BundleRefused, GzipTrailerMismatch) {
  // libarchive's tar reader stops at the tar end marker, before the gzip CRC and length.
  const std::string gz = ArchiveBuilder(Format::TarGz).file("mesh.bin", test::noise(1000, 7)).finish();
  for (size_t at : {gz.size() - 8, gz.size() - 1}) {
    std::string bad = gz;
    bad[at] = char(bad[at] ^ 0x20);
    expect_refused(bad, "corrupt compressed data");
  }
  expect_refused(gz + "junk", "unexpected data after the compressed stream");
  EXPECT_TRUE(inspect_bundle(gz + std::string(512, '\0')).ok());
  EXPECT_TRUE(inspect_bundle(gz + gz).ok());  // concatenated members: the first tar ends the bundle
}

TEST(BundleRefused, NotAnArchive) {
  expect_refused(test::noise(4096, 3), "not a .tar.gz, .tar or .zip bundle");
  expect_refused("", "empty bundle");
  expect_refused("<scene version=\"3.0.0\"/>\n", "not a .tar.gz, .tar or .zip bundle");
}

TEST(BundleRefused, CorruptCompressedData) {
  std::string bytes = ArchiveBuilder(Format::TarGz).file("mesh.bin", test::noise(100000, 9)).finish();
  for (size_t i = bytes.size() / 3; i < bytes.size() / 3 + 64; ++i) bytes[i] = char(~bytes[i]);
  expect_refused(bytes, "corrupt");
}

TEST(FindSceneXml, SingleXmlAtTheRoot) {
  std::string err;
  std::vector<BundleEntry> files = {{"textures/a.xml", 1}, {"Scene.XML", 1}, {"a.png", 1}};
  EXPECT_EQ(find_scene_xml(files, "", err), "Scene.XML");
  EXPECT_EQ(err, "");
}

TEST(FindSceneXml, NoneOrSeveral) {
  std::string err;
  EXPECT_EQ(find_scene_xml({{"a.png", 1}}, "", err), "");
  EXPECT_EQ(err, "no .xml file at the bundle's root");
  EXPECT_EQ(find_scene_xml({{"cornell/scene.xml", 1}}, "", err), "");
  EXPECT_EQ(err, "no .xml file at the bundle's root (found 'cornell/scene.xml': name the scene file)");
  EXPECT_EQ(find_scene_xml({{"a.xml", 1}, {"b.xml", 1}}, "", err), "");
  EXPECT_NE(err.find("'a.xml', 'b.xml'"), std::string::npos) << err;
}

TEST(FindSceneXml, Requested) {
  std::string err;
  std::vector<BundleEntry> files = {{"a.xml", 1}, {"b.xml", 1}, {"sub/c.Xml", 1}, {"d.png", 1}};
  EXPECT_EQ(find_scene_xml(files, "sub/c.Xml", err), "sub/c.Xml");
  EXPECT_EQ(err, "");
  EXPECT_EQ(find_scene_xml(files, "d.png", err), "");
  EXPECT_EQ(err, "scene 'd.png' is not an .xml file");
  EXPECT_EQ(find_scene_xml(files, "e.xml", err), "");
  EXPECT_EQ(err, "scene 'e.xml' is not in the bundle");
}

}  // namespace
}  // namespace tessera

// Result uploads read as they arrive (server/src/upload_spool.h): a small body in memory, a large
// one spooled to a file that is mapped and already gone from the directory.
#include "upload_spool.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace tessera::test {
namespace {

namespace fs = std::filesystem;
using namespace tessera::server;

// A reader that hands `body` to the receiver in pieces of `piece` bytes, as httplib does.
httplib::ContentReader reader_of(const std::string& body, size_t piece) {
  return httplib::ContentReader(
      [body, piece](httplib::ContentReceiver receive) {
        for (size_t at = 0; at < body.size(); at += piece)
          if (!receive(body.data() + at, std::min(piece, body.size() - at))) return false;
        return true;
      },
      [](httplib::MultipartContentHeader, httplib::ContentReceiver) { return false; });
}

std::string random_bytes(size_t n) {
  std::mt19937 rng(7);
  std::string s(n, '\0');
  for (char& c : s) c = char(rng());
  return s;
}

size_t files_in(const fs::path& dir) {
  return size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

struct UploadSpool : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("tessera-spool-" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }
};

TEST_F(UploadSpool, ASmallBodyStaysInMemory) {
  const std::string body = random_bytes(1000);
  Result<std::shared_ptr<const UploadBytes>> got = read_upload(reader_of(body, 300), dir.string(), 4096);
  ASSERT_TRUE(got.ok()) << got.status.detail;
  EXPECT_EQ(got.value->file, nullptr);
  EXPECT_EQ(got.value->view(), body);
  EXPECT_EQ(files_in(dir), 0u);
}

TEST_F(UploadSpool, ALargeBodyIsSpooledMappedAndUnlinked) {
  const std::string body = random_bytes(100000);
  Result<std::shared_ptr<const UploadBytes>> got = read_upload(reader_of(body, 777), dir.string(), 4096);
  ASSERT_TRUE(got.ok()) << got.status.detail;
  ASSERT_NE(got.value->file, nullptr);
  EXPECT_TRUE(got.value->memory.empty());
  EXPECT_EQ(got.value->view(), body);  // (every piece, the ones before the spill too, in order)
  EXPECT_EQ(files_in(dir), 0u);
}

TEST_F(UploadSpool, ABodyCutShortIsRefusedAndLeavesNoFile) {
  const std::string body = random_bytes(100000);
  httplib::ContentReader cut(
      [&](httplib::ContentReceiver receive) { return receive(body.data(), 50000) && false; },
      [](httplib::MultipartContentHeader, httplib::ContentReceiver) { return false; });
  Result<std::shared_ptr<const UploadBytes>> got = read_upload(cut, dir.string(), 4096);
  EXPECT_EQ(got.status.code, Code::BadRequest);
  EXPECT_EQ(files_in(dir), 0u);
}

TEST_F(UploadSpool, AnUnwritableSpoolIsAnErrorNamingIt) {
  const std::string missing = (dir / "missing").string();
  Result<std::shared_ptr<const UploadBytes>> got = read_upload(reader_of(random_bytes(10000), 1000), missing, 4096);
  EXPECT_EQ(got.status.code, Code::Internal);
  EXPECT_NE(got.status.detail.find(missing), std::string::npos) << got.status.detail;
}

TEST_F(UploadSpool, ClearingRemovesOnlySpoolFiles) {
  std::ofstream(dir / "upload-abc123") << "partial";
  std::ofstream(dir / "image-7.exr") << "other";
  clear_spool(dir.string());
  EXPECT_FALSE(fs::exists(dir / "upload-abc123"));
  EXPECT_TRUE(fs::exists(dir / "image-7.exr"));
}

}  // namespace
}  // namespace tessera::test

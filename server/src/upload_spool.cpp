#include "upload_spool.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace tessera::server {

namespace fs = std::filesystem;

namespace {

constexpr const char* kSpoolPrefix = "upload-";

// A spool file: created with a unique name, written as the body arrives, removed once mapped (the
// mapping outlives the name) or when it is given up.
class SpoolFile {
 public:
  explicit SpoolFile(const std::string& dir) : path_((fs::path(dir) / (std::string(kSpoolPrefix) + "XXXXXX")).string()) {
    fd_ = mkstemp(path_.data());
    if (fd_ < 0) errno_ = errno;
  }
  ~SpoolFile() {
    if (fd_ >= 0) close(fd_);
    if (fd_ >= 0 || created_) unlink(path_.c_str());
  }
  SpoolFile(const SpoolFile&) = delete;
  SpoolFile& operator=(const SpoolFile&) = delete;

  bool write(const char* data, size_t n) {
    while (n > 0 && errno_ == 0) {
      const ssize_t w = ::write(fd_, data, n);
      if (w < 0 && errno == EINTR) continue;
      if (w < 0) errno_ = errno;
      else data += w, n -= size_t(w);
    }
    return errno_ == 0;
  }
  std::shared_ptr<const MappedFile> map() {
    created_ = true;
    close(fd_);
    fd_ = -1;
    return std::make_shared<const MappedFile>(path_);
  }
  int error() const { return errno_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
  int errno_ = 0;
  bool created_ = false;
};

Status spool_error(const SpoolFile& file) {
  const Code code = file.error() == ENOSPC ? Code::InsufficientStorage : Code::Internal;
  return make_error(code, "spool_failed",
                    "could not write the upload to " + file.path() + ": " + std::strerror(file.error()));
}

}  // namespace

Result<std::shared_ptr<const UploadBytes>> read_upload(const httplib::ContentReader& reader,
                                                       const std::string& spool_dir, size_t memory_bytes) {
  UploadBytes bytes;
  std::unique_ptr<SpoolFile> file;
  const bool read = reader([&](const char* data, size_t n) {
    if (!file && bytes.memory.size() + n <= memory_bytes) {
      bytes.memory.append(data, n);
      return true;
    }
    if (!file) {  // past what stays in memory: what came so far goes first
      file = std::make_unique<SpoolFile>(spool_dir);
      if (!file->write(bytes.memory.data(), bytes.memory.size())) return false;
      std::string().swap(bytes.memory);
    }
    return file->write(data, n);
  });
  if (file && file->error() != 0) return spool_error(*file);
  if (!read) return make_error(Code::BadRequest, "incomplete_body", "the upload ended before its Content-Length");
  if (file) {
    try {
      bytes.file = file->map();
    } catch (const std::exception& e) {
      return make_error(Code::Internal, "spool_failed", e.what());
    }
  }
  return std::make_shared<const UploadBytes>(std::move(bytes));
}

void clear_spool(const std::string& spool_dir) {
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(spool_dir, ec))
    if (entry.path().filename().string().rfind(kSpoolPrefix, 0) == 0) fs::remove(entry.path(), ec);
}

}  // namespace tessera::server

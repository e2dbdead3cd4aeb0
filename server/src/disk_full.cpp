#include "disk_full.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace tessera::server {

namespace fs = std::filesystem;

namespace {

std::atomic<uint64_t> full_answers{0};

bool mentions_full_disk(const std::string& text) {
  return text.find(std::strerror(ENOSPC)) != std::string::npos || text.find(std::strerror(EDQUOT)) != std::string::npos ||
         text.find("database or disk is full") != std::string::npos;
}

// Less than this free after a failed write: the write failed for lack of space, whatever the
// writer said (stb reports only "cannot write").
constexpr uintmax_t kNearlyFull = uintmax_t(1) << 20;

bool nearly_full(const std::string& dir) {
  std::error_code ec;
  const fs::space_info info = fs::space(dir, ec);
  return !ec && info.available < kNearlyFull;
}

[[noreturn]] void throw_full(const std::string& what, const std::string& data_dir) { throw DiskFullError(what, data_dir); }

void fsync_path(const std::string& path, bool directory, const std::string& data_dir) {
  int fd = ::open(path.c_str(), (directory ? O_RDONLY | O_DIRECTORY : O_WRONLY) | O_CLOEXEC);
  if (fd < 0) return;
  const int rc = ::fsync(fd), err = errno;
  ::close(fd);
  if (rc != 0 && !directory) throw_write_error("cannot sync " + path, err, data_dir);
}

}  // namespace

bool is_disk_full_errno(int err) { return err == ENOSPC || err == EDQUOT; }

bool is_disk_full(const std::exception& e) {
  if (auto* se = dynamic_cast<const StoreError*>(&e)) return se->disk_full;
  if (auto* sys = dynamic_cast<const std::system_error*>(&e))
    return sys->code().category() == std::generic_category() || sys->code().category() == std::system_category()
               ? is_disk_full_errno(sys->code().value())
               : false;
  return mentions_full_disk(e.what());
}

void throw_write_error(const std::string& what, int err, const std::string& data_dir) {
  if (is_disk_full_errno(err)) throw_full(what + ": " + std::strerror(err), data_dir);
  throw StoreError(what + ": " + std::strerror(err), false);
}

void throw_if_disk_full(const std::string& error, const std::string& data_dir) {
  if (error.empty()) return;
  if (mentions_full_disk(error) || (error.find("cannot ") != std::string::npos && nearly_full(data_dir)))
    throw_full(error, data_dir);
}

Status disk_full_status(const std::exception& e) {
  ++full_answers;
  std::string detail = "the coordinator's disk is full: ";
  detail += e.what();
  if (auto* full = dynamic_cast<const DiskFullError*>(&e); full && !full->data_dir.empty())
    detail += " (data dir " + full->data_dir + ")";
  detail += "; free some space there (or set --retain-bytes / --retain-days) and retry";
  return make_error(Code::InsufficientStorage, "disk_full", detail);
}

uint64_t disk_full_errors() { return full_answers.load(); }

void verify_image_file(const std::string& path, const std::string& format, const Image& image,
                       const std::string& data_dir) {
  std::string problem;
  try {
    const Image back = format == "exr" ? read_exr(path) : read_image(path);
    if (back.width() != image.width() || back.height() != image.height())
      problem = "it reads back as " + std::to_string(back.width()) + "x" + std::to_string(back.height());
    else if (format == "exr" && back.channels() == image.channels() &&
             std::memcmp(back.data(), image.data(), sizeof(float) * back.values().size()) != 0)
      problem = "its pixels differ from the image written";
  } catch (const std::exception& e) {
    problem = e.what();
  }
  if (problem.empty()) return;
  const std::string what = "cannot write " + path + " (" + problem + ")";
  if (mentions_full_disk(problem) || nearly_full(data_dir)) throw_full(what, data_dir);
  throw std::runtime_error(what);
}

void write_image_durably(const std::string& path, const Image& image, const ImageAttributes& attributes,
                         const std::string& data_dir, const std::vector<ImageLayer>& layers) {
  const std::string tmp = path + ".tmp.exr";
  std::error_code ec;
  try {
    try {
      write_exr_layers(tmp, image, layers, attributes);
    } catch (const std::exception& e) {
      if (mentions_full_disk(e.what()) || nearly_full(data_dir)) throw_full(e.what(), data_dir);
      throw;
    }
    verify_image_file(tmp, "exr", image, data_dir);
    fsync_path(tmp, false, data_dir);
    fs::rename(tmp, path);
    fsync_path(fs::path(path).parent_path().string(), true, data_dir);
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

}  // namespace tessera::server

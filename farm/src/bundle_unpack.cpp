// Unpacking a scene bundle: the shared walk (bundle_walk.h) with a sink that writes files into a
// private temporary folder, renamed into place only when the whole bundle was good.
#include "tessera/farm/bundle.h"

#include "bundle_walk.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>

namespace tessera {

namespace {

namespace fs = std::filesystem;

/// Writes files under `root` (a fresh, private directory): names are already validated, so
/// plain joins cannot leave it; O_EXCL|O_NOFOLLOW are a second line of defence.
class DiskSink : public detail::EntrySink {
 public:
  DiskSink(fs::path root, const std::set<std::string>* only) : root_(std::move(root)), only_(only) {}
  ~DiskSink() override {
    if (fd_ >= 0) ::close(fd_);
  }

  std::string directory(const std::string& path) override {
    if (only_) return "";  // only the folders the wanted files need
    std::error_code ec;
    fs::create_directories(root_ / path, ec);
    return ec ? "cannot create folder: " + ec.message() : "";
  }
  std::string begin(const std::string& path) override {
    if (only_ && !only_->count(path)) return "";
    fs::path target = root_ / path;
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (ec) return "cannot create folder '" + target.parent_path().string() + "': " + ec.message();
    fd_ = ::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd_ < 0) return "cannot create '" + target.string() + "': " + std::strerror(errno);
    target_ = target.string();
    return "";
  }
  std::string write(const char* data, size_t size) override {
    while (fd_ >= 0 && size > 0) {
      ssize_t n = ::write(fd_, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return "cannot write '" + target_ + "': " + std::strerror(errno);
      data += n;
      size -= size_t(n);
    }
    return "";
  }
  std::string end() override {
    if (fd_ < 0) return "";
    int rc = ::close(fd_);
    fd_ = -1;
    return rc != 0 ? "cannot write '" + target_ + "': " + std::strerror(errno) : "";
  }

 private:
  fs::path root_;
  const std::set<std::string>* only_;
  int fd_ = -1;
  std::string target_;
};

std::string random_suffix() {
  std::random_device rd;
  static const char kHex[] = "0123456789abcdef";
  std::string s;
  for (int i = 0; i < 2; ++i)
    for (uint32_t v = rd(), k = 0; k < 8; ++k, v >>= 4) s += kHex[v & 15];
  return s;
}

}  // namespace

BundleResult unpack_bundle(std::string_view bytes, const std::string& dest_dir, const BundleLimits& limits,
                           const std::optional<std::set<std::string>>& only) {
  BundleResult r;
  fs::path dest = fs::path(dest_dir).lexically_normal();
  if (!dest.empty() && dest.filename().empty()) dest = dest.parent_path();  // "dir/" -> "dir"
  if (dest.empty() || dest == "." || dest == "..") {
    r.error = "invalid destination folder '" + dest_dir + "'";
    return r;
  }
  std::error_code ec;
  if (dest.has_parent_path()) fs::create_directories(dest.parent_path(), ec);
  const fs::path tmp = dest.string() + ".tmp-" + random_suffix();
  if (ec || !fs::create_directory(tmp, ec)) {
    r.error = "cannot create folder '" + tmp.string() + "': " + (ec ? ec.message() : "it exists");
    return r;
  }
  {
    DiskSink sink(tmp, only ? &*only : nullptr);
    r = detail::walk_bundle(bytes, limits, &sink);
  }
  if (r.ok() && only) {
    std::set<std::string> present;
    for (const BundleEntry& f : r.files) present.insert(f.path);
    for (const std::string& want : *only)
      if (!present.count(want)) {
        r.error = "bundle has no file '" + want + "' (the scene needs it)";
        break;
      }
    std::erase_if(r.files, [&](const BundleEntry& f) { return !only->count(f.path); });
  }
  if (r.ok()) {
    // Swap in the new tree; the old one (a previous unpack) is moved aside first and removed.
    const fs::path old = dest.string() + ".old-" + random_suffix();
    const bool had_old = fs::exists(fs::symlink_status(dest, ec));
    ec.clear();  // "not found" is the usual case, not an error
    if (had_old) fs::rename(dest, old, ec);
    if (!ec) fs::rename(tmp, dest, ec);
    if (ec) {
      r.error = "cannot move the unpacked bundle into '" + dest.string() + "': " + ec.message();
      std::error_code ignored;
      if (had_old && !fs::exists(dest, ignored)) fs::rename(old, dest, ignored);
    } else if (had_old) {
      fs::remove_all(old, ec);
    }
  }
  if (!r.ok()) {
    r.files.clear();
    fs::remove_all(tmp, ec);
  }
  return r;
}

}  // namespace tessera

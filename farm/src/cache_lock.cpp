#include "tessera/farm/cache_lock.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace tessera::farm {

namespace {

std::string lock_path(const std::string& dir) { return (std::filesystem::path(dir) / "lock").string(); }

struct flock whole_file(short type) {
  struct flock l {};
  l.l_type = type;
  l.l_whence = SEEK_SET;  // (l_start = l_len = 0: the whole file)
  return l;
}

}  // namespace

CacheLock::CacheLock(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::string path = lock_path(dir);
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  struct flock l = whole_file(F_WRLCK);
  if (fcntl(fd_, F_SETLK, &l) == 0) return;
  const int err = errno;
  const pid_t pid = holder(dir);
  ::close(fd_);
  fd_ = -1;
  if (err != EACCES && err != EAGAIN) throw std::runtime_error("cannot lock " + path + ": " + std::strerror(err));
  throw std::runtime_error("the cache folder " + dir + " is in use by another worker" +
                           (pid > 0 ? " (pid " + std::to_string(pid) + ")" : std::string()) +
                           "; give each worker its own --cache-dir");
}

CacheLock::~CacheLock() {
  if (fd_ >= 0) ::close(fd_);  // (closing drops the lock)
}

pid_t CacheLock::holder(const std::string& dir) {
  const int fd = ::open(lock_path(dir).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return 0;
  // F_GETLK asks whether a write lock could be had: it reports the conflicting lock without
  // taking one (a read lock would need write access; F_WRLCK on a read-only fd is only queried).
  struct flock l = whole_file(F_WRLCK);
  const int r = fcntl(fd, F_GETLK, &l);
  ::close(fd);
  return r == 0 && l.l_type != F_UNLCK ? l.l_pid : 0;
}

}  // namespace tessera::farm

// A worker's claim on its cache folder: one worker per folder, so two never download into, evict
// from or report one cache (and a coordinator's local workers, restarted, never run twice under
// one name). A POSIX record lock on `DIR/lock`, which the kernel drops with its process (kill -9
// included), and which others can query for the holder's pid without taking it.
#pragma once

#include <sys/types.h>

#include <string>

namespace tessera::farm {

class CacheLock {
 public:
  /// Claims `dir` (created if missing). Throws std::runtime_error naming the folder and the
  /// holder's pid when another process holds it.
  explicit CacheLock(const std::string& dir);
  ~CacheLock();
  CacheLock(const CacheLock&) = delete;
  CacheLock& operator=(const CacheLock&) = delete;

  /// The pid of the process holding `dir`'s claim; 0 when none does (or the folder has no lock).
  static pid_t holder(const std::string& dir);

 private:
  int fd_ = -1;
};

}  // namespace tessera::farm

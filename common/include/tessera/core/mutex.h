// A mutex whose use the compiler checks: Clang's thread-safety analysis (-Wthread-safety; the
// clang stage of scripts/test.sh builds the coordinator with it and fails on any warning). State
// is declared TESSERA_GUARDED_BY(mu), functions that need the lock held TESSERA_REQUIRES(mu); an
// access without the lock is then a compile error rather than a comment. Other compilers see plain
// std::mutex code.
#pragma once

#include <mutex>

#if defined(__clang__)
#define TESSERA_THREAD_ANNOTATION(x) __attribute__((x))
#else
#define TESSERA_THREAD_ANNOTATION(x)
#endif

#define TESSERA_CAPABILITY(x) TESSERA_THREAD_ANNOTATION(capability(x))
#define TESSERA_SCOPED_CAPABILITY TESSERA_THREAD_ANNOTATION(scoped_lockable)
#define TESSERA_GUARDED_BY(x) TESSERA_THREAD_ANNOTATION(guarded_by(x))
#define TESSERA_PT_GUARDED_BY(x) TESSERA_THREAD_ANNOTATION(pt_guarded_by(x))
#define TESSERA_REQUIRES(...) TESSERA_THREAD_ANNOTATION(requires_capability(__VA_ARGS__))
#define TESSERA_EXCLUDES(...) TESSERA_THREAD_ANNOTATION(locks_excluded(__VA_ARGS__))
#define TESSERA_ACQUIRE(...) TESSERA_THREAD_ANNOTATION(acquire_capability(__VA_ARGS__))
#define TESSERA_RELEASE(...) TESSERA_THREAD_ANNOTATION(release_capability(__VA_ARGS__))
#define TESSERA_NO_THREAD_SAFETY_ANALYSIS TESSERA_THREAD_ANNOTATION(no_thread_safety_analysis)

namespace tessera {

class TESSERA_CAPABILITY("mutex") Mutex {
 public:
  void lock() TESSERA_ACQUIRE() { mu_.lock(); }
  void unlock() TESSERA_RELEASE() { mu_.unlock(); }

 private:
  std::mutex mu_;
};

/// Holds a Mutex for its scope; unlock() and lock() let a function wait off the lock, and it is a
/// lock std::condition_variable_any waits with.
class TESSERA_SCOPED_CAPABILITY MutexLock {
 public:
  explicit MutexLock(Mutex& mu) TESSERA_ACQUIRE(mu) : mu_(mu) { mu_.lock(); }
  ~MutexLock() TESSERA_RELEASE() {
    if (held_) mu_.unlock();
  }
  MutexLock(const MutexLock&) = delete;
  MutexLock& operator=(const MutexLock&) = delete;
  void lock() TESSERA_ACQUIRE() {
    mu_.lock();
    held_ = true;
  }
  void unlock() TESSERA_RELEASE() {
    mu_.unlock();
    held_ = false;
  }

 private:
  Mutex& mu_;
  bool held_ = true;
};

}  // namespace tessera

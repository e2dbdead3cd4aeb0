// Fixture of clang_checks_test: the same state read with its lock held, and by a function that
// requires it. The clang stage must pass this.
#include "tessera/core/mutex.h"

namespace {

struct Counter {
  tessera::Mutex mu;
  int count TESSERA_GUARDED_BY(mu) = 0;
  int read_locked() TESSERA_REQUIRES(mu) { return count; }
  int read() {
    tessera::MutexLock lock(mu);
    return read_locked();
  }
};

}  // namespace

int fixture_main() { return Counter().read(); }

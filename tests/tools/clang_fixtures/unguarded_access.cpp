// Fixture of clang_checks_test: guarded state read without its lock. The clang stage must fail here.
#include "tessera/core/mutex.h"

namespace {

struct Counter {
  tessera::Mutex mu;
  int count TESSERA_GUARDED_BY(mu) = 0;
  int read() { return count; }  // (the lock is not held)
};

}  // namespace

int fixture_main() { return Counter().read(); }

// Invariant checks. CHECK runs in every build; DCHECK only when NDEBUG is not defined. Both abort
// with file and line: a failed invariant is a bug, not bad input (bad input gets a SceneError).
#pragma once

#include <cstdio>
#include <cstdlib>

#define TESSERA_CHECK(cond)                                                                   \
  do {                                                                                        \
    if (!(cond)) {                                                                            \
      std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);           \
      std::abort();                                                                           \
    }                                                                                         \
  } while (0)

#ifdef NDEBUG
#define TESSERA_DCHECK(cond) \
  do {                       \
  } while (0)
#else
#define TESSERA_DCHECK(cond) TESSERA_CHECK(cond)
#endif

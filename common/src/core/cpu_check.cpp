// Refuses to run on a CPU without the SIMD baseline the binary was built for (CMake TESSERA_SIMD).
// Without it, the first AVX instruction would end the process with SIGILL and no word why. Runs
// before main and before other static initialisers; the linker keeps it through the
// --undefined=tessera_cpu_check option that tessera_common passes to every program.
#include <cstdio>
#include <cstdlib>

extern "C" __attribute__((constructor(101))) void tessera_cpu_check() {
#if defined(__AVX2__)
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2")) {
    std::fputs("tessera: this program was built for AVX2 (TESSERA_SIMD=avx2) and this CPU has none; "
               "rebuild with cmake -DTESSERA_SIMD=sse2\n",
               stderr);
    std::_Exit(1);
  }
#endif
}

#include "tessera/core/huge_page_allocator.h"

#include <sys/mman.h>

#include <cstdlib>

namespace tessera {

void* huge_page_alloc(size_t bytes) {
  constexpr size_t kHuge = size_t(2) << 20;
  const size_t align = bytes >= kHuge ? kHuge : 64;
  const size_t rounded = (bytes + align - 1) / align * align;
  void* p = std::aligned_alloc(align, rounded == 0 ? align : rounded);
  if (!p) throw std::bad_alloc();
  // Advice only: without THP the pages are ordinary ones, and nothing else changes.
  if (align == kHuge) (void)madvise(p, rounded, MADV_HUGEPAGE);
  return p;
}

void huge_page_free(void* p) noexcept { std::free(p); }

}  // namespace tessera

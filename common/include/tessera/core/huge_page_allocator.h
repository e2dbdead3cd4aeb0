// Allocator for the renderer's big arrays (BVH nodes, triangle packets, build scratch): blocks of
// 2 MiB and more are 2 MiB-aligned and marked MADV_HUGEPAGE, so Linux backs them with transparent
// huge pages where THP is in "madvise" mode (Debian's default). A first touch then faults once per
// 2 MiB instead of once per 4 KiB (on a virtual machine a fault costs microseconds: the BVH build
// spent a third of its time in them), and incoherent rays miss the TLB far less. Elements are
// default-initialised, so resize() leaves trivial ones unwritten for a parallel fill.
#pragma once

#include <cstddef>
#include <new>
#include <utility>
#include <vector>

namespace tessera {

/// Aligned to 64 bytes at least; 2 MiB-aligned and advised for huge pages from 2 MiB up. Throws
/// std::bad_alloc. Free with huge_page_free.
void* huge_page_alloc(size_t bytes);
void huge_page_free(void* p) noexcept;

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
  T* allocate(size_t n) {
    static_assert(alignof(T) <= 64);
    return static_cast<T*>(huge_page_alloc(n * sizeof(T)));
  }
  void deallocate(T* p, size_t) noexcept { huge_page_free(p); }
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

template <class T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace tessera

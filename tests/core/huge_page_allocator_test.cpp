// The big-array allocator: alignment (2 MiB from 2 MiB up, 64 bytes below), contents kept across
// growth, and huge pages actually granted where the kernel's THP mode allows them.
#include "tessera/core/huge_page_allocator.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>

namespace tessera {
namespace {

TEST(HugePageAllocator, AlignsSmallAndLargeBlocks) {
  HugeVector<uint8_t> small(100);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(small.data()) % 64, 0u);
  HugeVector<uint64_t> large(size_t(3) << 18);  // 6 MiB
  EXPECT_EQ(reinterpret_cast<uintptr_t>(large.data()) % (size_t(2) << 20), 0u);
}

TEST(HugePageAllocator, KeepsContentsWhenGrowing) {
  HugeVector<uint32_t> v;
  for (uint32_t i = 0; i < 1000000; ++i) v.push_back(i * 7u);
  for (uint32_t i = 0; i < 1000000; i += 9973) ASSERT_EQ(v[i], i * 7u);
  HugeVector<uint32_t> copy = v;
  EXPECT_EQ(copy, v);
}

/// AnonHugePages of this process, in kB (0 when the kernel reports none).
long anon_huge_kb() {
  std::ifstream smaps("/proc/self/smaps_rollup");
  std::string key;
  long value = 0;
  while (smaps >> key) {
    if (key == "AnonHugePages:") {
      smaps >> value;
      return value;
    }
    smaps.ignore(1 << 10, '\n');
  }
  return 0;
}

TEST(HugePageAllocator, GetsHugePagesWhenTheKernelAllowsThem) {
  std::ifstream mode_file("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string mode((std::istreambuf_iterator<char>(mode_file)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(mode.empty()) << "no /sys/kernel/mm/transparent_hugepage/enabled";
  const bool thp = mode.find("[never]") == std::string::npos;
  const long before = anon_huge_kb();
  HugeVector<uint8_t> block(size_t(16) << 20);
  for (size_t i = 0; i < block.size(); i += 4096) block[i] = 1;  // touch every page
  const long after = anon_huge_kb();
  if (thp)
    EXPECT_GT(after, before) << "THP mode: " << mode;  // "always" or "madvise": the advice is taken
  else
    EXPECT_EQ(after, before) << "THP mode: " << mode;  // "never": ordinary pages, nothing else changes
}

}  // namespace
}  // namespace tessera

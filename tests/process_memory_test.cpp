// keep_freed_memory_for_reuse: a freed block of a long rod's Jacobian size is handed out again
// from the heap instead of being mapped afresh. Counted by glibc's own statistics (mallinfo2:
// hblks is the number of blocks that have their own mapping), so it runs only where glibc's
// malloc is the one in use: not under AddressSanitizer, which brings its own (and whose build
// here, with clang, does not define __SANITIZE_ADDRESS__: the test asks malloc itself).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "kirchhoff/jobs/process_memory.hpp"

namespace kirchhoff {
namespace {

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
// Blocks with a mapping of their own while one block of `bytes` is held.
std::size_t own_mappings_while_holding(std::size_t bytes) {
  void* block = std::malloc(bytes);
  EXPECT_NE(block, nullptr);
  std::memset(block, 1, 4096);  // touched, so that no compiler drops the allocation
  const std::size_t mappings = mallinfo2().hblks;
  std::free(block);
  return mappings;
}
#endif

TEST(ProcessMemoryTest, LargeBlocksComeFromTheHeapOnceKept) {
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
  // 143 MB: the dense Jacobian of the exact ply at L/2R = 1000 (4,236 unknowns).
  constexpr std::size_t kJacobianBytes = std::size_t{4236} * 4236 * sizeof(double);
  const std::size_t before = mallinfo2().hblks;
  // glibc's default: a block this large gets its own mapping (its dynamic threshold stops at 32 MB).
  // Where it does not, another malloc (a sanitizer's) answers mallinfo2, and there is nothing to test.
  if (own_mappings_while_holding(kJacobianBytes) != before + 1) GTEST_SKIP() << "glibc's malloc is not the one in use";
  ASSERT_TRUE(keep_freed_memory_for_reuse());
  EXPECT_EQ(own_mappings_while_holding(kJacobianBytes), before);
  // Freed and asked for again: the same pages, still in the heap (not trimmed back to the system).
  void* first = std::malloc(kJacobianBytes);
  const std::size_t arena = mallinfo2().arena;
  std::free(first);
  EXPECT_EQ(mallinfo2().arena, arena);
  void* second = std::malloc(kJacobianBytes);
  EXPECT_EQ(second, first);
  std::free(second);
#else
  GTEST_SKIP() << "glibc's malloc is not the one in use";
#endif
}

}  // namespace
}  // namespace kirchhoff

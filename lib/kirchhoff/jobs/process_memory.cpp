#include "kirchhoff/jobs/process_memory.hpp"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace kirchhoff {

bool keep_freed_memory_for_reuse() {
#if defined(__GLIBC__)
  // Blocks up to 1 GiB come from the heap rather than their own mappings; the heap's free top is
  // returned to the system only beyond INT_MAX bytes (mallopt takes an int).
  constexpr int kHeapBlocksUpTo = 1 << 30;
  const bool threshold = mallopt(M_MMAP_THRESHOLD, kHeapBlocksUpTo) == 1;
  const bool trim = mallopt(M_TRIM_THRESHOLD, INT_MAX) == 1;
  return threshold && trim;
#else
  return false;
#endif
}

}  // namespace kirchhoff

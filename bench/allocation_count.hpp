// Counts the calls of malloc, calloc and realloc in the process that includes this header (one
// translation unit of a benchmark executable; never the library): the issue's "no allocation per
// evaluation" as a number, machine-independent. The executable's malloc interposes glibc's and
// forwards to it (__libc_malloc and friends), so memory is glibc's and free() is untouched. Eigen's
// dynamic matrices and the standard containers allocate through these.
#pragma once

#include <atomic>
#include <cstddef>

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
}

namespace kirchhoff::bench {
inline std::atomic<long> g_allocations{0};
inline long allocations() { return g_allocations.load(std::memory_order_relaxed); }
}  // namespace kirchhoff::bench

extern "C" {
void* malloc(std::size_t size) {
  kirchhoff::bench::g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  kirchhoff::bench::g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) {
  kirchhoff::bench::g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(pointer, size);
}
}

// How the process's heap treats the large blocks a long rod's continuation allocates and frees.
#pragma once

namespace kirchhoff {

// Keep freed blocks of up to a gibibyte in the process's heap for the next allocation, instead
// of handing each large one back to the system when it is freed (glibc's malloc: its mmap
// threshold and trim threshold raised).
//
// Why: the dense Jacobian of a multiple-shooting rod with thousands of unknowns is over a hundred
// megabytes (4,236 unknowns, the exact ply at L/2R = 1000: 143 MB), and the continuation
// allocates several per point, with the sparse LU's work arrays beside them. By default glibc
// maps each such block afresh and unmaps it on free, so every new matrix is page-faulted in and
// zeroed by the kernel again: on that ply a third of the run's time. Kept in the heap, the next
// matrix reuses the same pages.
//
// Process-wide and for the rest of the process: its resident memory stays at its peak. The CLI
// calls it when it starts; a program using the library, or Python (kirchhoff.keep_freed_memory),
// opts in. Returns false where the C library has no such setting (nothing changes then).
bool keep_freed_memory_for_reuse();

}  // namespace kirchhoff

// `kirchhoff sweep SPEC.toml --out DIR [--resume]`: the jobs of a sweep file (sweep.hpp), run
// serially, or under mpirun / srun by the MPI scheduler (sweep_mpi.hpp) in `kirchhoff-mpi`, the
// CLI built with MPI (apps/CMakeLists.txt), which `kirchhoff` hands such a run to. Argument
// mapping only; the work is in the library.
#pragma once

#include <string>

namespace kirchhoff::cli {

struct SweepArguments {
  std::string spec_path;
  std::string out_dir = "sweep";
  bool resume = false;
  bool manager_only = false;  // MPI: rank 0 hands out jobs and runs none
  bool quiet = false;         // no progress line per job
  char** command_line = nullptr;  // main's argv: what `kirchhoff` hands to `kirchhoff-mpi` under MPI
};

// Exit status: 0 when every job has its result (whatever its status: failed jobs are recorded in
// the index, never stop the sweep), 2 when the sweep file or the folder is refused.
int run_sweep(const SweepArguments& args);

}  // namespace kirchhoff::cli

#include "sweep_command.hpp"

#include <iostream>

#include "kirchhoff/sweeps/sweep.hpp"
#include "kirchhoff/sweeps/sweep_run.hpp"
#include "solve_command.hpp"
#ifdef KIRCHHOFF_HAVE_MPI
#include "kirchhoff/sweeps/detail/sweep_mpi.hpp"
#endif

namespace kirchhoff::cli {

int run_sweep(const SweepArguments& args) {
  const int launched = launcher_process_count();
  SweepSpec spec;
  try {
    spec = load_sweep(args.spec_path);
  } catch (const SweepError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  SweepRunOptions options;
  options.out_dir = args.out_dir;
  options.resume = args.resume;
  if (!args.quiet) options.progress = [](const std::string& line) { std::cerr << line << std::endl; };
  SweepSummary summary;
  int rank = 0;
  try {
#ifdef KIRCHHOFF_HAVE_MPI
    if (launched > 0) {
      SweepMpiOptions mpi;
      mpi.run = options;
      mpi.manager_runs_jobs = !args.manager_only;
      summary = run_sweep_mpi(spec, mpi, &rank);
    } else {
      summary = kirchhoff::run_sweep(spec, options);
    }
#else
    if (launched > 1) {
      std::cerr << "error: started as one of " << launched
                << " MPI processes, but this kirchhoff was built without MPI: each would run the whole sweep "
                   "into the same folder. Install libopenmpi-dev and rebuild, or run the sweep without mpirun\n";
      return kExitBadInput;
    }
    summary = kirchhoff::run_sweep(spec, options);
#endif
  } catch (const SweepError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (rank != 0) return kExitOk;
  std::cerr << args.out_dir << "/index.csv: " << summary.jobs << " jobs, " << summary.ran << " run now, "
            << summary.skipped << " finished before, " << summary.failed << " not ok";
  if (summary.dispatches > 0)
    std::cerr << "; workers waited " << 1e3 * summary.dispatch_wait_seconds / summary.dispatches
              << " ms per job for the manager";
  std::cerr << "\n";
  return kExitOk;
}

}  // namespace kirchhoff::cli

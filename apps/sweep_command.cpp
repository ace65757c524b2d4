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
    if (launcher_process_count() > 0) {
      SweepMpiOptions mpi;
      mpi.run = options;
      mpi.manager_runs_jobs = !args.manager_only;
      summary = run_sweep_mpi(spec, mpi, &rank);
    } else {
      summary = kirchhoff::run_sweep(spec, options);
    }
#else
    summary = kirchhoff::run_sweep(spec, options);  // (refuses to be one of several MPI copies)
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

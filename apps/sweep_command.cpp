#include "sweep_command.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "kirchhoff/sweeps/sweep.hpp"
#include "kirchhoff/sweeps/sweep_run.hpp"
#include "solve_command.hpp"
#ifdef KIRCHHOFF_HAVE_MPI
#include "kirchhoff/sweeps/detail/sweep_mpi.hpp"
#endif

namespace kirchhoff::cli {
namespace {

#ifdef KIRCHHOFF_MPI_SIBLING
// Under an MPI launcher, `kirchhoff` (built without MPI, so that no other command loads OpenMPI)
// replaces itself by the CLI built with it, installed beside it, with the same arguments: the
// process keeps the launcher's environment, and with it its place among the ranks. Returns only
// when that fails, saying why; the serial sweep then refuses to be one of several copies.
void hand_over_to_mpi_build(char** command_line) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error || command_line == nullptr) return;
  const std::string sibling = (self.parent_path() / KIRCHHOFF_MPI_SIBLING).string();
  ::execv(sibling.c_str(), command_line);
  std::cerr << "warning: cannot start " << sibling << " for the MPI sweep: " << std::strerror(errno) << "\n";
}
#endif

SweepSummary run_jobs(const SweepSpec& spec, const SweepRunOptions& options, const SweepArguments& args,
                      int* rank) {
#ifdef KIRCHHOFF_HAVE_MPI
  if (launcher_process_count() > 0) {
    SweepMpiOptions mpi;
    mpi.run = options;
    mpi.manager_runs_jobs = !args.manager_only;
    return run_sweep_mpi(spec, mpi, rank);
  }
#else
  (void)args;
  (void)rank;
#endif
  return kirchhoff::run_sweep(spec, options);  // (refuses to be one of several MPI copies)
}

}  // namespace

int run_sweep(const SweepArguments& args) {
#ifdef KIRCHHOFF_MPI_SIBLING
  if (launcher_process_count() > 0) hand_over_to_mpi_build(args.command_line);
#endif
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
    summary = run_jobs(spec, options, args, &rank);
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

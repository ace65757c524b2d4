// The sweep under MPI (mpirun -n K, srun): rank 0 is the manager, the others workers.
//
// The manager keeps the queue of jobs to run (prepare_sweep_folder: --resume skips finished
// ones), ordered by decreasing cost hint (SweepJob::cost; ties in job order), and hands out one
// job at a time to whichever rank asks: dynamic scheduling, since jobs differ in cost by orders of
// magnitude. A worker runs its job (run_sweep_job writes the job's folder), reports the outcome
// and its wall time, and asks again. Unless `manager_runs_jobs` is off, the manager runs jobs
// too, on a thread of its own between messages (its main thread only answers them), so that with
// -n 2 both cores compute; with hundreds of ranks it may be turned off so that no answer waits.
// The manager writes times.csv as outcomes arrive and, once every job is done, the index
// (write_sweep_index) from the job folders: the same files as the serial sweep. DIR must be on a
// file system every rank sees.
//
// Built only when CMake finds MPI (KIRCHHOFF_HAVE_MPI, target kirchhoff_sweep_mpi); the serial
// sweep (sweep_run.hpp) never needs it.
#pragma once

#include "kirchhoff/sweeps/sweep_run.hpp"

namespace kirchhoff {

struct SweepMpiOptions {
  SweepRunOptions run;
  bool manager_runs_jobs = true;
};

// Initialises MPI (MPI_THREAD_FUNNELED), runs the sweep over MPI_COMM_WORLD and finalises.
// Every rank returns; the summary (with the index) is complete on rank 0 only, `*rank` tells
// which this is. A SweepError while preparing the folder (on rank 0) stops every rank: it is
// rethrown on rank 0, the others return an empty summary.
SweepSummary run_sweep_mpi(const SweepSpec& spec, const SweepMpiOptions& options, int* rank);

}  // namespace kirchhoff

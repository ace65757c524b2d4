// Running a sweep's jobs (sweep.hpp) and what they leave in the output folder DIR:
//   DIR/jobs/<id>/result.json   the job's result (status, reason, parameters, contact state,
//                               stability index, derived quantities, contacts; per equilibrium
//                               for equilibria jobs), written once the job has finished
//   DIR/jobs/<id>/*.csv         profiles (solve: profile.csv; equilibria: equilibrium_K.csv), the
//                               branch (continue: branch.csv) or branches (plectonemes:
//                               plectoneme_<L/2R>.csv and their state files)
//   DIR/index.csv               one row per job in job order, rebuilt from the result files
//   DIR/times.csv               job, wall seconds, rank: one line per job run, as they finish
// A job's folder is written as DIR/jobs/.<id>.partial and renamed when complete, so a job either
// has its whole folder or none: a sweep killed at any point and resumed (--resume runs exactly the
// jobs without a folder) leaves the same files as one never interrupted. The index holds nothing
// that depends on when or where a job ran, so it is byte-identical whatever the order, the rank
// count or the interruptions; wall times go to times.csv instead.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "kirchhoff/model/obstacle.hpp"
#include "kirchhoff/sweeps/sweep.hpp"

namespace kirchhoff {

// A job's contact state from its active contacts: "none", "point" (one point contact), "flat"
// (one extended contact on a plane), "wrap" (one extended contact on a curved obstacle), "hanging_fold"
// (two point contacts on one obstacle: the hanging fold of a rod on a wall; not the status `fold`) or "several".
std::string contact_state(const std::vector<Obstacle>& obstacles, const std::vector<PointContact>& contacts);

struct JobOutcome {
  std::string status;  // "ok", or the failure's status word
  std::string reason;  // why, for a failure
  double seconds = 0.0;
};

// Where a sweep's progress lines go, without their newline; unset: nowhere.
using SweepProgress = std::function<void(const std::string&)>;

// Runs one job and writes its folder under dir (dir/jobs must exist). A failing job (not
// converged, refused, an exception from the solver) is an outcome with its status, not an
// exception; throws std::runtime_error only when the folder cannot be written. A long job's own
// progress lines go to `progress`, prefixed with the job's id: a plectonemes job's, as
// `kirchhoff plectonemes` prints them ("ply: L/2R = 100  point 50  turns = 3.1").
JobOutcome run_sweep_job(const SweepJob& job, const std::string& dir, const SweepProgress& progress = {});

// Readies DIR for the sweep and returns the positions (in spec.jobs) of the jobs to run, in job
// order. Without resume a folder that already holds job results is refused (SweepError); with
// resume finished jobs are skipped after checking that each was computed for the same job
// (SweepError when the sweep file changed under the ids), and partial folders are removed.
std::vector<int> prepare_sweep_folder(const SweepSpec& spec, const std::string& dir, bool resume);

// Appends "job,seconds,rank" to DIR/times.csv.
void record_job_time(const std::string& dir, const std::string& id, double seconds, int rank);

// The merged index: columns job, kind, the swept parameters, status, reason, contact_state,
// stable_states, stability_index, equilibria, energy, then the cases' derived quantities. Cells
// are text as in index.csv (numbers in the shortest form that reads back to the same double,
// empty where not defined); numeric[k] tells which columns hold numbers.
struct SweepIndex {
  std::vector<std::string> columns;
  std::vector<bool> numeric;
  std::vector<std::vector<std::string>> rows;
};
// Builds the index from the job results in job order (a job without a result: status
// "not_run") and writes DIR/index.csv atomically.
SweepIndex write_sweep_index(const SweepSpec& spec, const std::string& dir);

struct SweepRunOptions {
  std::string out_dir;
  bool resume = false;
  // One line per job as it finishes ("[3/40] phase-003 a=0.1 Delta=0.02: ok (1.2 s)"), and the
  // progress lines of long jobs as they run (run_sweep_job).
  SweepProgress progress;
};

struct SweepSummary {
  int jobs = 0;     // in the sweep
  int ran = 0;      // by this run
  int skipped = 0;  // finished before (--resume)
  int failed = 0;   // of all jobs, status other than ok
  SweepIndex index;
  // MPI: how long workers waited from asking for a job to getting it, summed, and how many
  // jobs they were handed after finishing one (the manager's overhead per job is the ratio).
  double dispatch_wait_seconds = 0.0;
  int dispatches = 0;
};

// The serial sweep: every job to run, in job order, then the index. Throws SweepError (bad
// input) when this process is one of several an MPI launcher started (launcher_process_count).
SweepSummary run_sweep(const SweepSpec& spec, const SweepRunOptions& options);

// "[k/n] id a=0.1 Delta=0.02: status (1.2 s)" as progress lines say it.
std::string describe_job_end(const SweepJob& job, const JobOutcome& outcome, int done, int total);

// The number of processes an MPI launcher started this one among (mpirun, mpiexec, srun), from
// the variables they set (OMPI_COMM_WORLD_SIZE, PMI_SIZE, SLURM_STEP_NUM_TASKS); 0 when
// none is set. The CLI uses it to choose the MPI scheduler; run_sweep (the serial sweep, the CLI's
// without MPI and Python's) refuses to run as one of K > 1 copies into one folder.
int launcher_process_count();

}  // namespace kirchhoff

#include "kirchhoff/sweeps/detail/sweep_mpi.hpp"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <iostream>
#include <sstream>
#include <thread>

namespace kirchhoff {
namespace {

constexpr int kManager = 0;
constexpr int kTagReady = 1;  // worker -> manager: "job\tseconds\twait\tstatus\treason" (job -1: first request)
constexpr int kTagJob = 2;    // manager -> worker: the job's position in spec.jobs, -1: stop
// How long the manager's main thread sleeps when there is neither a message nor a finished local
// job: it bounds the latency of an answer (and so the overhead per job) at about this, while the
// polling costs about 1e-3 of a core.
constexpr auto kPollInterval = std::chrono::microseconds(200);

using Clock = std::chrono::steady_clock;

// Ipopt's sequential MUMPS (libdmumps_seq) exports stubs of MPI_Init, MPI_Comm_rank, MPI_Finalize
// and MPI_Wtime, and comes before libmpi in the executable's libraries: MPI_Comm_rank would then
// answer 0 on every rank. Their profiling names (PMPI_, which every MPI defines and the stubs do
// not) reach the real MPI whatever the link order.
int world_rank() {
  int rank = 0;
  PMPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

struct Report {
  int job = -1;
  JobOutcome outcome;
  double wait = 0.0;  // how long the worker waited for its previous job after asking
};

std::string encode(const Report& r) {
  std::ostringstream os;
  os.precision(17);
  os << r.job << "\t" << r.outcome.seconds << "\t" << r.wait << "\t" << r.outcome.status << "\t" << r.outcome.reason;
  return os.str();
}

Report decode(const std::string& text) {
  Report r;
  std::istringstream is(text);
  std::string field;
  std::getline(is, field, '\t');
  r.job = std::stoi(field);
  std::getline(is, field, '\t');
  r.outcome.seconds = std::stod(field);
  std::getline(is, field, '\t');
  r.wait = std::stod(field);
  std::getline(is, r.outcome.status, '\t');
  std::getline(is, r.outcome.reason);
  return r;
}

JobOutcome run_guarded(const SweepJob& job, const std::string& dir) {
  try {
    return run_sweep_job(job, dir);
  } catch (const std::exception& e) {
    // The job's folder could not be written: it stays unfinished (not_run), --resume runs it.
    JobOutcome outcome;
    outcome.status = "not_written";
    outcome.reason = e.what();
    return outcome;
  }
}

void worker(const SweepSpec& spec, const std::string& dir) {
  Report report;
  for (;;) {
    const std::string message = encode(report);
    const auto asked = Clock::now();
    MPI_Send(message.data(), static_cast<int>(message.size()), MPI_CHAR, kManager, kTagReady, MPI_COMM_WORLD);
    int job = -1;
    MPI_Recv(&job, 1, MPI_INT, kManager, kTagJob, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    report.wait = std::chrono::duration<double>(Clock::now() - asked).count();
    if (job < 0) return;
    report.job = job;
    report.outcome = run_guarded(spec.jobs[static_cast<std::size_t>(job)], dir);
  }
}

SweepSummary manager(const SweepSpec& spec, const SweepMpiOptions& options, std::vector<int> queue, int size) {
  const std::string& dir = options.run.out_dir;
  // Largest first where costs are known; equal costs in job order (stable).
  std::stable_sort(queue.begin(), queue.end(), [&spec](int a, int b) {
    return spec.jobs[static_cast<std::size_t>(a)].cost > spec.jobs[static_cast<std::size_t>(b)].cost;
  });
  SweepSummary summary;
  summary.jobs = static_cast<int>(spec.jobs.size());
  summary.skipped = summary.jobs - static_cast<int>(queue.size());
  int done = summary.skipped;
  std::size_t next = 0;
  int workers_running = size - 1;
  const bool local = options.manager_runs_jobs || size == 1;

  auto finished = [&](const Report& r, int rank) {
    const SweepJob& job = spec.jobs[static_cast<std::size_t>(r.job)];
    record_job_time(dir, job.id, r.outcome.seconds, rank);
    ++summary.ran;
    if (options.run.progress) options.run.progress(describe_job_end(job, r.outcome, ++done, summary.jobs));
  };

  std::future<JobOutcome> local_run;
  int local_job = -1;
  std::vector<char> buffer;
  while (workers_running > 0 || local_job >= 0 || (local && next < queue.size())) {
    bool busy = false;
    if (local_job >= 0 && local_run.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
      Report r;
      r.job = local_job;
      r.outcome = local_run.get();
      finished(r, kManager);
      local_job = -1;
      busy = true;
    }
    if (local && local_job < 0 && next < queue.size()) {
      local_job = queue[next++];
      const SweepJob* job = &spec.jobs[static_cast<std::size_t>(local_job)];
      local_run = std::async(std::launch::async, [job, &dir] { return run_guarded(*job, dir); });
      busy = true;
    }
    if (workers_running > 0) {
      // Probed and slept on rather than blocked on: a blocking MPI_Probe spins (OpenMPI polls at
      // full speed), taking a core from the jobs when ranks share cores.
      int flag = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, kTagReady, MPI_COMM_WORLD, &flag, &status);
      if (flag) {
        int count = 0;
        MPI_Get_count(&status, MPI_CHAR, &count);
        buffer.resize(static_cast<std::size_t>(std::max(count, 1)));
        MPI_Recv(buffer.data(), count, MPI_CHAR, status.MPI_SOURCE, kTagReady, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        const Report r = decode(std::string(buffer.data(), static_cast<std::size_t>(count)));
        if (r.job >= 0) {
          finished(r, status.MPI_SOURCE);
          summary.dispatch_wait_seconds += r.wait;
          ++summary.dispatches;
        }
        const int job = next < queue.size() ? queue[next++] : -1;
        MPI_Send(&job, 1, MPI_INT, status.MPI_SOURCE, kTagJob, MPI_COMM_WORLD);
        if (job < 0) --workers_running;
        busy = true;
      }
    }
    if (!busy) std::this_thread::sleep_for(kPollInterval);
  }
  summary.index = write_sweep_index(spec, dir);
  const auto status = std::find(summary.index.columns.begin(), summary.index.columns.end(), "status") -
                      summary.index.columns.begin();
  for (const auto& row : summary.index.rows)
    if (row[static_cast<std::size_t>(status)] != "ok") ++summary.failed;
  return summary;
}

}  // namespace

SweepSummary run_sweep_mpi(const SweepSpec& spec, const SweepMpiOptions& options, int* rank_out) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  struct Finalise {
    ~Finalise() { PMPI_Finalize(); }  // not MPI_Finalize: see world_rank
  } finalise;
  int rank = 0, size = 1;
  rank = world_rank();
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (rank_out) *rank_out = rank;

  std::vector<int> queue;
  std::string error;
  if (rank == kManager) {
    try {
      queue = prepare_sweep_folder(spec, options.run.out_dir, options.run.resume);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  int refused = error.empty() ? 0 : 1;
  MPI_Bcast(&refused, 1, MPI_INT, kManager, MPI_COMM_WORLD);
  if (refused) {
    if (rank == kManager) throw SweepError(error);
    return {};
  }
  if (rank != kManager) {
    worker(spec, options.run.out_dir);
    return {};
  }
  return manager(spec, options, std::move(queue), size);
}

}  // namespace kirchhoff

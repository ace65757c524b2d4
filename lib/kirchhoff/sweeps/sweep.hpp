// Sweep files: many runs of one case (or a few) over a grid or a list of parameter values, as
// `kirchhoff sweep` runs them serially or under MPI (sweep_run.hpp, sweep_mpi.hpp). The format is
// in docs/sweeps.md; in short:
//
//   title = "..."
//   case = "../cases/wall.toml"        # relative to the sweep file's folder
//   set = { m_guess = 0.9 }            # overrides of every job (optional)
//   [[jobs]]
//   name = "phase"                     # job ids: phase-001, phase-002, ... (default: the kind)
//   kind = "solve"                     # solve | equilibria | continue | plectonemes
//   grid = { a = [0.05, 0.1], Delta = { from = 0.005, to = 0.06, count = 12 } }
//   # or list = [{ a = 0.1, Delta = 0.02 }, ...]; values, ranges and log ranges
//   # ({ from = 1e-4, to = 1e-1, count = 4, log = true })
//
// Every problem is a SweepError naming the file, the line (where TOML knows it), the key and the
// reason, as case files do (case_file.hpp).
#pragma once

#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kirchhoff/jobs/case_file.hpp"

namespace kirchhoff {

struct SweepError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class SweepJobKind { Solve, Equilibria, Continue, Plectonemes };
const char* to_string(SweepJobKind kind);

// One run: a case at given parameter values, and what to do there.
struct SweepJob {
  std::string id;             // "<name>-<k>", k from 1 in expansion order, zero-padded
  int order = 0;              // position in the sweep (the index's row)
  SweepJobKind kind = SweepJobKind::Solve;
  std::string case_path;      // as the job opens it (resolved against the sweep file's folder)
  std::string case_name;      // as the sweep file writes it (results name it: they do not depend on the folder)
  ParameterOverrides values;  // the swept parameters, in the sweep's column order
  ParameterOverrides set;     // fixed overrides (the sweep's, then the group's)
  SolverOverrides solver;     // [solver] overrides (the group's `solver` table)
  double cost = 1.0;          // relative cost: under MPI larger jobs are handed out first
  // solve: Newton from the guess at the values instead of the homotopy from the case's own.
  bool direct = false;
  double max_seconds = 120.0;  // wall-clock limit of the job's solve or search (0: none)
  int max_equilibria = 16;     // equilibria
  bool profiles = true;        // write the profile CSV(s)
  // continue: a branch in `param` (case_continue.hpp), to `to` (NaN: no target) within
  // max_points, with these pseudo-arclength steps; branch points and stability as `continue`.
  std::string param;
  double to = std::numeric_limits<double>::quiet_NaN();
  int max_points = 500;
  double step = 0.05, min_step = 1e-7, max_step = 0.5;
  bool branch_points = true;
  bool stability = true;
  // plectonemes: a branch of the case (plectoneme.toml) at the job's values of `slenderness` and
  // `turns` (its largest turns), from the untwisted rod (plectoneme_sweep.hpp), or with from_ply
  // > 0 from the ply of that thicker slenderness followed first, in the job, up to from_ply_turns;
  // hard_from > 0: the ply with exact contact from that many turns (`plectonemes --hard-from`).
  double from_ply = 0.0;
  double from_ply_turns = 20.0;
  double hard_from = 0.0;
  // What the job is, as one line of text: a finished job's result records it, and --resume
  // refuses a folder whose results were computed for other jobs under the same ids.
  std::string fingerprint() const;
  // The overrides the job's case is loaded with: `set`, then the swept values (which win).
  ParameterOverrides overrides() const;
};

struct SweepSpec {
  std::string path;   // the sweep file
  std::string title;
  std::vector<std::string> parameter_columns;  // every swept name, in order of appearance
  std::vector<std::string> derived_columns;    // the cases' [output] derived names, in order
  std::vector<SweepJob> jobs;                  // in job order (deterministic)
};

// Bounds on what a sweep file may ask for.
namespace sweep_limits {
// A sweep file is a few kB, like a case file.
constexpr std::size_t kMaxFileBytes = std::size_t{1} << 20;
// Jobs in one sweep: a 1000 x 1000 map. Each job is a folder and an index row.
constexpr std::size_t kMaxJobs = 1000000;
}  // namespace sweep_limits

// Reads, validates and expands the sweep file. Each group's case is loaded once with its
// overrides, so unknown parameters and bad cases are refused here, before any job runs.
SweepSpec load_sweep(const std::string& path);
// The same from the file's text; `path` names it in messages and relative case paths are
// resolved against its folder.
SweepSpec load_sweep_text(const std::string& text, const std::string& path);

}  // namespace kirchhoff

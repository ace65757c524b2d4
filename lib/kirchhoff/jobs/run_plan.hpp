// Where a continuation run starts, planned from what its front end was given (`kirchhoff
// continue` and Python's continue_ both call plan_run, so they refuse and report alike): the
// state of an interrupted run to resume, another run's last point to start from, or the case's
// own start; and the parameter values the case is loaded with for it.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "kirchhoff/jobs/case_continue.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/run_state.hpp"

namespace kirchhoff {

struct RunPlanInputs {
  std::string case_path;
  ParameterOverrides overrides;  // the front end's --set
  std::string phase_condition;   // as load_case takes it
  SolverOverrides solver;
  // Resume the interrupted run whose state file is state_path. csv_path, when the run writes a
  // branch CSV: a run killed before it saved its first point has no state file and at most the
  // start's row, and resuming it starts it again; more rows and no state are refused.
  bool resume = false;
  std::filesystem::path state_path;
  std::filesystem::path csv_path;
  // Another run's state file to start from (at its last point), and the continued parameter's
  // name for files older than the record of it.
  std::string start_from;
  std::string start_param;
};

struct RunPlan {
  Case c;                         // loaded with the run's parameter values
  std::optional<RunStart> start;  // start_from: where, and which values differ from the file's
  std::vector<std::string> notes; // what the front end says before the run (a resume that restarts)
};

// Fills request->identity (run_identity, unless the caller gave one), request->resume / start /
// start_name / set_parameters and validates the request on the loaded case. `loaded`, when
// given, is the case as the front end loaded it with `overrides`: used as is where the run keeps
// those values. Throws CaseError (or std::invalid_argument for a state file that cannot be used,
// a CaseError for one that cannot be read) with the reason; the front ends report it as bad
// input.
RunPlan plan_run(const RunPlanInputs& in, ContinueRequest* request, const Case* loaded = nullptr);

// What identifies a run (ContinueRequest::identity, recorded in its state; a resume whose state
// records another is refused): the case file (its canonical path and a hash of its bytes), the
// values and solver settings it was given (as numbers: "P=1" and "P=1.0" are one run), and every
// field of the request that decides its points. The same for the CLI and Python, so that either
// can resume a run the other started.
std::string run_identity(const RunPlanInputs& in, const ContinueRequest& request);

// The data rows of a branch CSV (0 when there is none).
int branch_csv_rows(const std::filesystem::path& path);

}  // namespace kirchhoff

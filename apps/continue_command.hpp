// `kirchhoff continue`: pseudo-arclength continuation of a case in one parameter, written to a
// CSV point by point, resumable after being killed. The arguments are mapped onto
// kirchhoff::continue_case (case_continue.hpp), which does the run.
#pragma once

#include <string>
#include <vector>

#include "solve_command.hpp"

namespace kirchhoff::cli {

struct ContinueArguments {
  std::string case_path;
  std::vector<std::string> overrides;
  std::vector<std::string> solver;     // --solver KEY=VALUE: [solver] keys
  std::string phase_condition;
  std::string parameter;
  double to = 0.0;
  bool has_to = false;
  double direction = 1.0;     // +1 / -1: which way the parameter goes first without --to
  double step = 0.05;
  double min_step = 1e-7;
  double max_step = 0.5;
  int max_points = 500;
  int switch_at_bp = 0;       // > 0: switch onto the branch bifurcating at the K-th branch point
  bool no_branch_points = false;  // skip the branch-point test functions (an SVD per point)
  bool no_stability = false;      // skip the stability index of every point
  double switch_side = 1.0;   // +1 / -1: which side of the bifurcating branch
  std::vector<std::string> stop_events;    // NAME=VALUE: stop when crossed
  std::vector<std::string> record_events;  // NAME=VALUE: record when crossed
  std::string out_path = "branch.csv";
  std::string profiles_dir;
  bool resume = false;
  int samples = 101;
  StartSeed seed;             // where the first point is solved from (not used on --resume)
  // Start from the last resumable point of another run's state file (e.g. a ply found by
  // continuation in turns, now continued in slenderness); that run's parameter is set to the
  // point's value. start_param names it for state files written before they recorded it.
  std::string start_from;
  std::string start_param;
  double max_seconds = 0.0;   // wall-clock limit of the run (0: none); it stops resumable, time_limit
  // The state file is saved after the first point, then at most once per this many seconds (0:
  // after every point), and at the end; a resume recomputes the rows after the last save.
  double checkpoint_seconds = 1.0;
  // --deflate: every branch through the equilibria found at the start (deflated_continuation.hpp),
  // at most deflate_max of them; branch k of the CSV starts at the k-th by energy.
  bool deflate = false;
  int deflate_max = 16;
};

int run_continue(const ContinueArguments& args);

}  // namespace kirchhoff::cli

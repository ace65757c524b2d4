// `kirchhoff plectonemes`: the Fig. 11 sweep - plectoneme branches of cases/plectoneme.toml for
// several slendernesses, each followed in the end rotation from the untwisted rod, written as
// CSV rows of T_ext rho^2/EI against the helical angle beside eq. (61).
#pragma once

#include <map>
#include <string>
#include <vector>

namespace kirchhoff::cli {

// Largest pseudo-arclength step at L/2R = 100: the unknowns are dominated by forces of 1e2-1e4
// there, so steps of tens are small.
inline constexpr double kPlectonemeMaxStep = 60.0;
inline constexpr int kPlectonemeReuseJacobian = 8;

struct PlectonemeBranchSummary {
  int points = 0;
  double seconds = 0.0;
  std::string stop;                         // the continuation's stop reason
  std::map<std::string, double> last;       // the CSV columns at the last point with a ply
  std::vector<std::map<std::string, double>> ply;  // the same at every point with a ply, in order
};

struct PlectonemeRunOptions {
  int progress_every = 0;                 // a progress line on stderr every this many points (0: none)
  double max_step = kPlectonemeMaxStep;   // at L/2R = 100, scaled with the forces (1/R^2)
  // A point whose chord iterations converged within this many keeps the previous Jacobian
  // (ContinuationOptions::reuse_jacobian_iterations; -1: every point computes its own).
  int reuse_jacobian = kPlectonemeReuseJacobian;
  // Continue a killed run from csv_path's state file (csv_path + ".state.json"); a branch whose
  // CSV ends at its endpoint is left as it is. Without a state file the branch starts afresh.
  bool resume = false;
};

// Follows cases/plectoneme.toml (at `case_path`) with slenderness set, from turns = 0 to
// turns_max, writing one CSV row per point to csv_path (flushed as it goes) and the state to
// resume from beside it. Throws on a case that does not solve at turns = 0. A resumed run's
// summary counts (and its `ply` holds) only the points computed after resuming.
PlectonemeBranchSummary follow_plectoneme_branch(const std::string& case_path, double slenderness, double turns_max,
                                                 const std::string& csv_path, const PlectonemeRunOptions& options);

struct PlectonemesArguments {
  std::string case_path;
  std::vector<double> slenderness{100, 200, 500, 1000};
  std::vector<double> turns{10, 20, 20, 50};
  std::string out_dir = "plectonemes";
  double max_step = kPlectonemeMaxStep;
  int reuse_jacobian = kPlectonemeReuseJacobian;
  bool resume = false;
};

int run_plectonemes(const PlectonemesArguments& args);

}  // namespace kirchhoff::cli

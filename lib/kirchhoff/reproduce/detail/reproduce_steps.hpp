// Internal (not installed): the result groups of `reproduce` (reproduce.hpp), one file each, and
// what they share. Each group appends its rows in the report's order and writes its figure data
// into the profiles folder.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/continuation/rod_continuation.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/reproduce/reproduce.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff::reproduce_steps {

namespace fs = std::filesystem;

// What every group is given: the cases folder, the folder of its figure data, the run's extent,
// where progress lines go (never empty) and the rows to append to.
struct Step {
  fs::path cases;
  fs::path out;  // out_dir/profiles
  bool full = false;
  ReproduceProgress progress;
  std::vector<ReportRow>* rows = nullptr;
};

// A case solved from its guess (no homotopy: each override set puts the guess near the wanted
// equilibrium), with its stability stated as the report prints it.
struct Solved {
  std::unique_ptr<ShootingProblem> problem;
  Solution solution;
  std::string stability;  // describe(analyse_stability(...))
};

// Throws std::runtime_error("<file>: <brief report>") when Newton does not converge.
Solved solve_for_report(const fs::path& file, const ParameterOverrides& overrides, int samples);

// What the points of a group's continuation are for, which decides what each records.
enum class ReportPoints {
  // Special points located (branch points, a target): the rows read their parameters and the
  // derived quantities asked for, not their profiles, so the invariants each point carries are
  // sampled on a coarse profile of 21 points.
  Located,
  // A branch followed for its derived quantities or its end: no invariants, the derived
  // quantities on the default profile of 101 points.
  Followed,
};

// The continuations the groups run, all of one shape: `parameter` towards `target` (NaN: none; an
// event or a branch switch ends the run) in pseudo-arclength steps up to `max_step` (each
// branch's own scale), recording `derived` at every point as `points` says.
RodContinuationOptions report_continuation(const std::string& parameter, double target, double max_step,
                                        ReportPoints points, const std::vector<std::string>& derived = {});

// 4 significant digits, as the notes print values.
std::string format_short(double v);

// Sets the stability of the last `count` rows.
void state_stability(std::vector<ReportRow>* rows, int count, const std::string& stability);

void simply_supported(const Step& step);   // Fig. 3 and eq. (54)
void tapered(const Step& step);            // Fig. 9 and eq. (57)
void invariants(const Step& step);         // Section 5
void continuation(const Step& step);       // Euler column and twisted rod bifurcations
void stability(const Step& step);          // stability indices of classical equilibria
void sleeves(const Step& step);            // Figs. 6-8
void wall(const Step& step);               // Fig. 12, hard and soft walls: the two below
// The hard wall's values that the soft wall's rows tend to as b -> 0.
struct HardWall {
  double H = 0.0, contact_force = 0.0, kappa_c = 0.0;
};
HardWall hard_wall(const Step& step);
void soft_wall(const Step& step, const HardWall& hard);
void vibrations(const Step& step);         // Section 9
void cavity(const Step& step);             // Section 7.2 / Fig. 5
void plectonemes(const Step& step);        // Fig. 11 with the self-contact barrier
void exact_plies(const Step& step);        // Fig. 11 with exact self-contact
void wall_phase_diagram(const Step& step, const fs::path& out_dir);  // full only

}  // namespace kirchhoff::reproduce_steps

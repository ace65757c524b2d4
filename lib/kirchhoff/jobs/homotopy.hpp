// Reaching new parameter values along the branch of equilibria a solution lies on.
//
// Newton from a guess at new values converges to whichever equilibrium attracts the guess: the
// simply supported Elastica asked for theta0 = 3.1 from the case's guess lands on a rod whose ends
// cross or that is pulled backwards. A homotopy instead joins the solution at the values a to the
// values b along
//     p(t) = (1 - t) a + t b,   t in [0, 1],
// in every changed parameter at once, and follows the equilibria by pseudo-arclength continuation
// in t (continuation.hpp; with obstacles, through changes of the contact set, contact.hpp). The
// equilibrium reached at t = 1 is then polished by Newton at exactly b.
//
// What the path meets is reported, never jumped over:
//   - a fold in t: the branch turns back before b, so no equilibrium at b lies on it this side
//     of the fold (the homotopy stops there, with the values at the fold; with through_folds it
//     goes on, and may turn again towards b);
//   - a simple branch point: the branch goes on smoothly through it and so does the path (it is
//     listed; the equilibrium's stability changes there, see stability.hpp);
//   - a contact set that changes (contacts appear, lift off, flatten), as continuation reports.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct ParameterChange {
  std::string name;
  double from = 0.0;
  double to = 0.0;
  double at(double t) const { return (1.0 - t) * from + t * to; }  // exactly `to` at t = 1
};

struct HomotopyOptions {
  int max_points = 5000;
  // No continuation step starts after this (a command's wall-clock limit).
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  // Problems with more unknowns than this (long multiple-shooting rods) are followed as the
  // plectoneme sweeps follow theirs: branch points are not looked for (an SVD of the bordered
  // matrix per point; the path says so), and the corrector keeps its matrix (modified Newton).
  int branch_point_unknown_limit = 400;
  // Follow the branch through folds in t instead of stopping at the first (`equilibria`'s carried
  // paths): a branch that turns back may turn again and reach b, with an equilibrium there that
  // no starting point at b reaches (the wall's hanging fold at Delta = 0.05, past the fold at
  // 0.0466 from the file's 0.026). The path then ends at b, or at max_points or the deadline.
  bool through_folds = false;
};

struct HomotopyResult {
  bool reached = false;   // t = 1 reached and the equilibrium there polished by Newton
  std::string stop;       // "reached", or why not: "fold", "step_too_small", "max_points",
                          // "time_limit", "inadmissible", "start_failed", "not_converged"
  std::string message;
  double fraction = 0.0;  // t at the last point the path reached
  int points = 0;         // continuation points
  bool branch_points_checked = true;
  std::vector<double> branch_points;       // t at each branch point crossed
  std::vector<std::string> contact_changes;
  long residual_evaluations = 0;           // F alone, and F with its Jacobian, along the path
  long jacobian_evaluations = 0;
  // At b (reached only): the definition with the final contact set, and the polished solve.
  ProblemDefinition definition;
  ShootingResult result;
};

// Follows the homotopy from `start` (a definition at the values a, its contact set the start
// solution's) whose solution has the unknowns x_start. Throws std::invalid_argument when a change names a parameter that is missing, solved for, or
// computed from others.
HomotopyResult follow_homotopy(const ProblemDefinition& start, const Eigen::VectorXd& x_start,
                               const std::vector<ParameterChange>& changes,
                               const HomotopyOptions& options = {});

// The values of the changed parameters at t, as "name = value, ..." for messages.
std::string describe_values(const std::vector<ParameterChange>& changes, double t);

}  // namespace kirchhoff

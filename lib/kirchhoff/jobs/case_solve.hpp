// Solving a case as `kirchhoff solve` and Python's Case.solve() both do, so that neither front
// end decides how: at the values the case was loaded with (its file's, with the --set overrides),
// reached
//   - by homotopy from the file's own values (homotopy.hpp): the default whenever the overrides
//     change a parameter that is not solved for, so that the equilibrium is the one on the branch
//     the case's guess starts, not whichever one Newton happens to reach from that guess;
//   - directly, by Newton (with the active-set loop when there are obstacles) from the case's
//     guess at those values: with `direct`, and when only guesses of solved-for parameters change;
//   - from Ipopt's minimum of the discretised energy at those values (seed ipopt): its own start.
// and then, once converged, what both front ends report of it: the solution (profile, derived
// quantities, invariants, its checks) and the stability index with its independent check, so
// that the front ends only translate.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kirchhoff/analysis/discrete_stability.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/homotopy.hpp"

namespace kirchhoff {

// Where the solver starts: the case's [guess], or Ipopt on the discretised energy
// (discrete_seed.hpp), which also gives the initial contact set.
struct StartSeed {
  bool ipopt = false;
  int segments = 200;
  double amplitude = 0.05;  // the first mode's amplitude Ipopt starts from (its sign: the side)

  std::string validate() const;  // "" when valid, else the reason (bad input)
};

struct CaseSolveOptions {
  bool direct = false;  // Newton from the guess at the requested values, no homotopy
  StartSeed seed;
  HomotopyOptions homotopy;  // its deadline defaults to the case's wall-clock limit
  // What is made of a converged equilibrium (each left empty in the result when off):
  bool solution = true;         // make_solution: profile, derived quantities, invariants, checks
  int samples = 0;              // the solution's profile points; 0: the case's [output] samples
  bool stability = true;        // analyse_stability: the index by conjugate points
  bool stability_check = true;  // discrete_stability: the index's independent check, where it applies
};

// What a homotopy that stopped short adds to its message: the direct solve, which `continue` (whose
// start is direct already) leaves out.
inline constexpr const char* kDirectSolveHint =
    "; a direct solve (--direct, or direct=True in Python) starts Newton from the guess at the requested values "
    "instead, and reaches whichever equilibrium attracts it";

// How the equilibrium was reached.
struct SolvePath {
  std::string method;                    // "direct", "homotopy" or "ipopt_seed"
  std::vector<ParameterChange> changes;  // homotopy: from the file's values to the requested ones
  HomotopyResult homotopy;               // homotopy: what the path met (its result moved out)
  std::string seed_summary;              // ipopt_seed: what Ipopt found
};

struct CaseSolve {
  // The problem at the requested values and its solve; the problem is null when a homotopy
  // stopped before reaching them or the solve could not start (the summary is then the failed
  // start solve's, or has an infinite residual when the path itself stopped or never started).
  DefinitionSolve solved;
  SolvePath path;
  // Empty, or the status word of a solve that could not start ("infeasible",
  // "integration_failed", "seed_failed") or of a path that stopped short ("fold",
  // "step_too_small", ..., or the Newton status of the case's own solve it starts from) with its
  // message (what stopped it, where, and what to do).
  std::string failure;
  std::string message;
  // Once Newton converged (and no failure): the solution made from solved.result (a copy; its
  // status is the profile checks' verdict, verification.hpp), and, when that passed (or no
  // solution was asked for), the stability of the equilibrium and its independent check.
  std::optional<Solution> solution;
  std::optional<StabilityReport> stability;
  std::optional<DiscreteStability> stability_check;

  // The verdict on the whole solve: the path's or Newton's summary, or the solution's checks'.
  const NewtonSummary& summary() const {
    return solution ? solution->result.summary : solved.result.summary;
  }
  bool converged() const { return failure.empty() && summary().converged(); }
};

// A solve that cannot start is a failure with its status word, as the front ends report it:
// "infeasible" (an end imposed inside an obstacle), "integration_failed" (the guess cannot be
// integrated), "seed_failed" (Ipopt's minimisation did not converge). Throws
// std::invalid_argument only for a case the Ipopt seed does not model or a seed whose settings
// are invalid (StartSeed::validate): bad input.
CaseSolve solve_case(const Case& c, const CaseSolveOptions& options = {});

// The changes a homotopy makes for this case: its overrides of parameters that are not solved
// for and differ from the file's values.
std::vector<ParameterChange> homotopy_changes(const Case& c);

// The case at its file's values, where a homotopy to the requested ones starts: the overrides of
// parameters only its [guess] uses are kept (they choose the equilibrium it starts from), and the
// solver settings as the case was given them.
Case case_at_file_values(const Case& c);

}  // namespace kirchhoff

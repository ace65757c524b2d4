#include "kirchhoff/jobs/case_equilibria.hpp"

#include "kirchhoff/jobs/case_solve.hpp"

namespace kirchhoff {

EquilibriaSearch find_case_equilibria(const Case& c, int samples, EquilibriaOptions options) {
  // Without changed values `solve` is Newton from the case's guess, which the search's first seed
  // is already: only a homotopy adds an equilibrium the search might not reach.
  if (!homotopy_changes(c).empty()) {
    CaseSolveOptions solve;
    solve.solution = solve.stability = solve.stability_check = false;
    const CaseSolve solved = solve_case(c, solve);
    if (solved.converged() && solved.solved.problem)
      options.known_roots.push_back({solved.solved.problem->definition().contacts, solved.solved.result.x,
                                     "solve (homotopy from the file's values)"});
  }
  return find_equilibria(c.definition, c.start_guess, c.derived, samples, options);
}

}  // namespace kirchhoff

// The equilibria of a loaded case, as `kirchhoff equilibria` and Python's Case.equilibria() both
// list them: find_equilibria (equilibria.hpp) from the case's guess, with the equilibrium `solve`
// reports at the same values among them. Where the case's --set values differ from its file's,
// that equilibrium is reached by homotopy from the file's own (case_solve.hpp): one the case's
// guess need not lead the search to (the wall's flat contact at Delta = 0.04, which the active-set
// loop from the arch's guess does not settle on), and which a user who ran `solve` expects listed.
// Then the equilibria found at the file's values, each carried to the requested ones along its own
// homotopy (case_equilibria.cpp): a rod loaded far past its critical loads, whose stable
// equilibria the search at that load does not reach, gets them from a moderate file's value.
#pragma once

#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/equilibria.hpp"

namespace kirchhoff {

// `samples` as make_solution takes them (the case's [output] samples for the CLI). Throws what
// find_equilibria throws.
EquilibriaSearch find_case_equilibria(const Case& c, int samples, EquilibriaOptions options = {});

}  // namespace kirchhoff

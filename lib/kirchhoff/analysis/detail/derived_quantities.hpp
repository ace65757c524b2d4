// The derived quantities a case names in [output] derived (solution.hpp's derived_catalogue()),
// evaluated on a solved equilibrium. They are one table in derived_quantities.cpp: name, meaning
// and the function computing it, so that the catalogue and the evaluator cannot disagree.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "kirchhoff/analysis/solution.hpp"

namespace kirchhoff {

// The named quantities of `sol` (its profile, contacts, invariants and unknowns must be set; its
// derived map is not read), the plectoneme measured once for all of its names. Throws
// std::invalid_argument("unknown derived quantity 'NAME'") for a name derived_catalogue() lacks,
// and measure_plectoneme's std::invalid_argument for a plectoneme quantity of a rod without
// half-turn self-contact.
// A solution described at its start alone (a profile of one point: make_start_solution) has only
// the quantities derived_read_start_only accepts; another throws std::logic_error.
std::map<std::string, double> derived_values(const std::vector<std::string>& names, const ShootingProblem& problem,
                                             const Solution& sol);

// Whether every one of `names` reads the state at s = 0 alone (P, theta0, n_x, ...): false for an
// unknown name, which derived_values reports.
bool derived_read_start_only(const std::vector<std::string>& names);

}  // namespace kirchhoff

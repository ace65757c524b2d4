// Following every branch through the equilibria that exist at the start: the equilibria at the
// starting parameter values are found by deflation (equilibria.hpp), and the branch through each
// is followed in one parameter by pseudo-arclength continuation (with obstacles, through changes
// of its contact set). Branches that meet later (through a fold joining two starting equilibria,
// say) are each followed from their own start: the runs are independent, and deflation is used at
// the start only, not at every step as in Farrell et al.'s deflated continuation (defcon) - a
// branch that exists only away from the start is not found.
#pragma once

#include <functional>
#include <vector>

#include "kirchhoff/continuation/rod_continuation.hpp"
#include "kirchhoff/jobs/equilibria.hpp"

namespace kirchhoff {

struct BranchFromEquilibrium {
  int rank = 0;                       // the starting equilibrium's rank (by energy) in the search
  ContinuationResult result;
  std::vector<std::string> contact_changes;
};

struct EveryBranch {
  EquilibriaSearch search;                     // the equilibria at the start
  std::vector<BranchFromEquilibrium> branches;  // one per equilibrium, in the search's order
};

// The sink for the points of the branch starting at equilibrium `rank` (called before it starts).
using BranchSinkFor = std::function<PointSink(int rank, const Equilibrium& start)>;

// `options.parameter` is continued from its value in `definition`; the definition's contacts are the
// search's starting active set. Throws what find_equilibria throws.
EveryBranch continue_every_branch(const ProblemDefinition& definition, const RodPoint& guess,
                                  const std::vector<std::string>& derived_names, int samples,
                                  const RodContinuationOptions& options, const EquilibriaOptions& search,
                                  const BranchSinkFor& sink_for = {});

}  // namespace kirchhoff

#include "kirchhoff/jobs/deflated_continuation.hpp"

#include <chrono>

#include "kirchhoff/contact/contact.hpp"

namespace kirchhoff {

EveryBranch continue_every_branch(const ProblemDefinition& definition, const RodPoint& guess,
                                  const std::vector<std::string>& derived_names, int samples,
                                  const RodContinuationOptions& options, const EquilibriaOptions& search,
                                  const BranchSinkFor& sink_for) {
  EveryBranch out;
  out.search = find_equilibria(definition, guess, derived_names, samples, search);
  const bool obstacles = !definition.obstacles.empty() || definition.moving_obstacles;
  for (size_t k = 0; k < out.search.equilibria.size(); ++k) {
    const Equilibrium& start = out.search.equilibria[k];
    const PointSink sink = sink_for ? sink_for(static_cast<int>(k), start) : PointSink{};
    // The equilibrium's own problem: its active contact set, and the phase condition or unknowns
    // it was solved with.
    BranchFromEquilibrium branch;
    branch.rank = static_cast<int>(k);
    const Eigen::VectorXd& x = start.solution.result.x;
    if (obstacles) {
      ContactContinuationResult legs = continue_with_contacts_from(start.problem->definition(), x, options, sink);
      branch.result = std::move(legs.result);
      branch.contact_changes = std::move(legs.changes);
    } else {
      branch.result = RodContinuation(*start.problem, options).run(x, sink);
    }
    out.branches.push_back(std::move(branch));
    if (std::chrono::steady_clock::now() > options.deadline) break;
  }
  return out;
}

}  // namespace kirchhoff

// A starting point and an initial contact set for the shooting solver when the user has none:
// Ipopt minimises the discretised energy (discrete_elastica.hpp) and the shooting unknowns are
// read off its solution.
//
// Why: from a contact-free guess the active-set loop adds one point contact at a time where the
// free rod penetrates most. That finds isolated contacts, but not configurations whose contact set
// is far from the free rod's: a rod pressed flat on a wall, a hanging fold (cases/cavity.toml
// beyond Delta ~ 0.01 fails from its guess). The energy minimisation needs no contact set, and
// its gap multipliers say where the rod touches and how hard.
//
// What is read off (segments N, h = L / N):
//   - the state at s = 0: the clamp's position and frame, n(0) from the multipliers, and
//     m(0) = EI (theta_0 - clamp angle) / (h / 2) - first-order accurate, which Newton corrects;
//     at a pinned start m(0) = 0 and the frame's angle 1.5 theta_0 - 0.5 theta_1 (the first two
//     segments' angles extrapolated to s = 0);
//   - the contacts: per obstacle, runs of interior nodes that touch (gap < 1e-9 L) or carry a
//     force (> 1e-6 of |n(0)| + EI / L^2). A run longer than two segments on a plane is an extended
//     contact over it (the rod lies flat there; its end forces are the multipliers of the run's
//     first and second halves); any other run is a point contact at its force-weighted mean
//     arclength, with the run's total force.
// Then solve_with_contacts starts from both and corrects the set if needed.
//
// Scope: what the discrete model describes - planar, inextensible and unshearable rods without
// natural curvature or external fields, each end clamped or pinned without a couple, with no
// unknown parameters. Other
// definitions are refused with the reason (std::invalid_argument).
#pragma once

#include <string>
#include <vector>

#include "kirchhoff/analysis/discrete_elastica.hpp"
#include "kirchhoff/contact/contact.hpp"

namespace kirchhoff {

struct DiscreteSeed {
  RodPoint start;                      // state guess at s = 0
  std::vector<PointContact> contacts;  // the initial active set
  DiscreteElasticaResult discrete;     // Ipopt's solution it was read from
  std::string summary;                 // one line: segments, energy, contacts found
};

// `amplitude` picks the side the discrete rod buckles to first (see solve_discrete_elastica;
// `options` also the starting shape and the symmetry held). Throws std::invalid_argument for a
// definition outside the scope above and std::runtime_error when Ipopt does not converge or its
// solution fails the KKT check (DiscreteElasticaResult::kkt) - held mirror symmetric, its
// stationarity to 1e-3 only: a seed starts Newton, whose solution is checked on its own, and the
// symmetric formulation's recovered stationarity stays at 1e-5 .. 1e-4 (discrete_seed.cpp).
DiscreteSeed seed_from_discrete_energy(const ProblemDefinition& definition, int segments = 200,
                                       double amplitude = 0.05);
DiscreteSeed seed_from_discrete_energy(const ProblemDefinition& definition, int segments,
                                       const DiscreteSolveOptions& options);

// seed_from_discrete_energy, then solve_with_contacts from the seed.
ContactSolveResult solve_from_discrete_seed(const ProblemDefinition& definition, int segments = 200,
                                            double amplitude = 0.05, DiscreteSeed* seed = nullptr);
ContactSolveResult solve_from_discrete_seed(const ProblemDefinition& definition, int segments,
                                            const DiscreteSolveOptions& options, DiscreteSeed* seed = nullptr);

}  // namespace kirchhoff

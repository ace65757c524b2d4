// The index where the rod lies on an obstacle (an extended contact: a flat contact on a wall, a
// wrap on a disc), for analyse_stability (stability.hpp).
//
// The admissible perturbations (docs/stability.md, "Extended contacts", has the derivation): on the
// contact interval [s1, s2] the rod stays on the obstacle where the contact force is positive, so
// the part lying there moves rigidly along it - on a plane a common slide along the wall (the
// normal displacement and the rotation held, the tangential one the same for every section by
// inextensibility), on a disc a rotation about its centre. The free arcs meet it at the take-off
// points with their position and direction continuous; the take-off points may move, but the
// rod's curvature is continuous there (no point moment), so a move is of second order in the
// arcs' perturbations and needs no degree of freedom of its own. Tilting the rod at an edge
// against the obstacle would push into it on one side, which the edge's positive force resists
// at an order below two: to second order the edges hold the direction. Where the force density is
// zero (a flat contact's interior: n' = 0 and m = 0 there) the constraint is weakly active: the rod
// may lift off, and the lift-offs (a strut clamped by the obstacle at the edges) are checked apart
// (detail/discrete_stability_lying.hpp).
//
// The conjugate-point count is not extended to this yet: for planar rods the index is the
// discretised energy's (discrete_stability.hpp, which holds the nodes lying on the obstacle),
// reported with method "discretised_energy" and used only when its self-checks pass - the index
// and zero modes equal at N and N/2 elements, every counted eigenvalue (and the lift-off one)
// farther from zero than twice its change between them (the first-order convergence of a contact),
// the discrete equilibrium converging to the shooting one. Otherwise, and for spatial rods, the
// index is null with the reason.
#pragma once

#include <Eigen/Dense>

#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// Whether the equilibrium x has an extended contact.
bool has_extended_contact(const ShootingProblem& problem, const Eigen::VectorXd& x);

// The index of an equilibrium with an extended contact (has_extended_contact), or null with why.
StabilityReport extended_contact_stability(const ShootingProblem& problem, const Eigen::VectorXd& x);

}  // namespace kirchhoff

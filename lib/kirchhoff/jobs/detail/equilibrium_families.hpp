// Continuous families among the equilibria a search found (equilibria.hpp).
//
// An equilibrium with zero modes (stability.hpp) is not isolated: it is one point of a continuous
// family of equilibria that a symmetry the ends keep generates (a rod pinned at both ends at one
// point turned about the pin; the isotropic rod's circles about e3; translations that no end
// holds), or a bifurcation point. Deflated Newton finds members of such a family as distinct
// points, so counting them as equilibria would mislead. They are grouped instead:
//
//   two equilibria with zero modes are members of one family when their energies agree
//   (family_energy_tolerance, relative to |E| + F0 L) and a rigid motion maps one onto the other
//   (rigid_motion_distance below, within the search's distinct_tolerance),
//
// and the grouping is transitive (a member joins the family of any member it matches). Each
// equilibrium with zero modes gets a family number, 1, 2, ... in the order of the list (by energy);
// isolated ones (no zero mode, or an index that is not defined) get 0.
//
// What the rule does not know: the symmetry itself. A rigid motion relating two members is the
// family's generator where the family comes from turning or moving the whole rod (every case the
// tests know); two distinct families that a discrete symmetry (a half-turn) maps onto each other
// would be merged. Mirror images are never related by a proper rigid motion in the plane, so a
// planar rod and its mirror image are two families. A group of one member is a family of which one
// point was found, or a bifurcation point: the zero modes alone do not tell.
#pragma once

#include <vector>

#include "kirchhoff/jobs/equilibria.hpp"

namespace kirchhoff {

// The scale-free distance between two solutions after the rigid motion that best maps b onto a
// (least squares over `samples` points): the largest difference of (r - centroid) / L, d3,
// n / F0 and m / (F0 L) along the rod. Planar rods are turned in their plane only (so a mirror
// image stays apart); spatial rods by any proper rotation. d1 is left out, as in
// axial_orbit_distance: the isotropic rod's circles turn the sections back.
double rigid_motion_distance(const ShootingProblem& a, const Eigen::VectorXd& xa, const ShootingProblem& b,
                             const Eigen::VectorXd& xb, double force_scale, int samples = 101);

// Sets Equilibrium::family on every equilibrium (see above) and returns the number of families.
int group_continuous_families(std::vector<Equilibrium>* equilibria, double force_scale, double distinct_tolerance,
                              double energy_tolerance, int samples = 101);

}  // namespace kirchhoff

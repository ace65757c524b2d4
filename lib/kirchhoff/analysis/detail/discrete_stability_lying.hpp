// Extended contacts in the discrete stability check (discrete_stability.hpp): the nodes where the
// rod lies on an obstacle, and the lift-off of a part that lies there with zero contact force.
//
// Where the rod lies on an obstacle over [s1, s2] (a flat contact on a wall, a wrap on a disc),
// the nodes there are constraints of the discrete energy: their gaps held at zero (bilateral).
// Every other node is held, from the first inside the shooting solution's interval: holding every
// node leaves the multipliers a checkerboard (the trapezoid rule's positions see the angles of two
// neighbouring nodes only through their sum, and the nodal forces only through the sums of
// neighbouring shears), while with every other node the rod between two held nodes is a beam over
// supports 2h apart, pinned to the obstacle to O(h^2) and as stiff as B / h^4 against leaving
// it: the constraint of the whole part in the limit. Which parts carry force is read from the
// shooting solution, not from the discrete multipliers: near an edge the nodal reactions of a beam
// on point supports alternate in sign (decaying by about -(2 - sqrt 3) per support), which says
// nothing of the continuous contact force.
//
// The edges carry positive forces (else not covered). A wrap presses with N / radius > 0 inside:
// bilateral everywhere. A flat contact carries no force inside (n' = 0 and m = 0 there): weakly
// active, the rod may lift off there at no first-order cost, but not push in. The admissible
// perturbations are then a cone, not a space, and the second variation is treated as
// docs/stability.md derives it:
//   - the whole lying part held gives the space L1; its index is counted;
//   - the edges hold the rod's position and direction (tilting the rod at an edge pushes into the
//     obstacle on one side, which the edge force resists at an order below two), so the lift-offs
//     are the perturbations supported between the edges with clamped ends (a strut clamped by the
//     obstacle), Q-orthogonal to L1 (the second variation is local and they meet every end's
//     constraint on their own);
//   - the strut's lowest eigenvalue (lift_off_eigenvalue) > 0: no lift-off lowers the energy, and
//     the index is L1's; < 0 with a one-signed mode (it lifts everywhere): the equilibrium is
//     unstable by lifting off, which is reported as such, not as a count (on a cone the number of
//     negative directions is not an index).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/model/obstacle.hpp"

namespace kirchhoff {

// The shooting solution's extended contact: the rod on `obstacle` over [s1, s2].
struct LyingInterval {
  std::shared_ptr<const Obstacle> obstacle;
  double s1 = 0.0, s2 = 0.0;
  bool weak = false;  // no force inside (a flat contact): weakly active between the edges
};

// A node held on an obstacle.
struct LyingNode {
  int node = 0;
  std::shared_ptr<const Obstacle> obstacle;
};

// The lowest eigenvalue per int dtheta^2 of the strut's second variation Q (the Hessian of the
// Lagrangian on the angles between the edges) on the angle perturbations that leave the edge after
// them in place (rows: d r_edge / d theta, 2 x m), with element length h. *gap_rates: the lowest
// mode's change of each node's gap between the edges (rates: d gap_i / d theta, m x m), for the
// one-signed test.
double lift_off_eigenvalue(const Eigen::MatrixXd& Q, const Eigen::MatrixXd& rows, const Eigen::MatrixXd& rates,
                           double h, Eigen::VectorXd* gap_rates);

}  // namespace kirchhoff

// The closest approach of a discretised rod to an obstacle near a point contact, for the
// discrete stability check (discrete_stability.hpp).
//
// A point contact with a positive force is a bilateral constraint on the perturbations, but the
// contact point slides along the obstacle: the constraint is that the rod's smallest gap,
// min_s g(r(s)), stays zero - not the gap at a fixed material point. With the gaps g_-, g_0, g_+
// at three consecutive nodes (spacing h) around the contact, the quadratic through them,
//   q(t) = g_0 + a t + b t^2 / 2,   a = (g_+ - g_-) / (2 h),   b = (g_+ - 2 g_0 + g_-) / h^2,
// has its minimum q* = g_0 - a^2 / (2 b) at t* = -a / b (b > 0: the rod curves away from the
// obstacle). q* is a smooth function of the three gaps, and its second derivative
//   d^2 q* / dg dg^T = -(1 / b) v v^T,   v = da/dg + t* db/dg,
// brings into the Hessian of the Lagrangian (multiplier -f for a contact force f) the term
// f (dq'(t*))^2 / b: the continuous second variation's sliding term f (nu.dr')^2 / g''. Holding
// the gap at a node instead drops it (the "fixed material point" count, which is wrong).
// The interpolant's error is O(h^3) in q* even across the jump of g''' that the contact force
// makes, so equilibria and eigenvalues keep the discretisation's O(h^2) convergence.
#pragma once

#include <Eigen/Dense>

namespace kirchhoff {

struct ClosestApproach {
  double value = 0.0;      // q*, the smallest gap of the interpolant
  double offset = 0.0;     // t*, where it is, from the middle node (in arclength)
  double curvature = 0.0;  // b = q'', > 0 when the rod curves away from the obstacle
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();    // dq*/dg (the force's share of each node)
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // v: d^2 q*/dg^2 = -(1/b) v v^T
};

// The closest approach from the gaps at three consecutive nodes spaced h. Needs curvature > 0
// (the caller checks it); otherwise the fields are infinite or NaN.
ClosestApproach closest_approach(double before, double middle, double after, double h);

}  // namespace kirchhoff

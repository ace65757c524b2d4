// The planar Elastica as a constrained minimisation of its discretised energy, solved by Ipopt:
// an independent check of the shooting solutions (and their contact forces, which here are the
// multipliers of the gap constraints), converging as the number of segments grows, and a way to
// find a starting point and contact set for them (discrete_seed.hpp).
//
// Clamped-clamped rod of length L and bending stiffness EI(s), clear of obstacles (planes,
// cylinders, level sets). Unknowns: the angles theta_i of N equal segments (midpoint rule) and
// the interior nodes r_k; energy sum EI_k/(2 h) (theta_k - theta_{k-1})^2 over the interior nodes
// k with half cells EI/h (theta - clamp angle)^2 at the clamps; equality constraints
// r_i+1 - r_i = h (cos, sin) theta_i per segment (r_0, r_N the clamps); one inequality gap >= 0
// per interior node and obstacle. Every constraint involves one angle and at most two nodes, so
// the KKT matrix is banded (O(N) per iteration: 0.3 s at N = 1000, 1.2 s at 4000; with the
// angles alone the gap rows were dense, 5.6 s at N = 1000). The Hessian of the Lagrangian is
// given exactly: tridiagonal in the angles, and the obstacles' 2 x 2 curvature blocks at the
// nodes. The results (P, n(0), the gap multipliers) are stated in the angles-only formulation,
// in which the KKT check below verifies them. Second-order accurate: errors fall as 1/N^2 - on a curved obstacle only
// where the contact falls on a node, since contact is imposed at nodes and its arclength is not an
// unknown; elsewhere the forces converge at first order, irregularly (the energy still at second).
//
// Checked, not trusted: after Ipopt returns, the KKT conditions are recomputed here from its
// angles and multipliers (DiscreteKktCheck); `converged` needs both. A KKT point is an equilibrium
// of the discrete problem but not necessarily the one wanted (a rod buckled away from the wall is
// one too): solve_discrete_elastica_refined also solves at N/2 and N/4 and checks that the three
// converge at second order, which gives P's error estimate (DiscreteRefinementCheck).
// docs/cross-checks.md.
#pragma once

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// A clamped-clamped planar rod: ends at `start` and `end` with tangent angles `start_angle` and
// `end_angle` (from e_x), bending stiffness EI(s), clear of the obstacles. An angle that is NaN
// leaves its end free to turn (pinned: position held, no moment), its half cell out of the energy.
struct DiscreteClampedElastica {
  double L = 1.0;
  std::function<double(double)> EI = [](double) { return 1.0; };
  Vec3 start = Vec3::Zero();
  double start_angle = 0.0;
  Vec3 end = Vec3::UnitX();
  double end_angle = 0.0;
  std::vector<Obstacle> obstacles;
};

// The solution's own check of the Karush-Kuhn-Tucker conditions, recomputed here from the angles
// and Ipopt's multipliers (check_discrete_elastica), not taken from Ipopt. F is the force scale
// |n(0)| + sum of the contact forces + max EI / L^2, h = L / N. Each number is dimensionless and
// independent of N at an exact solution of the discrete problem:
//   stationarity    max_i |dL/dtheta_i| / (h F): the moment balance of each segment (L = energy +
//                   multipliers x constraints), in units of the force scale;
//   end_error       |r_N - end| / L: the end constraints;
//   penetration     max(0, -min gap) / L: the gap constraints (>= 0);
//   negative_force  max(0, -min contact force) / F: a contact may push, never pull;
//   complementarity max force x gap / (F L): a node carries force only where it touches.
// Passed when every one is <= kDiscreteKktTolerance.
struct DiscreteKktCheck {
  double stationarity = NAN, end_error = NAN, penetration = NAN, negative_force = NAN, complementarity = NAN;
  double force_scale = NAN;
  bool passed = false;
  std::string failure;  // the first condition that failed, with its value; empty when passed
};
// Ipopt solves to tol = 1e-12 on its scaled KKT error in its own (banded) variables; translated to
// the angles, each segment's moment balance sums the nodes' force residuals after it, so the
// stationarity here is ~1e-12 to 1e-11 once divided by h F (>= 0.1 at N = 1000 on wall.toml).
// Measured on wall.toml (N = 50 to 2000), cavity.toml's four seeds (tests/discrete_seed_test.cpp),
// a disc (N = 50 to 400) and a level set: all five at most 1e-12 up to N = 1000 from the default
// start, 4.3e-12 at N = 2000, 8.3e-12 for N = 1000 started from the N = 500 solution (round-off
// in EI / h (theta_k - theta_k-1) grows like N). 1e-8 leaves three decades for harder cases and
// still rejects the perturbations of tests/discrete_check_test.cpp (1e-6 in one angle or in P
// relative, 1 % in a contact force).
inline constexpr double kDiscreteKktTolerance = 1e-8;

// Richardson's check of a solve at N segments against N/2 and N/4 (solve_discrete_elastica_refined).
// The midpoint-rule energy is second-order accurate, P_N = P + C h^2 + O(h^4), so
//   error_estimate = |P_N - P_N/2| / 3      (the error of P_N, to O(h^2) of itself)
//   ratio          = (P_N/4 - P_N/2) / (P_N/2 - P_N)   (4 at second order, 2 at first).
// Passed when the ratio lies in [kRefinementRatioMin, kRefinementRatioMax] (observed order between
// 1 and 3), or both differences are at round-off (<= 1e-10 |P|). A ratio outside means the three
// are not one equilibrium refined (a solve on another branch: the free arch buckled away from the
// wall differs by 47 % in P) or not yet in the asymptotic range; either way the error estimate is
// not to be believed, and the result is not reported as converged.
struct DiscreteRefinementCheck {
  int segments = 0;
  double P = NAN, P_half = NAN, P_quarter = NAN;
  double error_estimate = NAN;   // of P at N segments, absolute
  double P_extrapolated = NAN;   // (4 P_N - P_N/2) / 3
  double ratio = NAN;
  bool passed = false;
  std::string failure;
};
inline constexpr double kRefinementRatioMin = 2.0, kRefinementRatioMax = 8.0;

struct DiscreteElasticaResult {
  // True only when Ipopt reported success AND the KKT check passed (and, for
  // solve_discrete_elastica_refined, the refinement check too).
  bool converged = false;
  // "converged", or why not: Ipopt's return status, "KKT check failed: ...", "refinement check
  // failed: ...".
  std::string status;
  std::string ipopt_status;    // Ipopt's own verdict ("success" or its return status)
  int iterations = 0;
  double P = 0.0;              // compressive end load, -n_x(L) (the x-constraint's multiplier)
  double n_y = 0.0;            // n_y at s = 0
  Vec3 n_start = Vec3::Zero(); // n(0)
  double m_start = 0.0;        // the clamp's moment at s = 0, EI (theta_0 - start_angle) / (h / 2); 0 pinned
  double contact_force = 0.0;  // sum of the contact forces' magnitudes
  double energy = 0.0;
  double min_gap = 0.0;
  std::vector<double> x, y, theta;  // nodes (N + 1) and segment angles (N)
  // Per obstacle, the contact force at each interior node k = 1..N-1 (index k - 1), and the gap.
  std::vector<std::vector<double>> node_forces, node_gaps;
  // Ipopt's multipliers of every constraint row (end x, end y, then the gaps obstacle by
  // obstacle), in its convention: Lagrangian = energy + multipliers . constraints.
  std::vector<double> multipliers;
  DiscreteKktCheck kkt;
  DiscreteRefinementCheck refinement;  // filled by solve_discrete_elastica_refined only
};

struct DiscreteSolveOptions {
  double amplitude = 0.05;  // of the first mode in the starting point (its sign: the side)
  // Lobes of the starting shape y = (A/2)(1 - cos(2 pi lobes s / L)) across the chord: 1 the
  // first clamped-clamped mode; 2 two bumps with the middle back on the chord, the way to a
  // rod touching an obstacle twice (the wall's hanging fold, which Ipopt from one lobe leaves for
  // the lower asymmetric contact).
  int lobes = 1;
  // Minimise over the rods symmetric under the reflection across the chord's perpendicular
  // bisector only (theta_i + theta_N-1-i = twice the chord's angle; N even). A minimiser left free
  // breaks a symmetric start's symmetry for a lower asymmetric minimum; held to it, it reaches
  // the symmetric local minimum, which is an equilibrium of the whole problem where the problem
  // is symmetric (symmetric criticality) and fails the KKT check, made without the symmetry, where
  // it is not.
  bool mirror_symmetric = false;
  // Start from these segment angles instead (size N; e.g. a coarser solution interpolated).
  std::vector<double> initial_theta;
  // Ipopt's starting value of every gap constraint's multiplier, i.e. the contact force each
  // node starts with (bound_mult_init_val). 0: max EI / (L^2 N), a total of EI / L^2 over the
  // rod, 1/40 of its Euler load. Ipopt's own default, 1 per node, is a total force N EI / L^2
  // pushing the starting rod away from the obstacles: on wall.toml from N ~ 750 on it pushed the
  // rod through the straight state to the free arch buckled away from the wall (P = 40.0
  // instead of 75.08, "converged": a true minimum of the discrete energy, but another branch).
  double initial_multiplier = 0.0;
};
// Starts from the chord between the ends with the first clamped-clamped mode of amplitude
// `amplitude` on it (its sign picks the side it buckles to) and the clamps' angles blended in;
// throws std::invalid_argument for non-physical input (L or EI <= 0, ends further apart than L).
DiscreteElasticaResult solve_discrete_elastica(const DiscreteClampedElastica& rod, int segments,
                                               double amplitude = 0.05);

DiscreteElasticaResult solve_discrete_elastica(const DiscreteClampedElastica& rod, int segments,
                                               const DiscreteSolveOptions& options);

// The KKT check above, recomputed from result.theta and result.multipliers (both of size N and
// 2 + obstacles x (N - 1)); throws std::invalid_argument when their sizes do not match the rod.
DiscreteKktCheck check_discrete_elastica(const DiscreteClampedElastica& rod, const DiscreteElasticaResult& result);

// The refinement check above from the three values of P.
DiscreteRefinementCheck check_refinement(int segments, double P, double P_half, double P_quarter);

// Solves at N/4 from the starting point of `options` (initial_theta, if given, holds N/4 angles),
// then at N/2 and at N each from the coarser solution with every segment split in two (the same
// nodes, so the three stay on one branch), and checks the three by Richardson. Returns the
// solution at N with `refinement` filled; converged only when all three solves pass their KKT
// check and the refinement check passes. When a coarser solve fails, its result is returned
// (not converged, the status naming N). N must be divisible by 4, N/4 >= 4. Costs ~1.75 times the
// solve at N alone (a solve costs O(N) per iteration).
DiscreteElasticaResult solve_discrete_elastica_refined(const DiscreteClampedElastica& rod, int segments,
                                                       const DiscreteSolveOptions& options = {});

// The rod of the paper's Fig. 12: ends at (0, 0) and (L - Delta, 0), horizontal tangents.
DiscreteElasticaResult solve_discrete_clamped_elastica(double L, double EI, double Delta,
                                                       const std::vector<Obstacle>& obstacles, int segments,
                                                       double amplitude = 0.05);

}  // namespace kirchhoff

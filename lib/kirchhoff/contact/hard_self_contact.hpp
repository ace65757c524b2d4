// Hard (complementarity) self-contact for the symmetric plectoneme: the half rod of a solved
// HalfTurnSelfContact problem re-solved as a discretised rod whose centreline is held at least R
// from the half-turn axis by inequality constraints, with Ipopt.
//
// Why. The shooting formulation keeps the strands apart with a smooth barrier (self_contact.hpp):
// robust through continuation, but the strands then sit a gap of 5-30 % of R apart, so the ply's
// radius is R + gap rather than R and the contact force is spread by the barrier's range. Here
// the contact is exact: 0 <= rho - R perp p >= 0 at every node, the pressures p being the
// multipliers of the distance constraints, as the Karush-Kuhn-Tucker conditions of the
// constrained energy minimum. The shooting solution seeds it (its shape, its frames and with them
// the linking number, which a discretised energy by itself cannot count), so this is the hard
// limit of that solution: an independent check of the barrier and of eq. (61) with R itself.
//
// The discretisation (second order in the spacing h): nodes x_j at s = j h on the half rod
// [0, L/2], the clamp x_0 fixed; a unit quaternion q_i per edge i for its frame, tied to the edge
// by d3(q_i) = (x_{i+1} - x_i) / h; bending and twisting energy 2 B_k vec_k(conj(q_i) q_{i+1})^2 / h
// per pair of neighbouring edges (vec of the relative rotation is sin of half its angle about
// each director, so this is sum B_k kappa_k^2 h / 2 to second order), against the clamp's frame
// at half the distance, and against the edge's own image under the half-turn at s = L/2, counted
// half (it is shared with the other half rod): the symmetry condition is the energy's, not
// imposed. The end node lies on the axis. The internal force on edge i is n_i = -lambda_i / h,
// lambda_i the multiplier of its edge constraint.
#pragma once

#include <string>
#include <vector>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct HardSelfContactOptions {
  double spacing = 0.25;      // h / R
  double tolerance = 1e-10;   // Ipopt's (scaled) optimality tolerance
  int max_iterations = 500;   // Ipopt's, per round
  // Ipopt minimises within a box about the seed: nodes within trust_radius R of theirs (a
  // minimiser left free wanders off to a state of lower energy, passing strands through each
  // other away from the constrained pairs, or unwinding the twist). A minimum with a bound of the
  // box active is re-solved in a box about it, up to max_rounds times.
  double trust_radius = 1.0;
  int max_rounds = 20;
};

struct HardSelfContactPlectoneme {
  // Ipopt succeeded, the minimum lies inside the trust region, and the complementarity check on
  // the solution (min_gap, min_force, complementarity below, each within max(1e-8, 100 x
  // tolerance)) passed.
  bool converged = false;
  std::string status;        // "converged", Ipopt's return status, or the check that failed
  int iterations = 0;        // Ipopt's, over all rounds
  int rounds = 0;            // trust-region rounds
  int box_active = 0;        // variables on a bound of the last round's box (0 at an accepted minimum)
  double radius = 0.0;       // R, the cross-section radius
  int segments = 0;          // edges on the half rod
  double spacing = 0.0;      // h
  double energy = 0.0;       // of the half rod
  // As in PlectonemeMeasures (plectoneme.hpp), here with exact contact:
  double T_ext = 0.0;        // n.d3(0): the first edge's force along the clamp's d3
  double m3 = 0.0;           // twisting moment B3 u3 in the middle of the half rod
  double contact_start = NAN, contact_end = NAN;  // nodes pressed with >= kContactFraction of the largest force
  double helix_angle = NAN;  // mean angle between d3 and the axis over the central half of the contact region
  double helix_radius = NAN; // mean distance to the axis there (R, to the constraint's tolerance)
  double contact_pressure = NAN;  // mean contact force per length there
  // Complementarity: the smallest (rho - R) / R over the constrained nodes (>= 0 up to Ipopt's
  // tolerance), the smallest contact force over the largest (>= 0), and the largest
  // force x gap over (largest force x R) (0 at an exact solution).
  double min_gap = NAN, min_force = NAN, complementarity = NAN;
  // Nodes 0..N (the clamp first), their contact force (per node, not per length; 0 where
  // unconstrained) and distance to the axis.
  std::vector<Vec3> nodes;
  std::vector<double> node_force, node_radius;
  std::vector<Eigen::Vector4d> frames;  // the edges' unit quaternions (w, x, y, z)
};

// The contact set of a discretised solution as shooting contacts on the self-contact cylinder
// (obstacle 0 of hard_ply_definition, plectoneme.hpp): runs of consecutive pressed nodes, a run of
// at most kPointContactNodes nodes a point contact (its forces summed, at their centroid), a longer
// one a line contact over its nodes, with the excess of its end nodes over their neighbours as the
// edge forces. The ply's ends are such isolated points beside its line contact (measured at
// L/2R = 100, 5 turns: point, gap of 0.5 % of R, line, gap, point).
std::vector<PointContact> ply_contacts(const HardSelfContactPlectoneme& solution);
inline constexpr int kPointContactNodes = 3;

// Re-solves the half rod of `problem` at the solution x with hard self-contact, seeded by x.
// Throws std::invalid_argument when the problem has no half-turn self-contact, is not an
// inextensible, unshearable spatial rod, or when the options are out of range.
HardSelfContactPlectoneme solve_hard_self_contact(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                                  const HardSelfContactOptions& options = {});

}  // namespace kirchhoff

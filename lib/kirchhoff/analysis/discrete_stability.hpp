// An independent check of the stability index (stability.hpp) for planar inextensible rods: the
// lowest eigenvalues of the Hessian of a discretised total potential energy, projected onto the
// perturbations the end conditions admit. It shares no code with the conjugate-point count: no
// Jacobi equations, no canonical coordinates, no isoperimetric correction - the constraints are
// simply constraints of a finite-dimensional minimisation.
//
// Discretisation (N elements of length h = L / N, nodes s_j = j h):
//   unknowns      the start position r_0 and the node angles theta_0 .. theta_N;
//   positions     r_i = r_0 + h/2 sum_{k<i} (t(theta_k) + t(theta_k+1)), t = (cos, sin) (trapezoid);
//   bending       sum_e B(s_e+1/2) / (2 h) (theta_e+1 - theta_e - h u_hat(s_e+1/2))^2 (midpoint);
//   dead loads    -F_0.r_0 - F_L.r_N - M_0 theta_0 - M_L theta_N (the given end loads);
//   field         sum_i h c_i W(s_i, r_i) (trapezoid weights c_i): for a uniform field
//                 -sum_i h c_i f.r_i; for one that depends on position (a soft wall's barrier)
//                 the lumped potential, whose Hessian adds sum_i (dr_i/dz)^T (-h c_i df/dr)
//                 (dr_i/dz) to the second variation, r_0 included.
// Both rules are second order, so equilibria and eigenvalues converge as h^2 (first order with a
// contact, below).
//
// Constraints, read from the case as stability.hpp reads it: imposed positions and rotations are
// held (e.r_0, e.r_N, theta_0, theta_N at their imposed values); an unknown parameter that is an
// end load is a Lagrange multiplier, so the displacement conjugate to it is held at the shooting
// solution's value (its load stays in the energy at the solved value; the constraint's multiplier
// takes up the O(h^2) difference). Extra conditions (the end slope theta0 of
// simply_supported.toml) only select the equilibrium and are not imposed.
//
// Point contacts (positive force, on a plane or a disc) are bilateral constraints whose contact
// point slides: the rod's closest approach to the obstacle, the minimum of the quadratic through
// the gaps of the three nodes around the contact, is held at zero (discrete_stability_contact.hpp).
// Its multiplier is minus the contact force, and its Hessian brings the sliding term
// f (dg')^2 / g'' (holding the gap at a node would leave it out: another, wrong count) and, on a
// disc, the obstacle's curvature. The interpolant's g'' is a second difference across the jump of
// g''' that the contact force makes, so eigenvalues converge at first order with a contact.
// Where the energy depends on the start position (a field that depends on position, a contact
// with a disc), its admissible perturbation, fixed by the held positions as dr_0 = R dtheta,
// enters the projected form; a start that may translate is then not covered.
//
// A sliding length (the rod's length ell outside a frictionless sleeve, an unknown balanced by the
// continuity of H at the sleeve's exit, as stability_free_length.hpp classifies it) is an unknown
// of the energy too: h = ell / N, and the energy gains the part inside the sleeve, straight along
// the clamped exit's tangent under the axial force H_in that the H condition names: H_in ell up to
// a constant (its inner end's dead load moves by -/+ d ell along the sleeve). The stationarity in
// ell is then the H condition. ell has no weight in int dtheta^2: where the constraints leave a
// direction that slides the rod at fixed angles, it is eliminated by a Schur complement (the
// second variation of that direction, 2 E_bend / ell^2, is positive for a bent rod), and by the
// inertia additivity of Schur complements the index is the complement's count (spectrum() in the
// .cpp). The discrete d^2 E*/d ell^2 along its fixed-length equilibria (reduced_curvature)
// converges to stability_free_length's S at second order.
//
// From the shooting solution sampled at the nodes, Newton solves the discrete KKT system
// (gradient of the Lagrangian, constraints) with the exact Hessian. The Hessian of the Lagrangian
// is projected on the null space Z of the constraint Jacobian, and the generalised eigenproblem
//   Z^T H Z v = mu Z^T M Z v,   M = diag(0, 0, h c_j)  (the trapezoid weight of int dtheta^2 ds)
// gives eigenvalues mu that approximate those of the continuous second variation with weight
// int dtheta^2 ds (the Hessian's eigenvalues divided by h, with half weights at the end nodes).
// Rigid translations that no end holds (zero weight, zero energy) are counted as zero modes and
// removed first. The index is the number of mu below -zero_tolerance; |mu| <= zero_tolerance
// are zero modes.
//
// The check checks itself (trustworthy = false with the reason in check_message otherwise):
//   - the KKT residual at N and N/2 elements below kDiscreteStabilityKktTolerance;
//   - the discrete equilibrium close to the shooting one (kDiscreteStabilityAngleTolerance), and
//     closer at N than at N/2 (it converges to the shooting solution, not to another one); a
//     sliding length's relative difference likewise;
//   - the lowest eigenvalues at N and N/2 agreeing to kDiscreteStabilityAgreement of the sum of
//     their parts' magnitudes (bending and loads), index and zero modes equal, and every eigenvalue counted with a sign that
//     the refinement cannot change (|mu_N| > |mu_N - mu_N/2|, three times the Richardson
//     error estimate, and the same sign at N/2; with a contact, first order, |mu_N| > twice the
//     change, the error estimate itself);
//   - each contact pushing in the discrete solve (its multiplier negative) with its closest
//     approach within one element of its interpolant's middle node.
// Not covered (index empty, reason given): spatial or extensible rods, natural shear or stretch,
// extended contacts, contacts with a level-set obstacle, a contact with zero force (weakly
// active) or where the rod flattens onto the obstacle (g'' = 0), half rods by symmetry, a field
// that depends on position (or a disc contact) on a rod whose start may translate, unknown
// parameters that are neither end loads nor a sliding length, dependent constraints (a straight
// rod whose chord is held: no perturbation keeps it to first order). Of sleeves: what
// stability_free_length refuses (a field, a non-uniform rod, other unknowns beside the length, a
// length that changes the rod's properties or is not closed by H at exactly one end), an H
// condition without a sliding length to balance it, an H value that changes with ell (not a dead
// load on a straight part: the inside part's energy is unknown), an exit that does not hold the
// rod's position and direction, a contact on a sliding rod, and a straight sliding rod (sliding at
// fixed shape costs no energy: the elimination is not defined).
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct DiscreteStability {
  std::optional<int> index;  // number of negative eigenvalues; empty when not defined (reason)
  std::string reason;        // why the index is not defined, else empty
  int zero_modes = 0;        // |mu| <= zero_tolerance, rigid translations included
  // The lowest eigenvalues mu at N elements (at most kDiscreteStabilityReported), increasing, in
  // the continuous operator's units (second variation per int dtheta^2 ds: a force, B / L^2),
  // and the same at N/2 elements.
  std::vector<double> lowest_eigenvalues, coarse_eigenvalues;
  double zero_tolerance = 0.0;
  double kkt_residual = 0.0;       // the larger of the two solves' scaled KKT residuals
  double angle_deviation = 0.0;    // max_j |theta_j - theta(s_j)| against the shooting solution, at N
  double coarse_angle_deviation = 0.0;  // the same at N/2
  // With a sliding length (its name, else empty): |ell - ell(shooting)| / ell at N and N/2, and
  // the discrete energy's d^2 E*/d ell^2 along its fixed-length equilibria at N and N/2, the
  // counterpart of stability_free_length's S (NaN where the fixed-length problem is singular).
  std::string sliding_length;
  double length_deviation = 0.0, coarse_length_deviation = 0.0;
  double reduced_curvature = NAN, coarse_reduced_curvature = NAN;
  // Extended contacts (detail/discrete_stability_lying.hpp): the nodes held on the obstacle at N,
  // how many of them carry zero force (weakly active: a flat contact's interior), and the lowest
  // lift-off eigenvalue of those (NaN without any) at N and N/2: the rod lifting off there,
  // clamped by the obstacle at the edges, per int dtheta^2 (positive: no lift-off lowers the
  // energy, and the index is that with every lying node held).
  int lying_nodes = 0, weakly_active_nodes = 0;
  double lift_off_eigenvalue = NAN, coarse_lift_off_eigenvalue = NAN;
  int elements = 0;
  int newton_iterations = 0;  // at N
  bool trustworthy = false;
  std::string check_message;  // "passed", or the first self-check that failed
  // No index, but unstable (reason): a part lying on the obstacle with zero force lifts off with
  // lower energy, its lift-off eigenvalue negative beyond its discretisation error at N and N/2
  // and its mode lifting the rod everywhere there; decided whatever the self-check says of the
  // rest of the spectrum.
  bool unstable = false;
  bool defined() const { return index.has_value(); }
};

// Scaled KKT residual: max over the angles of |dL/dtheta_j| / (h F), F = B_max/L^2 + the loads'
// magnitudes (the equation of node j is a moment balance over a length h, in units of F). Newton
// ends at round-off, which grows as eps N^2 max|theta| (B/h differences of the angles against a
// scale of h B/L^2): ~1e-10 at N = 400, ~3e-9 at N = 2000. 1e-8 leaves that margin.
inline constexpr double kDiscreteStabilityKktTolerance = 1e-8;
// The discrete angles differ from the shooting solution's by O(h^2): 3e-8 to 1.8e-4 rad on the
// suite's cases at N = 400 (docs/stability-cross-check.md), four times that at N/2. 1e-2 rad flags
// another equilibrium or an unresolved one, and the N versus N/2 comparison asks that the
// difference shrink.
inline constexpr double kDiscreteStabilityAngleTolerance = 1e-2;
// An eigenvalue is a sum of a bending part int B dtheta'^2 / int dtheta^2 and a load part, each
// discretised with a relative error O((k h)^2) for a mode of wave number k (the bending part low
// by (k h)^2 / 12); between N and N/2 the error changes by three times that. 1 % of the parts'
// magnitudes admits wave numbers up to ~0.2 / h (80 / L at N = 400): the lowest modes of any
// resolved equilibrium, while a coarse solve on another equilibrium is caught.
inline constexpr double kDiscreteStabilityAgreement = 1e-2;
// With contacts the eigenvalues converge at first order only (spectrum_check), so the change from
// N/2 to N is the error at N itself, not a third of it, and an equilibrium's contact edges set it
// rather than its wave numbers: the rod wrapped on the indenter's disc (wrapped_indenter.toml,
// rise 0.19 to 0.21) changes its lowest eigenvalue, 130 to 265, by 1.1 to 2.3 % from 400 to 800
// elements. 5 % of the parts' magnitudes; the sign is then still decided against twice the change.
inline constexpr double kDiscreteStabilityContactAgreement = 5e-2;
// Eigenvalues with |mu| <= this times B_max / L^2 are zero modes: exact symmetries (a rod turning
// about a pin its two ends share, rigid translations) give ~1e-10 here; a mode merely near
// neutral is not a zero mode of the discrete problem and its sign is decided, or the check fails.
inline constexpr double kDiscreteStabilityZeroTolerance = 1e-6;
// Elements by default, and where the rod lies on an obstacle (an extended contact): there the
// eigenvalues converge at first order (the edges' forces sit on single nodes); on
// wrapped_indenter.toml the lowest is 135.58, 138.33, 138.80, 139.03 at 200, 400, 800, 1600
// elements, so 400 against 200 differ by 2 % (more than kDiscreteStabilityAgreement) and 800
// against 400 by 0.3 %.
inline constexpr int kDiscreteStabilityElements = 400;
inline constexpr int kDiscreteStabilityLyingElements = 800;
// How many of the lowest eigenvalues are reported and compared.
inline constexpr int kDiscreteStabilityReported = 6;

// The discrete index of the equilibrium x of `problem` (x solved) with `elements` elements (even,
// >= 8) and a second solve with elements / 2; 0 chooses kDiscreteStabilityElements, or
// kDiscreteStabilityLyingElements where the rod lies on an obstacle. Never throws for an
// unsupported case: the result says why the index is not defined.
DiscreteStability discrete_stability(const ShootingProblem& problem, const Eigen::VectorXd& x, int elements = 0);

// "index k (N elements, trustworthy)" and the like, for messages.
std::string describe(const DiscreteStability& result);

// Where the conjugate points leave the index undefined (`report` has a reason, and is not known
// unstable) and the discretised energy decides it, having passed its own checks: `report` with
// that index and its zero modes, method "discretised_energy" and the conjugate points' reason as
// method_reason (a stiff foundation can make a held chord look degenerate to the conjugate points'
// absolute zero tolerance while the discretised Hessian is plainly positive). Otherwise `report`
// as it is.
StabilityReport with_discretised_index(StabilityReport report, const DiscreteStability& discrete);

// with_discretised_index for runs that do not report the discretised check beside the index
// (branches, lists of equilibria): the check is made only where `report`'s index is undefined (and
// not known unstable), and with `lying` false not where the rod lies on an obstacle (there it takes
// 800 elements, ~0.4 s, too slow for every point of a branch; the index stays undefined).
StabilityReport with_discretised_index_where_undefined(StabilityReport report, const ShootingProblem& problem,
                                                       const Eigen::VectorXd& x, bool lying);

}  // namespace kirchhoff

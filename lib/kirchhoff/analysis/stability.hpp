// Stability of an equilibrium: the index (number of negative eigenvalues) of the second variation
// of the total potential energy, restricted to the perturbations the case admits, by counting
// conjugate points of the Jacobi (linearised equilibrium) equations, which are the shooting
// core's variational equations.
//
// The perturbations the case admits follow from its end conditions, read as the experiment holds
// them: an imposed position or rotation holds its perturbation at zero; a load given at an end is
// a dead load (its perturbation is zero, the conjugate displacement free); an unknown parameter
// that is an end load (P of simply_supported.toml, balanced by the end slope) is a Lagrange
// multiplier, so the displacement it is conjugate to is held instead (the end shortening is
// imposed and P follows). Extra conditions (the end slope) only select the equilibrium.
//
// Method, in two steps (Manning, Rogers & Maddocks 1998 for the isoperimetric part):
//  1. The load-controlled problem: every end position free under a dead load equal to the
//     reaction. Its configuration is the rotation alone (the position follows from r' = d3) and
//     its Jacobi fields keep dn = 0, so the Legendre condition (bending and twist stiffness > 0)
//     holds strictly and Morse's index theorem applies. With the rotation pair in canonical
//     coordinates u = dpsi (lab-frame rotation vector), p = (dm + 1/2 m x dpsi) L / B (the m x dpsi
//     term makes the pair canonical on SO(3); zero in the plane), start the frame of Jacobi fields
//     meeting the rotation conditions at s = 0 and count
//       - the conjugate points in (0, L), where the frame's rotation block U(s) is singular, with
//         multiplicity, as the passages through -1 of the eigenvalues of the unitary matrix
//         W = (U + iP)(U - iP)^-1 (all in one direction under the Legendre condition; a passage
//         the other way means the count is not valid and the index is reported undefined);
//       - at s = L, the negative directions of the boundary form q(c) = (P c).(U c) on the fields
//         meeting the rotation conditions there (a conjugate point exactly at L adds the fields
//         whose dead-moment condition fails: they are negative just before L).
//  2. Positions held at both ends are isoperimetric constraints on the chord g = r(L) - r(0), the
//     reactions their multipliers. With D = dg/dF the change of the chord per unit change of the
//     end load along the load-controlled equilibria (k x k for k held directions),
//       index = index_dead + n_+(D) + r_Z - k,
//     the bordered-Hessian (Haynsworth inertia) count; r_Z is the rank of the chord change along
//     zero modes of the load-controlled problem (D is then taken on the loads doing no work on
//     them). Along the axis of a straight inextensible rod the chord cannot change to first
//     order, so that constraint is empty and dropped (the axial force is indeterminate).
// Where the energy depends on where the rod is - a field whose force depends on position (a soft
// wall, a barrier) or a contact with a curved obstacle - the rotation alone is not the
// configuration: the translation costs energy and the second variation holds dr.Hess V dr, non-
// local in the rotation. The positions are then configuration variables too (the "full frame":
// U holds (dr, dpsi), the Jacobi fields carry dn' = -(df/dr) dr), and every position an end holds
// is a constraint of its own (k = those held at either end, D = d(held positions)/d(reactions));
// stability.cpp says why the count stays valid (a problem of Lagrange: crossings are still
// one-way). Without such a dependence the full frame gives the same count (tested).
// Point contacts (force f > 0, the rod curving away from the obstacle at g'' > 0): the contact
// force is a dead load of the load-controlled problem, nu.dr(s_c) = 0 one more isoperimetric
// constraint (multiplier: the change of the force), and the contact point slides along the
// obstacle, which adds f (nu.dr' + k.dr)^2 / (2 g'') - f dr.K dr / 2 to the second variation
// (K = Hess g / |grad g| the obstacle's curvature, k = K d3, g'' = nu.d3' + d3.K d3; on a plane
// K = 0): a jump of the Jacobi fields' force and moment.
// Zero modes (Jacobi fields meeting every condition: symmetries such as the isotropic rod's
// rotation about its axis, rigid motions, or the rod at a bifurcation) are reported apart from
// the index, never counted in it.
// Half rods with a half-turn end (plectoneme.toml) get the whole rod's index: that of the half
// rod as stated (the symmetric perturbations) plus that of the antisymmetric ones, a half-rod
// problem with the complementary end conditions and, with self-contact, the pair energy's other
// second variation (stability_symmetric.hpp).
//
// Extended contacts (the rod lying on a wall or wrapped on a disc): the perturbations hold the
// lying part on the obstacle, sliding along it (detail/stability_extended_contact.hpp); for planar
// rods the index is the discretised energy's (method "discretised_energy"), where its self-checks
// pass.
// Not covered (index null with the reason): extended contacts of spatial rods, contacts of extensible rods,
// contacts with zero force (weakly active) or where the rod is about to flatten or wrap onto the
// obstacle (g'' = 0), half-turn ends that impose the loop's rotation, half-turn points at s = 0
// and half-turn symmetric rods with contacts, unknown parameters that are not end loads except a
// sliding length closed by the continuity of H (stability_free_length.hpp),
// non-conservative loads (a dead couple on a 3D end free to rotate), degenerate constraints (a
// straight rod held at its full length), degenerate crossings.
#pragma once

#include <Eigen/Dense>
#include <optional>
#include <string>
#include <vector>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct StabilityOptions {
  // Sub-intervals along the whole rod at least (two per shooting segment at least): the
  // eigenphases are observed at the end of each step of the fields' integration, and steps are
  // no longer than these; each is halved while an eigenphase of W moves more than
  // max_phase_step over it, so passages are never missed nor paired wrongly. Too few (2 on the
  // column at P = 200, whose phases turn through 9 pi) let a phase turn by more than pi unseen:
  // 16 leaves a factor 4 on the cases of the tests.
  int min_steps = 16;
  double max_phase_step = 0.5;  // rad
  // Conjugate points are located to this fraction of L (regula falsi on the phase from the
  // step that holds the passage; 1e-7 leaves a factor 100 on the tests' 1e-5), in at most
  // max_locating_steps trial integrations each.
  double passage_tolerance = 1e-7;
  int max_locating_steps = 20;
  int max_halvings = 16;
  // Observe the eigenphases between the integration's steps on its interpolant where those steps
  // are longer than the observations need (most of a rod whose phases turn slowly), going back to
  // exact observations near a conjugate point: fewer integration steps, the same count. false:
  // every observation on an exact integration (tests compare the two).
  bool interpolated_observations = true;
  // Where the eigenphase's speed has a proved bound - a planar rod whose force is constant along
  // it (uniform, inextensible, no field, no contact: the Elastica) has one eigenphase, turning at
  // most at 2 max(rate, |n| |v_hat| L^2 / (B rate)) / L in the canonical scales - the
  // observations are spaced by that bound alone, the phase moving at most 2.5 rad (< pi) over
  // each, so that no turn can pass unseen: a quarter of the observations the step control above
  // takes there. false: that step control everywhere (tests compare the two).
  bool bounded_observations = true;
  // Observations this many times denser than min_steps and max_phase_step say, on integration
  // steps as long as at 1 where they are observed on the interpolant: how a count in a field
  // that stiffens the perturbations is confirmed (analyse_stability runs it again so).
  double observation_density = 1.0;
  // Singular values (of the orthonormal frame's blocks, dimensionless) and eigenvalues of the
  // boundary form below this are zero: a conjugate point exactly at L, a zero mode. The frame is
  // integrated to ~1e-10, so 1e-6 leaves four orders of margin; modes within 1e-6 of neutral
  // (next to a bifurcation) are reported as zero modes, not guessed.
  double zero_tolerance = 1e-6;
  // Tolerance (absolute and relative) of the fields' integration; 0, or anything not looser than
  // the state's: the state's.
  double field_tolerance = 0.0;
  // Let point contacts slide along their plane (the right second variation). false holds them at
  // their material point instead, only to show the difference (tests, docs).
  bool contact_sliding = true;
  // Carry the positions as configuration variables beside the rotation (the full frame) even
  // where the energy does not depend on where the rod is. It is used automatically where it does
  // (position-dependent fields, contacts with curved obstacles); forcing it elsewhere only checks
  // that the two frames count alike (tests).
  bool positions_as_configuration = false;
  // The index of a planar rod lying on an obstacle (an extended contact) from the discretised
  // energy at 800 elements (detail/stability_extended_contact.hpp): seconds each (solves at 800
  // and 400 elements and their dense eigenproblems), so a branch's points may leave it out (null,
  // saying so).
  bool extended_contacts = true;
};

struct StabilityReport {
  std::optional<int> index;  // number of negative eigenvalues; empty when not defined (reason)
  std::string reason;        // why the index is not defined, else empty
  int zero_modes = 0;        // Jacobi fields meeting every condition (symmetries, bifurcations)
  std::vector<double> conjugate_points;  // s in (0, L) where U(s) is singular
  int interior_count = 0;                // conjugate points in (0, L), with multiplicity
  int end_count = 0;                     // negative directions added by the conditions at s = L
  int dead_load_index = 0;               // interior_count + end_count: every end load dead
  int constraint_count = 0;              // end positions held at both ends (isoperimetric)
  int constraint_correction = 0;         // index - dead_load_index
  // Half of a half-turn symmetric rod (a `half_turn` end): the counts above are the whole rod's,
  // the sums of the symmetric and antisymmetric halves, whose indices are these (empty otherwise).
  // Where the whole rod's index is not defined, symmetric_index may still be (the self-contact's
  // sliding partners not defined: stability_symmetric.hpp).
  std::optional<int> symmetric_index, antisymmetric_index;
  std::string method = "conjugate_points";
  // Why another method than the conjugate points gives the index ("discretised_energy" for the
  // planar extended contacts: detail/stability_extended_contact.hpp), else empty.
  std::string method_reason;
  // A sliding length among the unknowns (stability_free_length.hpp, method
  // "conjugate_points+reduced_energy"): its name, the index with it held, and S = d^2 E*/d ell^2
  // along the equilibria at fixed length (index = fixed_length_index + 1 if S < 0).
  std::string sliding_length;
  std::optional<int> fixed_length_index;
  std::optional<double> reduced_energy_curvature;
  long rhs_evaluations = 0;
  // Integrations of the Jacobi fields (observation steps, trial steps locating conjugate points):
  // what an index costs in the fields' own count, whatever the machine.
  long field_flows = 0;
  // No index, but unstable all the same (reason says why): a part lying on an obstacle with zero
  // contact force lifts off with lower energy, where the lowering perturbations form a cone, not
  // a space (detail/stability_extended_contact.hpp).
  bool unstable = false;
  // The index is undefined for want of accuracy, not for what the case is: a conjugate point or
  // the isoperimetric correction within the Jacobi fields' resolution. Fields integrated more
  // tightly may settle it (analyse_stability retries a branch's looser fields only then).
  bool resolution_limited = false;
  bool defined() const { return index.has_value(); }
  bool stable() const { return index && *index == 0; }
};

// The index of the equilibrium x of `problem` (x solved). Never throws for an unsupported case:
// the report says why the index is not defined.
StabilityReport analyse_stability(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                  const StabilityOptions& options = {});

// "stable", "unstable (index k)", "unstable, no index: reason" (StabilityReport::unstable), or
// "index undefined: reason".
std::string describe(const StabilityReport& report);

}  // namespace kirchhoff

// The stability index where an unknown parameter is a length of the rod that slides: the length
// ell outside a frictionless sleeve (sleeve.toml, arm_scale.toml), solved for with the continuity
// of H across the sleeve's exit (EndCondition::impose_hamiltonian). ell is then a degree of
// freedom of the energy like the rod's shape: the rod slides through the sleeve, and the H
// condition is the stationarity of the total energy in ell (the configurational, Eshelby-like
// force: Bigoni, Dal Corso, Bosi & Misseroni 2014; Bosi, Misseroni, Dal Corso & Bigoni 2014).
//
// Method: the second variation over (perturbations of the outside part, delta ell), reduced on ell.
// Let the fixed-length problem be the same case with ell given (not an unknown) and its H
// condition dropped, Q its second variation, and E*(ell) the total energy along its equilibria.
// With Q nonsingular, eliminating the shape perturbations (a Schur complement) leaves
//   index = index(Q) + (1 if S < 0),   S = d^2 E*/d ell^2,
// where E* includes the part inside the sleeve (straight, under the constant force the H
// condition names) and S = 0 is a zero mode: a fold of the problem in ell.
//   index(Q): analyse_stability on the fixed-length problem (ell is just the rod's length there).
//   S: along the fixed-length equilibria the whole problem's H row r = H(exit) - H(inside) is
//      -dE*/d ell (dE_outside/d ell = -H for a uniform rod whose ends do not move with ell; the
//      inside part adds H(inside); the factor -1 is checked against energies in
//      tests/stability_free_length_test.cpp). So S = -dr/d ell along the family, which is the
//      Schur complement of the whole problem's shooting Jacobian on its (H row, ell column):
//        S = -(r_ell - r_x J_fixed^-1 F_ell),
//      one linear solve with the Jacobian Newton uses, no extra Newton solves. Its accuracy is
//      that of the ell column (central differences of the flow, kParameterStep = 1e-6) and of the
//      H row (central differences of a closed form): S is zero (a zero mode) within
//      kFreeLengthZeroTolerance of the sizes of the products it sums.
//
// Not covered (index null, reason given): an unknown that moves an obstacle (no energy of which
// it is a degree of freedom), several unknowns that change the rod, other unknown parameters
// beside it (end loads acting as multipliers), a length not balanced by an H condition at one end
// (then it is not a sliding length), a length that changes the rod's properties besides its
// length, a rod whose properties vary along it or that feels an external field (dE_outside/d ell
// = -H needs a Lagrangian without explicit s, and a field would act on the part inside the sleeve
// too, which the case does not describe), an H condition whose value changes with ell or an exit
// that does not hold the rod's position and direction (the part inside then has no known energy:
// it is H_inside ell only for a straight part along a fixed line under a constant axial force),
// half-turn symmetric half rods, a fixed-length problem
// with a zero mode (Q singular: the reduction is not defined) or whose own index is undefined.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>

#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// S within this fraction of the sizes of the products it sums (|r_ell| + sum_i |r_x,i dx_i/d ell|)
// is zero. Those products are accurate to ~1e-8 of their size (the ell column's central
// differences: truncation ~1e-12, round-off of the 1e-12 integration over the 1e-6 step ~1e-6 at
// worst; S measured against energies along Newton-solved families agrees to 2e-8 of the scale),
// so 1e-5 leaves a margin while a fold passed by 1e-5 of the scale is called a zero mode rather
// than guessed.
inline constexpr double kFreeLengthZeroTolerance = 1e-5;

struct FreeLengthStability {
  StabilityReport report;        // the whole problem's: method "conjugate_points+reduced_energy"
  StabilityReport fixed_length;  // of the problem with the length held at its value
  std::string parameter;         // the sliding length's name (empty: the problem has none)
  double reduced_curvature = 0.0;  // S = d^2 E*/d ell^2 (force per length); NaN where not computed
  double curvature_scale = 0.0;    // |r_ell| + sum_i |r_x,i dx_i/d ell|: what S's zero test is relative to
};

// The unknown parameter that changes the rod or an obstacle, "" when none does (then
// analyse_stability covers the problem).
std::string rod_changing_unknown(const ShootingProblem& problem);

// Why the unknown `name` (rod_changing_unknown's) is not a sliding length this reduction covers,
// "" when it is: the classification both stability analyses use (this one and the discretised
// energy's, discrete_stability.hpp), with the reasons listed above.
std::string sliding_length_reason(const ShootingProblem& problem, const Eigen::VectorXd& x, const std::string& name);

// Whether the end carries an H condition (impose_hamiltonian): the sleeve's exit of a sliding length.
bool has_hamiltonian_condition(const EndCondition& end);

// The problem with the sliding length `name` given at its value in x and its H condition dropped,
// and x without that unknown: what E*(ell) is the energy of. Throws std::invalid_argument with the
// reason when it cannot be built.
struct FixedLengthProblem {
  std::unique_ptr<ShootingProblem> problem;
  Eigen::VectorXd x;
  int parameter_column = -1;  // ell's column in the whole problem's unknowns
};
FixedLengthProblem fixed_length_problem(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                        const std::string& name);

// The index of the equilibrium x of `problem` (x solved) with the sliding length among the
// configuration variables; never throws (the report says why it is not defined).
FreeLengthStability analyse_free_length(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                        const StabilityOptions& options = {});
StabilityReport analyse_free_length_stability(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                              const StabilityOptions& options = {});

}  // namespace kirchhoff

// Small-amplitude vibrations of the planar Elastica about a solved equilibrium (section 9 and
// Appendix B of the reference paper).
//
// With q = q_e(s) + eps qbar(s) cos(omega t) (eq. 92) the O(eps) part of the dynamics (B.2) is the
// linear boundary-value problem (B.4), a 6-dimensional system in the planar state layout
// qbar = (xbar, ybar, thetabar, nbar_x, nbar_y, mbar):
//   xbar' = -thetabar sin(theta_e),   ybar' = thetabar cos(theta_e),   EI thetabar' = mbar,
//   mbar' = nbar_x sin(theta_e) - nbar_y cos(theta_e) + thetabar (n_xe cos(theta_e) + n_ye sin(theta_e)),
//   nbar_x' = -rhoS omega^2 xbar,     nbar_y' = -rhoS omega^2 ybar.
// These are exactly the variational equations of the planar statics (B.3) plus the inertia
// terms, so natural curvature, EI(s) and a conservative field (n' = -f(r), linearised to
// nbar' = -(df/dr) rbar) carry over unchanged; extensible rods are refused.
//
// End conditions. Each end keeps the equilibrium's complete set of conditions, linearised: every
// quantity the case imposes is held at its equilibrium value while the rod vibrates, so its
// perturbation vanishes. Imposed positions and angles (supports, clamps) give rbar = 0, thetabar
// = 0; applied loads are *dead* loads (fixed magnitude and direction), so nbar = 0, mbar = 0 along
// them. In particular
//   clamped              xbar = ybar = thetabar = 0
//   pinned               xbar = ybar = mbar = 0
//   free                 nbar_x = nbar_y = mbar = 0
//   sliding (roller along e_x under the dead load P, the Euler column of euler_column.toml)
//                        ybar = 0, nbar_x = 0, mbar = 0.
// So a column whose end slides under a given load P vibrates differently from one whose end
// shortening is imposed (both ends pinned): the first has a softening mode as P nears a
// critical load, the second holds the chord fixed. The case decides which, by how it states its
// ends. Extra conditions (e.g. the end slope theta0 of simply_supported.toml, balanced by the
// unknown P) only choose which equilibrium is solved and play no part in the vibration problem.
//
// Frequencies by shooting from both ends to mid-span: with Y0(s), YL(s) the solutions started in
// the 3-dimensional spaces allowed by the conditions at s = 0 and s = L, omega is an eigenfrequency
// when [Y0(L/2), YL(L/2)] is singular. Matching at mid-span (rather than shooting across the whole
// rod) halves the exponential growth exp(sqrt(omega) L) that costs accuracy at high modes. The
// determinant, with rows made dimensionless and columns normalised (a positive scaling, so its
// sign is kept), lies in [-1, 1]; its sign changes on an omega grid bracket the frequencies, which
// TOMS 748 (bracketing, never leaves the bracket) refines to round-off.
//
// Straight equilibria with the axial position imposed at both ends are a degenerate case: a
// constant axial force nbar = nbar_t t with zero displacement solves (B.4) for every omega (the
// inextensible rod is axially statically indeterminate), so the determinant vanishes
// identically. There the axial pair (rbar.t, nbar.t) decouples and is identically zero on the
// vibration modes, and the transverse 4x4 matching problem is solved instead.
//
// Unstable equilibria have modes with omega^2 = -sigma^2 < 0 (imaginary frequencies: the
// perturbation grows as exp(sigma t)). The same boundary-value problem with rhoS omega^2 replaced by
// -rhoS sigma^2 holds them, and its determinant is searched on a grid in sigma (the same step, from
// omega_min) up to sigma_max, with the same bracketing and TOMS 748. By Sylvester's law of inertia
// the number of negative omega^2 is the number of negative eigenvalues of the second variation
// (the mass int rhoS |rbar|^2 is positive on the admissible perturbations), i.e. the stability
// index of the equilibrium *under the end conditions as read here*: every load given at an end,
// including an unknown one such as P of simply_supported.toml, is a dead load (nbar = 0 along it).
// stability.hpp reads such an unknown load as a Lagrange multiplier (the conjugate displacement
// held), so for those cases the two count different problems (docs/stability-cross-check.md).
// omega^2 = 0 (rigid motions, zero modes) is found by neither search.
//
// Where the search stops: with N the largest compression -n.d3 along the rod, kappa the largest
// curvature, B_min the smallest stiffness and G the largest |df/dr|, the second variation
// int B thetabar'^2 + (n.d3) thetabar^2 - rbar.(df/dr) rbar is bounded below by
// -(N^2 / B_min + N kappa^2 + G) int |rbar|^2 when both ends hold their positions (thetabar = t'.rbar'
// and one integration by parts, rbar = 0 at the ends; Young's inequality with weights 1/2). A free
// end adds boundary terms, the worst a rigid turn about the centre (-12 N / L^2 per unit mass), so
//   sigma_bound^2 = (N^2 / B_min + N kappa^2 + 12 N / L^2 + G) / rhoS,
// and the grid goes to sigma_max = 2 sigma_bound (a factor 4 on omega^2 beyond it). A rod without
// compression or field gradient has no negative omega^2 and nothing is searched.
//
// H_vib (eq. 95b) is computed along every mode; it is a Noether invariant only when the
// equilibrium is straight (and the rod uniform, without field). For a straight column the form
// (97) is computed too, with the sign of its P term corrected (see eq97_hamiltonian).
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/equations/integrator.hpp"
#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// Perturbation state in the planar layout (x, y, theta, n_x, n_y, m), the same as the equilibrium.
using VibrationState = Eigen::Matrix<double, 6, 1>;

struct VibrationOptions {
  int modes = 3;            // how many of the lowest non-zero frequencies to find
  double rho_s = 1.0;       // mass per unit length rho S (uniform)
  // The frequency scale omega_0 = sqrt(EI(0) / (rhoS L^4)) sets the search grid: beam frequencies
  // are (k pi)^2 omega_0 apart at least ~3 omega_0 for the lowest ones, so a step of 0.2 omega_0
  // separates them with margin. Two frequencies closer than one step can be missed (no sign change).
  double grid_step = 0.2;   // in units of omega_0
  double omega_min = 1e-3;  // first grid point, in units of omega_0; rigid-body modes (omega = 0) are skipped
  double omega_max = 0.0;   // last grid point in units of omega_0; 0: up to max_grid_points
  // Search the modes with omega^2 < 0 as well (sigma from omega_min to sigma_max, step grid_step).
  bool unstable_modes = true;
  double sigma_max = 0.0;   // in units of omega_0; 0: twice the bound above
  int max_grid_points = 20000;
  int profile_samples = 201;  // points per mode shape, ends included
  // RK78 at 1e-12 per step: with the mid-span matching the frequencies come out to ~1e-10 relative.
  IntegratorOptions integrator;

  std::string validate() const;  // empty when valid, else the reason
};

// Why the vibrations of this problem cannot be analysed with these options ("" when they can),
// said before its equilibrium is solved for: a spatial rod (the vibration equations B.4 are
// planar), or the options' own reason (VibrationOptions::validate). Bad input for both front ends.
std::string vibration_refusal(const ProblemDefinition& definition, const VibrationOptions& options);

struct VibrationMode {
  double omega = 0.0;   // sqrt(omega2); 0 for an unstable mode (omega2 < 0)
  double omega2 = 0.0;  // omega^2, negative for an unstable mode
  // sigma = sqrt(-omega2): an unstable mode grows as exp(sigma t); 0 for a vibration.
  double growth_rate() const;
  std::vector<double> s;                // equally spaced, ends included
  std::vector<VibrationState> state;    // qbar(s), normalised so that max |rbar| = 1 (or max |thetabar| = 1 if rbar = 0)
  std::vector<double> H_vib;            // eq. (95b) at each s
  std::vector<double> H_vib_column;     // eq. (97), corrected, at each s; empty unless the equilibrium is straight
  InvariantStats H_vib_stats;           // applies: straight, uniform rod, no external field
  // sigma_min / sigma_max of the scaled matching matrix at omega: how singular it is (round-off at a
  // true frequency).
  double matching_residual = 0.0;
};

struct VibrationAnalysis {
  std::vector<VibrationMode> modes;  // sorted by omega
  // Modes with omega^2 < 0, most negative first (empty when not searched: see unstable_searched).
  std::vector<VibrationMode> unstable_modes;
  bool unstable_searched = false;
  double sigma_max = 0.0;  // the search for them went up to this growth rate (absolute units)
  bool straight_equilibrium = false;
  bool axial_indeterminate = false;  // the degenerate straight case above (transverse problem solved)
  double omega_scale = 0.0;          // omega_0
  // Why H_vib (eq. 95b) is not conserved along the modes, "" where it is (a straight equilibrium of
  // a uniform rod in no field): the curved equilibrium, the stiffness or density varying along the
  // rod, or the external field (whose axial force varies).
  std::string H_vib_not_conserved;
  std::vector<double> frequencies() const;
  int negative_omega2_count() const { return static_cast<int>(unstable_modes.size()); }
  // omega^2 of every mode found, unstable ones first, increasing.
  std::vector<double> omega2() const;
};

// The vibration problem about one equilibrium: x solved for `problem` (a planar ShootingProblem).
// Throws std::invalid_argument naming the reason for a spatial or extensible rod, active contacts,
// an end sliding in a sleeve (H condition), invalid options, or end conditions that are not a
// complete set.
class VibrationProblem {
 public:
  VibrationProblem(const ShootingProblem& problem, const Eigen::VectorXd& x, VibrationOptions options = {});

  // det of the dimensionless, column-normalised matching matrix at omega (in [-1, 1]); it changes
  // sign at each simple eigenfrequency.
  double scaled_determinant(double omega) const;
  // The same at a signed omega^2 (negative: the unstable modes' problem).
  double scaled_determinant_at(double omega2) const;
  // The lowest options.modes frequencies above omega_min, increasing. Throws std::invalid_argument
  // when the grid ends (omega_max or max_grid_points) before enough are found.
  std::vector<double> frequencies() const;
  // Every omega^2 < 0 with sigma = sqrt(-omega^2) between omega_min and sigma_max(), increasing
  // (two closer than one grid step in sigma are found from the determinant's dip between them,
  // a double root as two; as for the frequencies).
  std::vector<double> negative_omega2() const;
  // The mode at an eigenfrequency omega (as returned by frequencies()), sampled along the rod.
  VibrationMode mode(double omega) const;
  // The mode at a signed omega^2 (as returned by negative_omega2(), or a frequency squared).
  VibrationMode mode_at(double omega2) const;
  // frequencies() and their modes, and (options.unstable_modes) negative_omega2() and theirs.
  VibrationAnalysis analyse() const;
  // Where the search for omega^2 < 0 stops (absolute units), and the bound it is twice of.
  double sigma_max() const { return sigma_max_; }
  double sigma_bound() const { return sigma_bound_; }

  bool straight_equilibrium() const { return straight_; }
  bool axial_indeterminate() const { return axial_indeterminate_; }
  double omega_scale() const { return omega_scale_; }
  const RodModel& model() const { return equations_->model(); }
  // Why H_vib (eq. 95b) varies along the modes (VibrationAnalysis::H_vib_not_conserved); "" where
  // it is an invariant: a straight equilibrium of a uniform rod in no field.
  std::string H_vib_not_conserved() const;

 private:
  struct Matching;
  Matching matching(double omega2) const;
  // (y_e, qbar) at the arclengths s (monotone, s.front() where y_e and qbar are given), integrated together.
  std::vector<Eigen::Matrix<double, 12, 1>> integrate_samples(const Eigen::VectorXd& y_e, const VibrationState& qbar,
                                                              const std::vector<double>& s, double omega2) const;
  // A root of f (a determinant of `variable`) bracketed by a sign change between a and b, checked
  // to be a singular matching matrix; `omega2_of` maps the variable to omega^2.
  template <class Omega2>
  double bracketed_root(double a, double fa, double b, double fb, const Omega2& omega2_of, const char* name) const;
  // The roots a dip of the determinant hides: samples at a, between (fm) and b of one sign, |fm|
  // the smallest (two roots closer than the grid step keep the sign at every sample). The minimum
  // of the determinant times sign(fm) over [a, b] splits them where it changes sign (each then
  // bracketed); a matching matrix of nullity k at that minimum is a k-fold root. Appends what it
  // finds to *found (in the variable, not omega^2).
  template <class Omega2>
  void dip_roots(double a, double fa, double fm, double b, double fb, const Omega2& omega2_of, const char* name,
                 std::vector<double>* found) const;
  // The roots of the determinant in the variable v = at(i) on the grid i = 0, 1, ... while
  // go_on(i, found) (sign changes and dips), in the order found.
  template <class Omega2, class At, class GoOn>
  std::vector<double> grid_roots(const At& at, const GoOn& go_on, const Omega2& omega2_of, const char* name) const;
  // sigma_bound from the equilibrium sampled at `points` (see the header comment).
  void bound_growth_rate(const std::vector<RodPoint>& points, const ProblemDefinition& definition);
  // start_basis_, end_basis_, row_projection_ and axial_indeterminate_ from the ends' linearised
  // conditions (held_condition_rows in vibration.cpp).
  void matching_spaces(const Eigen::MatrixXd& start_rows, const Eigen::MatrixXd& end_rows);

  std::shared_ptr<const RodEquations> equations_;
  VibrationOptions options_;
  double length_ = 0.0;
  double omega_scale_ = 0.0;
  double sigma_bound_ = 0.0, sigma_max_ = 0.0;
  Eigen::VectorXd y_start_, y_end_;  // equilibrium at s = 0 and s = L
  std::vector<double> node_s_;       // shooting nodes L i / M, i = 0..M
  std::vector<Eigen::VectorXd> node_y_;  // the equilibrium there
  Eigen::MatrixXd start_basis_, end_basis_;  // 6 x k: initial perturbations allowed by each end
  Eigen::MatrixXd row_projection_;           // r x 6: identity, or drops the axial pair when degenerate
  Eigen::VectorXd row_scale_;                // makes the state components dimensionless
  bool straight_ = false;
  bool axial_indeterminate_ = false;
};

// Transverse deflection w of a straight column along its axis t (w = rbar . normal) and its
// derivatives, read from the perturbation state through (B.4): w' = thetabar, w'' = mbar / EI,
// w''' = mbar' / EI.
struct ColumnDeflection {
  double w = 0.0, w1 = 0.0, w2 = 0.0, w3 = 0.0;
};

// Eq. (97) for a straight column under the compressive load P (n_e = -P t):
//   H_vib = 1/2 EI w''^2 + 1/2 rhoS omega^2 w^2 - 1/2 P w'^2 - EI w' w'''.
// The paper prints -1/2 P w^2 for the third term; that quantity is not constant along the modes
// of (96) (its derivative is P w' (w'' - w)), whereas -1/2 P w'^2 is exactly (95b) with theta_e = 0,
// n_xe = -P, and is constant. `as_printed` gives the printed form, for the tests that show this.
double eq97_hamiltonian(double EI, double rho_s, double omega, double P, const ColumnDeflection& d,
                        bool as_printed = false);

// Eq. (95b) at one point: qbar the perturbation, theta_e, n_e = (n_xe, n_ye) the equilibrium there.
double eq95b_hamiltonian(double EI, double rho_s, double omega, double theta_e, double n_xe, double n_ye,
                         const VibrationState& qbar);

}  // namespace kirchhoff

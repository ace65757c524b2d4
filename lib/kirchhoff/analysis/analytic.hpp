// Closed-form (and closed-form-up-to-one-root) results for elastic rods, kept apart from the
// numerical solvers so that the solvers can be checked against them.
//
// Contents:
//   * PinnedElastica: the first mode of the pinned-pinned planar Elastica in Jacobi elliptic
//     functions (Love, "A Treatise on the Mathematical Theory of Elasticity", ch. XIX).
//   * eq54_*: the maximum curvature and deflection of the same rod read off the Noether
//     invariant H = 1/2 EI kappa^2 - P cos(theta) (eq. 54 of the reference paper).
//   * euler_critical_load: Euler buckling loads for the four classical end conditions.
//   * pinned_column_frequency, beam_frequency, clamped_column_frequency: vibration frequencies
//     of straight columns and beams (eq. 96).
//   * StraightTwistedRod and clamped_twisted_critical_moment: the straight twisted rod under
//     tension and its Greenhill instability for clamped ends.
//
// Conventions shared with the planar solver (planar_equations.cpp): theta is the angle of the
// tangent d3 = (cos theta, sin theta) above the x axis, kappa = theta', the internal force n acts
// on [0, s] from (s, L], and m' = (n x r') . e_z, so a rod compressed by P (n = -P e_x) obeys
//   EI theta'' = -P sin(theta).
//
// Every function checks its arguments and throws std::invalid_argument, naming the argument and
// the reason, when they are outside the stated domain (non-finite values included).
#pragma once

namespace kirchhoff::analytic {

// Planar Elastica, pinned at both ends, first (one half-wave) mode; Love's classical solution.
// The rod starts at the origin heading at angle theta0 above the x axis, ends on the x axis at
// x = end_to_end(), and bulges towards +y; both supports carry the compressive end load P along
// the chord and no moment.
//
// With k = sin(theta0 / 2) (elliptic modulus), lambda = sqrt(P / EI) and K = K(k):
//   sin(theta / 2) = k sn(K - lambda s, k),   lambda L = 2 K(k),   so  P = 4 K(k)^2 EI / L^2.
//
// Sign convention: the arch turns clockwise, so kappa(s) = theta'(s) <= 0 on [0, L] and
// kappa(L / 2) = -kappa_max(); kappa_max() and y_max() are magnitudes.
//
// Domain: L > 0, EI > 0, theta0 in (0, pi) (theta0 -> pi is the closed loop, K -> infinity);
// arclengths s in [0, L].
struct PinnedElastica {
  double L;       // length
  double EI;      // bending stiffness
  double theta0;  // tangent angle at s = 0; theta(L) = -theta0

  double k() const;           // elliptic modulus sin(theta0 / 2)
  double lambda() const;      // sqrt(P / EI) = 2 K(k) / L
  double load() const;        // P = 4 K(k)^2 EI / L^2
  double y_max() const;       // mid-span deflection 2 k / lambda
  double kappa_max() const;   // |curvature| at mid-span, 2 k lambda
  double end_to_end() const;  // chord between the supports, L (2 E(k) / K(k) - 1)

  double theta(double s) const;  // 2 asin(k sn(K - lambda s, k))
  double kappa(double s) const;  // theta'(s) = -2 k lambda cn(K - lambda s, k)
  double x(double s) const;      // (2 / lambda) (E(k) - E(am(K - lambda s), k)) - s
  double y(double s) const;      // (2 k / lambda) cn(K - lambda s, k)
  // The invariant H(s) = 1/2 EI kappa^2 - P cos(theta); equals -P cos(theta0) for every s.
  double hamiltonian(double s) const;
};

// Eq. (54) of the reference paper: equate H = 1/2 EI kappa^2 - P cos(theta) at a support
// (kappa = 0, theta = theta0) and at mid-span (theta = 0), and use EI kappa = -P y:
//   kappa_max = sqrt(2 P / EI (1 - cos theta0)),   y_max = sqrt(2 EI / P (1 - cos theta0)).
// Exact for the Elastica with any P > 0, EI > 0, theta0 in (0, pi).
double eq54_kappa_max(double P, double EI, double theta0);
double eq54_y_max(double P, double EI, double theta0);

// Euler buckling of a straight column, P_cr = x_n^2 EI / L^2 = (n pi)^2 EI / (K_eff L)^2.
enum class EulerEnds { PinnedPinned, ClampedFree, ClampedPinned, ClampedClamped };

// x_n for mode n >= 1, in increasing order:
//   PinnedPinned   n pi
//   ClampedFree    (2n - 1) pi / 2
//   ClampedPinned  n-th positive root of tan x = x (4.4934094579..., 7.7252518369..., ...)
//   ClampedClamped 2 pi, 2 x_1, 4 pi, 2 x_2, ... : symmetric modes 2 j pi alternate with the
//                  antisymmetric ones 2 x_j (x_j the roots of tan x = x, i.e. tan(x/2) = x/2).
double euler_load_parameter(EulerEnds ends, int mode = 1);
double euler_critical_load(EulerEnds ends, double EI, double L, int mode = 1);

// n-th positive root (n >= 1) of tan x = x; it lies in (n pi, n pi + pi / 2).
double tan_x_equals_x_root(int n);

// Transverse vibrations of a straight uniform column (section 9, eq. 96):
//   EI w'''' + P w'' - rhoS omega^2 w = 0,  P the compressive dead load, rhoS the mass per length.
//
// Pinned-pinned (the far end sliding axially under P): w = sin(k pi s / L) and
//   omega_k^2 = (EI (k pi / L)^4 - P (k pi / L)^2) / rhoS,
// real for P below the k-th Euler load (k pi)^2 EI / L^2; above it the straight column is unstable
// in that mode and the function throws.
double pinned_column_frequency(double EI, double P, double rho_s, double L, int mode = 1);

// Beams without axial load, omega = (beta L)^2 sqrt(EI / rhoS) / L^2 with beta L the mode-th
// positive root of the characteristic equation:
//   ClampedFree     1 + cos(x) cosh(x) = 0   1.87510406871196, 4.69409113297418, 7.85475743823761, ...
//   ClampedClamped  cos(x) cosh(x) = 1       4.73004074486270, 7.85320462409584, ...  (x = 0 excluded)
enum class BeamEnds { ClampedFree, ClampedClamped };
double beam_frequency_parameter(BeamEnds ends, int mode = 1);
double beam_frequency(BeamEnds ends, double EI, double rho_s, double L, int mode = 1);

// Clamped-clamped column under the compressive dead load P (one clamp sliding axially), from
// the characteristic equation of (96): with w = A cosh(a s) + B sinh(a s) + C cos(b s) + D sin(b s),
//   a^2 = (-P + sqrt(P^2 + 4 EI rhoS omega^2)) / 2EI,  b^2 = (P + sqrt(...)) / 2EI,
// the four clamp conditions are singular when
//   2 a b (1 - cosh(a L) cos(b L)) + (a^2 - b^2) sinh(a L) sin(b L) = 0.
// The mode-th root in omega > 0, found by scanning b L and refining with Brent. Domain: P below
// the clamped-clamped Euler load 4 pi^2 EI / L^2 (P < 0 is a tension).
double clamped_column_frequency(double EI, double P, double rho_s, double L, int mode = 1);

// A straight rod along e3, twisted by an end rotation phi and pulled by a tension T.
// Isotropic bending stiffness B, twist stiffness C; m = (C phi / L) e3, n = T e3, and the
// Hamiltonian H = 1/2 m . K^-1 m + n . d3 = 1/2 m3^2 / C + T.
// Domain: B > 0, C > 0, L > 0, phi and T finite.
struct StraightTwistedRod {
  double B, C, L, phi, T;
  double twisting_moment() const;  // m3 = C phi / L
  double hamiltonian() const;      // 1/2 m3^2 / C + T
};

// Greenhill instability of a straight twisted isotropic rod clamped at both ends (the far end
// slides axially under the dead tension T; lateral position and orientation fixed): the smallest
// twisting moment M > 0 for which the linearised equations have a nontrivial solution.
//   T = 0:        M L / B = 2 x_1 = 8.98681891581813...
//   L -> infinity: M -> 2 sqrt(B T) (Greenhill); more precisely
//                  M = 2 sqrt(B T + pi^2 B^2 / L^2) (1 + O((B / (T L^2))^2)).
// Domain: B > 0, L > 0, T > -4 pi^2 B / L^2 (compression below the clamped-clamped Euler load;
// at that load the straight rod buckles with no twist at all). The derivation is in analytic.cpp.
double clamped_twisted_critical_moment(double B, double T, double L);

// Michell's twisted ring (Michell 1889-90; rederived, with the higher modes, by Goriely 2006,
// "Twisted elastic rings and the rediscoveries of Michell's instability", J. Elasticity 84): a
// closed isotropic ring of radius R, bending stiffness B and twist stiffness C, its material
// twisted uniformly by tau per length, is stable while C tau R < sqrt(3) B. Its out-of-plane
// perturbations of wavenumber `mode` (n >= 2 around the ring; n = 1 is a rigid turn) have a zero
// eigenvalue at C tau R / B = sqrt(n^2 - 1), each a double one (the mode and its quarter-period
// shift): the twist at which the n-th pair turns unstable, the index then 2 (n - 1).
// Domain: B, C, R > 0, mode >= 2.
double michell_ring_critical_twist(double B, double C, double R, int mode = 2);

// The symmetric single-arch Elastica pressed against a hard wall (Fig. 12 in the hard-wall
// limit): clamped-clamped, length L, end shortening Delta, frictionless point contact with the
// wall y = a at mid-span. The half rod [0, L/2] is a pendulum elastica,
//   EI theta'' = -F sin(theta - psi),  n = -F (cos psi, sin psi),
// written with Jacobi functions: sin(phi/2) = k sn(u), phi = theta - psi, u = lambda s + u0,
// lambda^2 = F/EI, and x, y from E(am u) and cn u (Love's treatise). The four unknowns
// (lambda, psi, k, u0) solve theta(0) = theta(L/2) = 0, x(L/2) = (L - Delta)/2, y(L/2) = a with
// GSL's hybrid root finder: no differential equation is integrated, so this is independent of
// the shooting solution it checks.
struct WallContactElastica {
  double P = 0.0;         // compressive load -n_x
  double n_y = 0.0;       // n_y on [0, L/2)
  double contact_force = 0.0;  // F_c = -2 n_y, the jump of n_y at the contact (eq. 63)
  double kappa_0 = 0.0;   // curvature at the clamps
  double kappa_c = 0.0;   // curvature at the contact
  double H = 0.0;         // EI kappa_0^2 / 2 - P (eq. 67 with the hard wall)
};
// Throws std::runtime_error when the root finder does not converge from its built-in guess
// (the first clamped-clamped buckling mode scaled to touch the wall).
WallContactElastica wall_contact_elastica(double L, double EI, double Delta, double a);

// The clamped-clamped Elastica in its first (symmetric) mode with its ends a distance D apart
// (0 < D < L): one full wave of the pendulum elastica, so D/L = 2 E(k)/K(k) - 1 fixes the modulus
// and the compression is P = 16 K(k)^2 EI/L^2. Returns P.
double clamped_clamped_elastica_load(double EI, double L, double D);

// Two strands of radius R wound into a double helix of helical angle theta (between the tangent
// and the helix axis), each touching the other along a line (Thompson et al. 2002, eq. 58):
// contact force per length, twisting moment and axial tension of each strand.
double helix_contact_pressure(double theta, double EI, double R);  // (58a) EI sin^4/(R^3 cos 2theta)
double helix_twisting_moment(double theta, double EI, double R);   // (58b) 2 EI sin^3 cos/(R cos 2theta)
double helix_tension(double theta, double EI, double R);           // (58c) EI sin^4/(R^2 cos 2theta)
// Eq. (61): the end pull of a plectoneme whose contact region has helical angle theta, from
// H_A = H_B: T_ext = EI/(2 R^2) sin^4 theta (1 + 2/cos 2theta). Valid for theta < pi/4.
double plectoneme_end_tension(double theta, double EI, double R);

// Where the flat contact of a clamped-clamped Elastica pressed against a wall buckles into a
// hanging fold (section 7.2): clamps at y = 0 with horizontal tangents, wall y = a, the middle of
// the rod flat on the wall over a length l under the compression P, which reaches its
// clamped-clamped Euler load there, P l^2 = 4 pi^2 EI.
// H = -P on the flat part, so the curvature vanishes wherever theta = 0: at the clamps as at the
// ends of the flat part. Each outer arc is then one full wave of an inflectional Elastica
// between inflection points on the line of action of the force F = P / cos(alpha), alpha being
// that line's angle with the wall: two pinned half-waves (PinnedElastica) of length s_h with end
// slope alpha to their chord. With mu = sqrt(EI / P):
//   s_h = 2 K(k) mu sqrt(cos alpha),  k = sin(alpha / 2),  l = 2 pi mu,  4 s_h + l = L,
//   height of the arc  2 s_h (2 E(k) / K(k) - 1) sin(alpha) = a,
// one equation in alpha (GSL's Brent), without any differential equation.
// Domain: L > 0, EI > 0, 0 < a < L / 6 (beyond, no such configuration).
struct FlatContactBuckling {
  double Delta = 0.0;      // end shortening at the onset
  double P = 0.0;          // compressive load
  double flat_length = 0.0;
  double contact_start = 0.0;  // arclength where the flat part begins (= 2 s_h)
  double alpha = 0.0;      // angle of the outer arcs' line of force to the wall
};
FlatContactBuckling flat_contact_buckling(double L, double EI, double a);
// The same rod where its mid-span point contact flattens (kappa_c = 0, hence H = -P): the two
// outer arcs meet at s = L / 2 with no flat part between them (flat_length = 0).
FlatContactBuckling contact_flattening(double L, double EI, double a);

// The clamped-clamped Elastica in its second symmetric mode (two arches of length L / 2 side by
// side, clamps and the middle on y = 0) whose crests reach the height a: where a hanging fold's
// contact forces vanish (both contacts, at L / 4 and 3 L / 4, at once). Each arch is a pinned
// half-wave of length L / 4 between its inflection points with a quarter wave on either side,
// so P = PinnedElastica{L / 4, EI, theta0}.load() with 2 y_max = a, and Delta = L - 4 chord.
// Domain: L > 0, EI > 0, 0 < a < 0.2 L (2 y_max peaks at 0.2016 L, at theta0 = 2).
struct SecondModeArches {
  double Delta = 0.0;
  double P = 0.0;
  double theta0 = 0.0;     // slope at the inflection points
};
SecondModeArches second_mode_arches(double L, double EI, double a);

// Three-point bending of the Elastica: a rod of length L on a pin and a roller at the same height
// (no moment, no horizontal force), pushed at mid-span by a frictionless indenter with the force
// F. Each half is a cantilever clamped horizontally at mid-span with the end load F/2 normal to
// the clamp: EI theta'' = (F/2) cos theta, first integral EI theta'^2 / 2 = (F/2)(sin theta -
// sin theta_e) with theta_e the slope at the supports. With chi = pi/2 - theta, k = sin(chi_e/2),
// sin psi1 = 1 / (sqrt 2 k), and differences Delta F = K(k) - F(psi1, k), Delta E likewise:
//   (L/2) sqrt(F / (2 EI)) = Delta F,  rise of mid-span = sqrt(2 EI / F) (Delta F - 2 Delta E),
//   half-span = sqrt(4 EI (2 k^2 - 1) / F).
// Domain: -pi/2 < theta_e < 0 (the slope at the supports, below the horizontal).
struct ThreePointBending {
  double force = 0.0;      // F, the indenter's force
  double rise = 0.0;       // height of mid-span above the supports
  double half_span = 0.0;  // horizontal distance from a support to mid-span
  double kappa_mid = 0.0;  // curvature at mid-span, -sqrt(F (-sin theta_e) / EI)
};
ThreePointBending three_point_bending(double L, double EI, double theta_end);

// The same three-point bending over a disc of radius rho large enough for the rod to wrap around
// it: the middle part lies on the disc over the angle 2 alpha (curvature 1/rho, tension N, pressure
// N / rho), each free part is the arc of the point-contact solution from the support (slope
// theta_e) to where its curvature reaches 1/rho. With R0 = F/2 the support's reaction and
// phi = -theta (the slope below the horizontal, from mid-span outwards), the free arc has
// EI phi'^2 / 2 = R0 (sin phi_e - sin phi); k = sin((pi/2 + phi_e)/2) and sin psi = sin((pi/2 +
// phi)/2) / k turn it into elliptic integrals:
//   sin alpha = sin phi_e - EI / (2 R0 rho^2)                (the curvature 1/rho where it meets the disc)
//   free length l = sqrt(EI / R0) (K(k) - F(psi_alpha, k)),  and L/2 = l + rho alpha  (solved for R0),
//   half-span = rho sin alpha + EI / (rho R0),  rise = rho (1 - cos alpha) + sqrt(EI / R0) (Delta F - 2 Delta E),
//   tension N = R0 sin alpha, force at each edge of the wrap R0 cos alpha.
// Throws std::invalid_argument where the rod does not wrap at this slope (its curvature at
// mid-span stays below 1/rho: three_point_bending applies) or is too short to reach the supports.
struct WrappedThreePointBending {
  double force = 0.0;         // F = 2 R0, the disc's total reaction
  double wrap_angle = 0.0;    // alpha: the wrap covers [-alpha, alpha] around the top
  double contact_start = 0.0; // s where the wrap begins, l; it ends at L - l
  double half_span = 0.0;
  double rise = 0.0;          // height of the disc's top above the supports
  double tension = 0.0;       // N on the wrap
  double edge_force = 0.0;    // the concentrated force at each end of the wrap
};
WrappedThreePointBending three_point_bending_wrapped(double L, double EI, double radius, double theta_end);

}  // namespace kirchhoff::analytic

// Internal: the antisymmetric half of the stability index of a rod solved on half its length by a
// half-turn symmetry (a `half_turn` end, cases/plectoneme.toml). stability.cpp counts the whole
// rod's index as the sum of the symmetric and the antisymmetric halves; this file holds what the
// antisymmetric half changes: the end's conditions and the self-contact's second variation.
//
// Why the index splits. The whole rod (length L = 2l) is invariant under the half-turn sigma:
// (r, R)(s) -> (Q r(L - s), Q R(L - s) F), Q the half-turn about the axis a, F = diag(1, -1, -1)
// (director 1 along a; diag(-1, 1, -1) for director 2) - the tangent reverses, d1 stays. On
// perturbations z = (dr, dpsi) (dpsi the lab-frame rotation vector: Q exp(dpsi x) R F =
// exp((Q dpsi) x) Q R F) it acts linearly: (sigma z)(s) = Q z(L - s), for positions and rotations
// alike (Q is proper, so it maps rotation vectors as vectors). The second variation Q2 of the
// whole rod is sigma-invariant, so the symmetric (sigma z = z) and antisymmetric (sigma z = -z)
// perturbations are Q2-orthogonal and index(whole) = index(sym) + index(anti), zero modes likewise.
// On either subspace the integrand at L - s equals that at s (it is quadratic, and z(L - s) =
// +-Q z(s), z'(L - s) = -+Q z'(s) enter it with the equilibrium's own symmetry: n(L - s) = -Q n(s),
// m(L - s) = -Q m(s)), so Q2 = 2 x (its integral over [0, l]), and each half is a half-rod problem
// whose conditions at s = l are:
//   symmetric:     z(l) = Q z(l): dr and dpsi lie along a (held across it); natural conditions
//                  a.dn = a.dm = 0 - the linearised half_turn end as the case states it;
//   antisymmetric: z(l) = -Q z(l): dr and dpsi lie across a (a.dr = a.dpsi = 0 held, free across
//                  it); natural conditions dn and dm along a (their lateral parts zero). A Jacobi
//                  field of the whole rod is smooth through l and its (dn, dm) maps as
//                  -sigma maps (n, m): the two sets are exactly its values at l under each parity.
// The equilibrium meets the end's loads: n(l) and m(l) are across a (n.a = m.a = 0), so the
// lateral dead couple of the antisymmetric end is conservative (1/2 m x dpsi has no lateral part
// for lateral m and dpsi).
//
// The self-contact (self_contact.hpp). The half rod's barrier W(s, r) = w(s) phi(rho - R), rho the
// distance from the axis, is the whole rod's pair energy
//   E_pair = 2 int_0^l w(s) phi(|d(s)| / 2 - R) ds,   d(s) = r(s) - r(L - s),
// restricted to symmetric configurations (d = 2 x the radial part of r, |d| / 2 = rho; the factor 2
// keeps E_whole = 2 E_half, as the elastic energy, and gives the half rod its force -grad W).
// With Psi(d) = phi(|d| / 2 - R), e = d / |d|: Hess Psi = phi'' / 4 e e^T + phi' / (2 |d|) (I - e e^T),
// and the pair's second variation is int_0^l w dd.Hess Psi dd with dd = dr(s) - dr(L - s):
//   symmetric:     dd = (I - Q) dr = 2 (I - a a^T) dr: w [phi'' e e^T + phi' / rho (I - a a^T -
//                  e e^T)], twice the half rod's Hess W - the field the case has, unchanged;
//   antisymmetric: dd = (I + Q) dr = 2 a (a.dr), along a, across d: only phi' enters, and the
//                  pair's second variation with the partners held is int_0^l w phi' / rho (a.dr)^2,
//                  a field Hessian H = w phi' / rho a a^T (phi' < 0: it lowers the energy).
// Holding the partners is one extension of the case's energy, which is defined on symmetric
// configurations only, and not the physical one for antisymmetric perturbations: they slide the
// strands past each other, and a contact between strands lying along each other does not open
// when they slide; held partners separate. Computed so, every equilibrium of plectoneme.toml past
// the end loop's closing had an antisymmetric negative direction.
//
// The sliding partners. The energy of a real contact depends on where the strands are, not on
// which material points face each other: E_pair = int_0^L w phi(D / 2 - R), D the distance of a
// cross-section to the other strand. Two such distances:
//   closest point:  D_c(s) = min_t |r(s) - r(t)|;
//   common shift:   D(sigma) = min_u |r(sigma + u) - r(L - sigma + u)| (u near 0).
// Both are unchanged when one strand slides along itself (for D: sliding strand 2 by tau turns
// D(sigma) into D(sigma + tau / 2), and the integral over sigma stays, where w is 1). On a
// symmetric configuration the common shift's minimum is at u = 0 exactly (with F(u) = |r(sigma + u)
// - r(L - sigma + u)|^2, F_u(0) = 2 d.(r'(s) - r'(L - s)) = 2 d.(I + Q) r' = 4 (a.r') d.a = 0), so
// D = |d| = 2 rho: E_pair is the case's energy on symmetric configurations and the solved
// equilibrium is its critical point. The closest point is L - s only where rho' = 0
// (d.r'(L - s) = -(rho^2)'), so D_c < 2 rho where the distance to the axis varies: it is not an
// extension of the case's energy, and the solved equilibrium is not its critical point (by
// ~ w phi' rho rho'^2). The common shift is the one used. Its second variation for
// z = dr, antisymmetric (z(L - s) = -Q z(s), z'(L - s) = Q z'(s)), at u(e) minimising F(u, e):
//   d2(min_u F)/de2 = F_ee - F_ue^2 / F_uu                           (F_u = 0 at e = 0)
//   F_ee = 2 |z(s) - z(L - s)|^2 = 8 (a.z)^2
//   F_ue = 2 [(r'(s) - r'(L - s)).(z(s) - z(L - s)) + d.(z'(s) - z'(L - s))]
//        = 2 [2 alpha a.2 a (a.z) + 2 rho_vec.2 z'] = 8 (alpha a.z + rho_vec.z')
//   F_uu = 2 |r'(s) - r'(L - s)|^2 + 2 d.(r''(s) - r''(L - s)) = 8 (alpha^2 + rho_vec.r'') = 8 kappa
// with alpha = a.r', rho_vec = d / 2 the radial vector, r'(L - s) = -Q r', r''(L - s) = Q r''.
// (Symmetric z keep the configuration symmetric, u = 0 and D = |d|: F_ue = 0, that half is
// unchanged, and the halves stay uncoupled.) D' = d.dd / D = 0 (dd along a), so D'' = d2F / (2 D)
// and the pair's second variation is
//   int_0^L w phi' D'' / 2 = 2 int_0^l w phi' / rho [(a.z)^2 - (alpha a.z + rho_vec.z')^2 / kappa],
// i.e. on the half rod z.H z (H above, the partners held) plus the sliding term
//   k (alpha a.z + rho_vec.z')^2,   k = -w phi' / (rho kappa) = (f.d_r) / (rho^2 kappa) > 0,
// a multiplier times (a contact-point shift)^2 / (the distance's curvature along the shift), as
// f (nu.dr')^2 / (2 g'') for a point contact (stability.cpp). It does not cancel H: on a uniform ply
// (a helix of pitch angle theta about a, rho' = 0) with z = a, alpha = cos theta, rho_vec.r'' =
// -sin^2 theta, kappa = cos 2 theta, and the sum is w phi' / rho (1 - cos^2 theta / cos 2 theta)
// = -w phi' / rho sin^2 theta / cos 2 theta > 0: sliding the strands along the axis turns the
// double helix's phase and brings them closer, which costs energy. The closest point's second
// variation (F_tt = 2 (1 - d.r''(t)) = 2 (1 + 2 rho_vec.r'')) has 1 + 2 rho_vec.r'' in place of kappa:
// they differ by (rho^2)'' / 2, zero on a uniform ply. z' = dr' = dd3 = dpsi x d3 is a rotation, so
// the term couples positions and rotations: it is given to the fields as the field's tangent
// stiffness k v v^T on (dr, dd3), v = (alpha a, rho_vec) (rod_model.hpp). It vanishes on rigid
// motions (F_ue = 0 for z = omega x r, and for translations), so the isotropic rod's turn about the
// clamps' axis stays a zero mode. kappa > 0 is needed (u = 0 a minimum, not a saddle): where the
// barrier acts with kappa <= 0 the index is not reported (sliding_reason). Tested against finite
// differences of E_pair with D found by minimisation on a solved ply (stability_symmetric_test).
// One-body fields invariant under Q (gravity along a, none in the cases) keep their Hessian on both
// halves: (Q dr).Hess V(Q r) (Q dr) = dr.Hess V(r) dr.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/equations/rod_equations.hpp"
#include "kirchhoff/shooting/boundary_conditions.hpp"

namespace kirchhoff {

// The conditions of the antisymmetric half at a half-turn end: position and rotation held along
// the axis, the force and moment across it dead (their values do not enter the index: only the
// directions do).
EndCondition antisymmetric_half_turn_end(const Vec3& axis);

// The rod's equations with the half-turn self-contact's second variation replaced by the
// antisymmetric one with sliding partners (above: H as force gradient, the sliding term as tangent
// stiffness); the equilibrium's force is unchanged. Null when the rod has no
// half-turn self-contact (its own equations then serve both halves).
std::shared_ptr<const RodEquations> antisymmetric_equations(const RodEquations& eq);

// kappa = alpha^2 + d.r'' (alpha = a.d3, d the radial vector): the curvature of the strands'
// squared distance along their relative shift, / 8 (above). The sliding term needs kappa > 0.
double shift_curvature(const Vec3& axis, const Vec3& radial, const Vec3& d3, const Vec3& d3_prime);

// Why the sliding partners are not defined at the equilibrium's point q of the rod with equations
// `eq` (its own, with the half-turn self-contact): the barrier acts there (its stiffness as below
// above zero_tolerance) and kappa <= 0, or the rod is planar. Empty otherwise.
std::string sliding_reason(const RodEquations& eq, const RodPoint& q, double zero_tolerance);

// The largest stiffness of the antisymmetric barrier term, |w phi'| / rho (above), over the
// equilibrium's samples, in units of B / L^4 (B the first bending stiffness at s = 0, L the half
// rod's length): the term changes the second variation by at most this, relative to the elastic
// energy of a perturbation of unit size. Zero without a half-turn self-contact.
double antisymmetric_barrier_stiffness(const RodEquations& eq, const std::vector<RodPoint>& samples);

}  // namespace kirchhoff

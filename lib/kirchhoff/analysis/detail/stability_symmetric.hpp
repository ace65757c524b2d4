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
//                  pair's second variation is int_0^l w phi' / rho (a.dr)^2, i.e. the half
//                  problem's field Hessian is H = w phi' / rho a a^T (phi' < 0: sliding the strands
//                  past each other along the axis lengthens d at second order and lowers the
//                  repulsion). As a force gradient df/dr = -H = (f.d_r) / rho^2 a a^T, with f the
//                  barrier's force and d_r the radial vector (f = -w phi' d_r / rho).
// Where the barrier acts this is the second variation of the partner-pair energy above, but not
// of the whole rod's self-contact: the case defines its energy on symmetric configurations only,
// and pairing s with L - s for ever is one extension of it, not the physical one. Antisymmetric
// perturbations slide the strands past each other; the pair of closest points then moves along
// both strands (as a point contact slides along its obstacle, stability.hpp), and a contact
// between strands lying along each other does not open, whereas the fixed partners separate and
// the term above lowers the energy by ~ contact pressure / R x (a.dr)^2. Along plectoneme.toml's
// branch it made every equilibrium past the end loop's closing unstable in one antisymmetric
// direction (and the crossings non-monotone at some), against what the rod literature finds for
// the ply under end-rotation control. So where the barrier acts the whole rod's index is not
// reported (the symmetric half's is); the field above is what the antisymmetric half uses where
// it does not act, to round-off (tested against finite differences of the pair energy).
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

// The rod's equations with the half-turn self-contact's force gradient replaced by the
// antisymmetric one (above); the equilibrium's force is unchanged. Null when the rod has no
// half-turn self-contact (its own equations then serve both halves).
std::shared_ptr<const RodEquations> antisymmetric_equations(const RodEquations& eq);

// The largest stiffness of the antisymmetric barrier term, |w phi'| / rho (above), over the
// equilibrium's samples, in units of B / L^4 (B the first bending stiffness at s = 0, L the half
// rod's length): the term changes the second variation by at most this, relative to the elastic
// energy of a perturbation of unit size. Zero without a half-turn self-contact.
double antisymmetric_barrier_stiffness(const RodEquations& eq, const std::vector<RodPoint>& samples);

}  // namespace kirchhoff

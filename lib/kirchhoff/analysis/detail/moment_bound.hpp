// The largest internal moment along an equilibrium, from its start alone, where the Hamiltonian is
// a first integral: what the stability index's scales need (the Jacobi fields' rate, stability.cpp)
// without sampling the rod.
#pragma once

#include <optional>

#include "kirchhoff/equations/rod_equations.hpp"

namespace kirchhoff::detail {

// For a uniform, inextensible, unshearable rod without natural curvature or strain, field or
// contact, H = m.B^-1 m / 2 + n.d3 is conserved (eq. 53) and n is constant, so m.B^-1 m =
// 2 (H - n.d3) <= 2 (H + |n|) all along; with m3 = m.d3 conserved too where B1 = B2 (isotropic).
// The bound on |m| that follows is reached where d3 turns against n (the pinned Elastica's
// mid-span). A symmetry-unfolding couple mu (the axial phase condition's unknown, ~1e-9 along a
// branch) changes H and m3 by at most O(mu L |m|): added to the bound, which then still holds.
// `start` is the equilibrium at s = 0; `has_contacts` whether any contact acts on it. Empty where
// the rod is not of that kind.
std::optional<double> moment_bound(const RodEquations& equations, const RodPoint& start, bool has_contacts);

}  // namespace kirchhoff::detail

// The minimum of a monitor that has a kink there: the smallest singular value of the bordered
// matrix along a branch near a branch point of even multiplicity, sigma(h) ~ c |h - h*| (two
// singular values pass through zero together and neither changes the determinant's sign).
//
// Brent's parabolic steps model a smooth minimum; at a kink they are rejected and it falls back to
// golden sections, about 58 evaluations for 40 bits, each one a corrector solve. Here each step
// fits a V, f = f0 + c |h - h*|, through the bracket's three points (two unknown slopes' worth of
// data fix c, h* and f0 once the side of h* is known: the side whose fit lands inside its own
// interval). On an exact V one fit lands on h*; with curvature the error falls quadratically.
// A fit that does not shrink the bracket to 0.6 of its width within two steps is replaced by a
// golden section of the larger part, so convergence is never slower than golden sections, and a
// smooth minimum is still found (more slowly than by Brent).
#pragma once

#include <functional>

namespace kirchhoff::detail {

struct MinimumSample {
  double h = 0.0;
  double value = 0.0;
};

struct KinkedMinimum {
  MinimumSample best;     // the lowest sample found
  int evaluations = 0;    // calls of f
  bool bracketed = true;  // false: the start was no bracket (f(m) above f(a) or f(b)); nothing done
};

// The minimum of f on [a.h, b.h] from a bracket a.h < m.h < b.h with m.value <= a.value, b.value:
// stops when the bracket is narrower than `tolerance`, after `max_evaluations` calls, or when f
// reaches 0 (a monitor that is a norm is then at its minimum). f may return +inf where it cannot
// be evaluated (treated as high).
KinkedMinimum minimise_kinked(const std::function<double(double)>& f, MinimumSample a, MinimumSample m,
                              MinimumSample b, double tolerance, int max_evaluations);

}  // namespace kirchhoff::detail

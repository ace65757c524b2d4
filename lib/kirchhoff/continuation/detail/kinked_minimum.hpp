// The minimum of a monitor that has a kink there: the smallest singular value of the bordered
// matrix along a branch near a branch point of even multiplicity, sigma(h) ~ c |h - h*| (two
// singular values pass through zero together and neither changes the determinant's sign).
//
// Brent's parabolic steps model a smooth minimum; at a kink they are rejected and it falls back to
// golden sections, about 58 evaluations for 40 bits, each one a corrector solve. Here each step
// intersects a falling line (left of the kink) with a rising one (right of it), each through the
// nearest samples on its side, for both sides the kink may lie on, and keeps the one that lands in
// its own interval (the lower where both do). On an exact V one fit lands on h*; with curvature
// the lines come from ever nearer samples. A fit that lands on the lowest sample is replaced by a
// probe mirrored across it, so that both sides get near samples. A step that does not bring the
// bracket to 0.6 of its width within two steps is a golden section of the larger part instead,
// so convergence is never slower than golden sections, and a smooth minimum is still found (more
// slowly than by Brent).
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

// The link of a twisted rod whose ends are clamped on one axis, and the check that a solution
// has the end rotation its case imposes, whole turns included.
//
// An end frame imposed by a rotation angle fixes that angle only modulo 2 pi: from a guess, Newton
// may return the rod turned by 2 pi less (at `turns = 2` the plectoneme case gave the untwisted
// rod after 0 iterations). What tells them apart is topological: with both ends on the e3 axis,
// tangent to it, the rod closed by the axis beyond its ends has a link Lk = Tw + Wr
// (Calugareanu-White) equal to the relative rotation of its end frames about e3 over 2 pi, as a
// real number (e.g. Fuller 1971; van der Heijden et al. 2003 use this closure for clamped rods).
// Tw = (1/2 pi) int u3 ds for an inextensible, unshearable rod; Wr is the Gauss double integral
// over the closed curve, the two axis rays done in closed form. A solution whose Lk differs from
// the imposed rotation by a whole number of turns has the right end frames and the wrong rod.
#pragma once

#include <string>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct LinkCheck {
  bool applies = false;    // false: why_not says why the check does not apply to this solution
  std::string why_not;
  double imposed = 0.0;    // the relative end rotation about e3 the case imposes, in turns
  double link = 0.0;       // Tw + Wr of the solution, in turns
  double twist = 0.0, writhe = 0.0;
  int samples = 0;         // points along the whole rod at which Wr converged
};

// Computes the link of the solution x of `problem` where the check applies: a spatial,
// inextensible, unshearable rod whose start frame is imposed by a rotation about e3 and whose
// end is either imposed the same way or is a half-turn symmetry point (the whole rod is the half
// and its image, as in cases/plectoneme.toml), with both ends of the whole rod on the e3 axis and
// tangent to it in the same sense, the end above the start along it.
LinkCheck check_link(const ShootingProblem& problem, const Eigen::VectorXd& x);

// "" when the check does not apply or the link agrees with the imposed rotation to within a
// quarter turn (the Gauss integral is resolved far better than that; what it must catch are
// whole turns), else the reason.
std::string link_failure(const ShootingProblem& problem, const Eigen::VectorXd& x);

}  // namespace kirchhoff

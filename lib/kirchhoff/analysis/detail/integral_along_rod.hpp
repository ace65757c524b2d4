// The integral of a quantity read off the rod's points, along the whole rod: composite Simpson on
// one integration pass per stretch, the stretches between the points where the integrand may jump
// or kink taken on their own (a property's jumps, RodModel::jumps; the contacts, where the shear
// force jumps), each sampled just inside its ends so that it is read from its own side. Simpson
// across a jump errs by its spacing times the jump (1e-4 of a stepped column's energy), across a
// kink by its spacing squared.
#pragma once

#include <Eigen/Dense>
#include <functional>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// intervals: over the whole rod (each stretch gets its share, even, at least 2).
double integral_along_rod(const ShootingProblem& problem, const Eigen::VectorXd& x, const RodModel& model,
                          int intervals, const std::function<double(const RodPoint&)>& f);

}  // namespace kirchhoff

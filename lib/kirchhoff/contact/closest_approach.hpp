// Where a solved rod comes closest to its obstacles: the smallest gap over equally spaced samples,
// then refined between the neighbouring samples by Brent's method. On a curved obstacle the
// sampled minimum alone is off by ~ spacing^2 / (2 radius) (5e-6 for a disc of radius 0.05 seen
// at 101 samples), which would place first contacts that far inside it.
#pragma once

#include <vector>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct ClosestApproach {
  int obstacle = -1;      // -1 when there are no obstacles
  double s = 0.0;
  double gap = INFINITY;
  double spacing = 0.0;   // between the samples it was found among
};

// Over `samples` equally spaced points; the unrefined sampled minimum.
ClosestApproach sampled_closest_approach(const ShootingProblem& problem, const Eigen::VectorXd& x, int samples);
// The same refined between the samples next to it.
ClosestApproach closest_approach(const ShootingProblem& problem, const Eigen::VectorXd& x, int samples);

}  // namespace kirchhoff

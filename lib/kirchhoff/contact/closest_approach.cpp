#include "kirchhoff/contact/closest_approach.hpp"

#include <algorithm>
#include <boost/math/tools/minima.hpp>

namespace kirchhoff {

ClosestApproach sampled_closest_approach(const ShootingProblem& problem, const Eigen::VectorXd& x, int samples) {
  ClosestApproach out;
  const Parameters p = problem.parameters_at(x);
  const auto obstacles = problem.obstacles(p);
  const double L = problem.length(p);
  out.spacing = L / (samples - 1);
  std::vector<double> s(samples);
  for (int i = 0; i < samples; ++i) s[i] = L * i / (samples - 1);
  for (const auto& point : problem.sample(x, s))
    for (size_t o = 0; o < obstacles.size(); ++o) {
      const double gap = obstacles[o].gap(point.r);
      if (gap < out.gap) {
        out.gap = gap;
        out.obstacle = static_cast<int>(o);
        out.s = point.s;
      }
    }
  return out;
}

ClosestApproach closest_approach(const ShootingProblem& problem, const Eigen::VectorXd& x, int samples) {
  ClosestApproach out = sampled_closest_approach(problem, x, samples);
  if (out.obstacle < 0) return out;
  const Parameters p = problem.parameters_at(x);
  const Obstacle obstacle = problem.obstacles(p)[out.obstacle];
  const double L = problem.length(p);
  auto gap_at = [&](double at) { return obstacle.gap(problem.sample(x, {at}).front().r); };
  const auto [s, gap] = boost::math::tools::brent_find_minima(gap_at, std::max(0.0, out.s - out.spacing),
                                                              std::min(L, out.s + out.spacing), 40);
  if (gap < out.gap) {
    out.s = s;
    out.gap = gap;
  }
  return out;
}

}  // namespace kirchhoff

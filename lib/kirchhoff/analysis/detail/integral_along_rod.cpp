#include "kirchhoff/analysis/detail/integral_along_rod.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace kirchhoff {
namespace {

// Composite Simpson over [a, b] with an even number of intervals, sampled by one integration.
double simpson(const ShootingProblem& problem, const Eigen::VectorXd& x, double a, double b, int intervals,
               const std::function<double(const RodPoint&)>& f) {
  std::vector<double> s(intervals + 1);
  for (int i = 0; i <= intervals; ++i) s[i] = a + (b - a) * i / intervals;
  s.back() = b;
  const auto points = problem.sample(x, s);
  double sum = 0.0;
  for (int i = 0; i <= intervals; ++i) sum += (i == 0 || i == intervals ? 1.0 : (i % 2 ? 4.0 : 2.0)) * f(points[i]);
  return sum * (b - a) / intervals / 3.0;
}

// Where the integrand may jump or kink: the rod's ends, its properties' jumps, the contacts.
std::vector<double> breakpoints(const ShootingProblem& problem, const Eigen::VectorXd& x, const RodModel& model) {
  const double L = model.length;
  std::vector<double> b{0.0, L};
  for (const ProfileJump& j : model.jumps()) b.push_back(j.before);
  for (const auto& c : problem.contacts_at(x)) {
    b.push_back(std::clamp(c.s, 0.0, L));
    if (c.extended) b.push_back(std::clamp(c.s_end, 0.0, L));
  }
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end()), b.end());
  return b;
}

}  // namespace

double integral_along_rod(const ShootingProblem& problem, const Eigen::VectorXd& x, const RodModel& model,
                          int intervals, const std::function<double(const RodPoint&)>& f) {
  const double L = model.length;
  const std::vector<double> breaks = breakpoints(problem, x, model);
  const double inset = 1e-12 * L;
  double total = 0.0;
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double a = breaks[i], b = breaks[i + 1];
    if (b - a <= 2 * inset) continue;
    const int n = std::max(2, 2 * static_cast<int>(std::ceil(0.5 * intervals * (b - a) / L)));
    total += simpson(problem, x, i == 0 ? a : a + inset, i + 2 == breaks.size() ? b : b - inset, n, f);
  }
  return total;
}

}  // namespace kirchhoff

// Hard contact of wall.toml (Fig. 12): shooting with complementarity vs Ipopt on the discretised
// energy at N = 200 and 1000 segments, timed in the same process, with each one's error in P
// against the elliptic-function solution. Goal (issue): shooting >= 100x faster than Ipopt at
// N = 1000 with >= 1000x smaller error in P. Prints ratios; asserts nothing.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "kirchhoff/analytic.hpp"
#include "kirchhoff/case_file.hpp"
#include "kirchhoff/contact.hpp"
#include "kirchhoff/discrete_elastica.hpp"
#include "kirchhoff/solution.hpp"

namespace {

using Clock = std::chrono::steady_clock;

template <class F>
double median_seconds(int repetitions, F&& f) {
  std::vector<double> t;
  for (int i = 0; i < repetitions; ++i) {
    const auto start = Clock::now();
    f();
    t.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

int main() {
  using namespace kirchhoff;
  const auto exact = analytic::wall_contact_elastica(1.0, 1.0, 0.026, 0.1);
  const Case c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/wall.toml");
  double P_shooting = 0.0;
  const double t_shooting = median_seconds(21, [&] {
    const ContactSolveResult r = solve_with_contacts(c.definition, c.start_guess);
    const ShootingProblem problem(r.definition);
    P_shooting = -problem.sample(r.result.x, {0.0}).front().n.x();
  });
  const double e_shooting = std::abs(P_shooting / exact.P - 1.0);
  std::printf("wall.toml, Delta = 0.026, a = 0.1; elliptic P = %.12f\n\n", exact.P);
  std::printf("%-34s %12s %14s %12s %12s\n", "method", "median_ms", "rel_error_P", "time_ratio", "error_ratio");
  std::printf("%-34s %12.3f %14.2e %12s %12s\n", "shooting + active set (from free arch)", 1e3 * t_shooting,
              e_shooting, "1", "1");
  const std::vector<Obstacle> wall{Obstacle::plane(Vec3(0, 0.1, 0), Vec3(0, -1, 0), "wall")};
  for (int N : {200, 1000}) {
    DiscreteElasticaResult d;
    const double t = median_seconds(N <= 200 ? 5 : 1, [&] { d = solve_discrete_clamped_elastica(1.0, 1.0, 0.026, wall, N); });
    const double e = std::abs(d.P / exact.P - 1.0);
    std::printf("%-34s %12.3f %14.2e %12.0f %12.2e   %s\n", ("Ipopt, N = " + std::to_string(N)).c_str(), 1e3 * t, e,
                t / t_shooting, e / std::max(e_shooting, 1e-16), d.status.c_str());
  }
  std::printf("\nGoal: Ipopt(N = 1000) / shooting >= 100 in time and >= 1000 in error.\n");
  return 0;
}

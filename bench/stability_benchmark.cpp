// Cost of the stability index (stability.hpp) against one residual-and-Jacobian evaluation of the
// same shooting problem at the same solution, in the same process: the goal is an index
// for at most two Newton iterations' worth. Prints, per equilibrium, the median CPU time of the
// thread for each over `--runs N` repetitions (default 20; CPU time, not wall time, because the
// machines are shared and a busy neighbour stretches wall time), their ratio, and
// machine-independent counts: right-hand-side evaluations of each, and the conjugate points found.
// `--only TEXT` keeps the equilibria whose label contains TEXT. Nothing here asserts on timings.
//
//   stability_benchmark [--runs N] [--only TEXT]
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/jobs/case_file.hpp"

namespace {

using kirchhoff::ParameterOverrides;

struct Scenario {
  const char* label;
  const char* file;
  ParameterOverrides overrides;
};

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

template <class F>
double median_seconds(int runs, F&& work) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const double start = thread_cpu_seconds();
    work();
    t.push_back(thread_cpu_seconds() - start);
  }
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return t[t.size() / 2];
}

void measure(const Scenario& sc, int runs) {
  using namespace kirchhoff;
  const Case c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/" + sc.file, sc.overrides);
  const ShootingProblem problem(c.definition);
  const ShootingResult solved = solve(problem, problem.initial_unknowns(c.start_guess));
  if (!solved.summary.converged()) {
    std::printf("%-44s not converged: %s\n", sc.label, solved.summary.brief_report().c_str());
    return;
  }
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  std::string failure;
  const long before = problem.rhs_evaluations();
  const double t_jacobian = median_seconds(runs, [&] { problem.evaluate(solved.x, &F, &J, &failure); });
  const long rhs_jacobian = (problem.rhs_evaluations() - before) / runs;
  StabilityReport report;
  const double t_index = median_seconds(runs, [&] { report = analyse_stability(problem, solved.x); });
  std::printf("%-44s %10.1f %10.1f %7.1f %9ld %9ld %6zu  %s\n", sc.label, 1e6 * t_jacobian, 1e6 * t_index,
              t_index / t_jacobian, rhs_jacobian, report.rhs_evaluations, report.conjugate_points.size(),
              describe(report).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 20;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (std::strcmp(argv[i], "--only") == 0 && i + 1 < argc) only = argv[++i];
  }
  const std::vector<Scenario> scenarios = {
      {"Fig. 3 Elastica, theta0 = 1 (simply_supported)", "simply_supported.toml", {{"theta0", 1.0}}},
      {"Euler column, mode 1, P = 20", "euler_column.toml", {{"P", 20.0}, {"theta_guess", 2.0}}},
      {"Euler column, straight, P = 50", "euler_column.toml", {{"P", 50.0}, {"theta_guess", 0.0}}},
      {"Euler column, straight, P = 200", "euler_column.toml", {{"P", 200.0}, {"theta_guess", 0.0}}},
      {"clamped-clamped, S mode", "clamped_clamped.toml", {{"s_mode", 1.0}}},
      {"twisted rod, straight, phi = 12", "twisted_clamped.toml", {{"phi", 12.0}}},
      {"heavy cantilever (gravity)", "heavy_cantilever.toml", {}},
      {"wall, point contact (full frame)", "wall.toml", {}},
      {"soft wall (barrier field, full frame)", "soft_wall.toml", {}},
  };
  std::printf("median CPU time of %d runs; F+J = one residual and variational Jacobian at the solution\n", runs);
  std::printf("%-44s %10s %10s %7s %9s %9s %6s  %s\n", "equilibrium", "F+J [us]", "index [us]", "ratio",
              "rhs F+J", "rhs index", "conj.", "result");
  for (const Scenario& s : scenarios)
    if (only.empty() || std::string(s.label).find(only) != std::string::npos) measure(s, runs);
  return 0;
}

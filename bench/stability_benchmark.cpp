// Cost of the stability index (stability.hpp) against one residual-and-Jacobian evaluation of the
// same shooting problem at the same solution, in the same process: the goal is an index
// for at most two Newton iterations' worth. Prints, per equilibrium, the median CPU time of the
// thread for each over `--runs N` repetitions (default 20; CPU time, not wall time, because the
// machines are shared and a busy neighbour stretches wall time), their ratio, and
// machine-independent counts: right-hand-side evaluations of each, and the conjugate points found.
// `--only TEXT` keeps the equilibria whose label contains TEXT.
//
// `--branch euler|twist` measures instead what the index adds to a continuation, the issue's
// second goal (at most +30 %): the branch of docs/performance.md's table (continue_case, as the
// CLI runs it) with the index at every point and without it, alternating, `--runs N` times each
// (default 5), median CPU time of the process; and, in the same process, the index of every
// point of the branch alone (analyse_stability with the continuation's options: the fields at
// its stability_field_tolerance, then at the state's tolerance), summed, against the branch
// without it - the share that does not depend on how two runs' times happened to vary.
// Nothing here asserts on timings.
//
//   stability_benchmark [--runs N] [--only TEXT]
//   stability_benchmark --branch euler|twist [--runs N]
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/jobs/case_continue.hpp"
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

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// A branch of docs/performance.md's stability table, as `kirchhoff continue` runs it.
struct Branch {
  const char* file;
  kirchhoff::ParameterOverrides overrides;
  kirchhoff::ContinueRequest request;
};

Branch branch_named(const std::string& name) {
  using namespace kirchhoff;
  Branch b;
  b.request.max_step = 1.0;
  b.request.switch_at_bp = 1;
  if (name == "euler") {
    b.file = "euler_column.toml";
    b.overrides = {{"P", 1.0}, {"theta_guess", 0.0}};
    b.request.parameter = "P";
    b.request.target = 12.0;
    b.request.events = {{"theta0", 3.0, true, ""}};
  } else if (name == "twist") {
    b.file = "twisted_clamped.toml";
    b.overrides = {{"phi", 6.0}, {"tension", 0.0}};
    b.request.parameter = "phi";
    b.request.target = 15.0;
    b.request.events = {{"end_to_end", 0.5, true, ""}};
  } else {
    throw std::invalid_argument("--branch: euler or twist, not " + name);
  }
  return b;
}

// A copy of each point's problem, at the point's parameter, and its unknowns.
struct KeepPoints : kirchhoff::ContinueSink {
  std::string parameter;
  std::vector<std::pair<kirchhoff::ShootingProblem, Eigen::VectorXd>> points;
  void begin(const std::string& name, const std::vector<std::string>&, int) override { parameter = name; }
  void point(const kirchhoff::RunPoint& p) override {
    if (!p.problem) throw std::logic_error("a contact run: not one of this benchmark's branches");
    points.emplace_back(*p.problem, p.point->x);
    points.back().first.set_parameter(parameter, p.point->parameter);
  }
};

int measure_branch(const std::string& name, int runs) {
  using namespace kirchhoff;
  const Branch b = branch_named(name);
  const Case c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/" + b.file, b.overrides);
  auto run = [&](bool stability, KeepPoints* keep) {
    ContinueRequest r = b.request;
    r.compute_stability = stability;
    std::vector<ContinueSink*> sinks;
    if (keep) sinks.push_back(keep);
    const double t0 = process_cpu_seconds();
    const ContinueRunResult result = continue_case(c, r, sinks);
    if (!result.ok) throw std::runtime_error("the branch did not end normally: " + result.message);
    return std::make_pair(process_cpu_seconds() - t0, result.points);
  };
  std::vector<double> with, without;
  int points = 0;
  for (int i = 0; i < runs; ++i) {
    with.push_back(run(true, nullptr).first);
    const auto w = run(false, nullptr);
    without.push_back(w.first);
    points = w.second;
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  KeepPoints keep;
  const double branch = run(false, &keep).first;
  std::printf("branch %s: %d points; CPU time, median of %d alternating runs: %.3f s with the index, %.3f s "
              "without (+%.0f %%)\n",
              name.c_str(), points, runs, median(with), median(without), 100 * (median(with) / median(without) - 1));
  // The index of each point alone: with the continuation's options (point_record.cpp), with the
  // estimate's step control where the phase speed's bound would serve (the baseline of
  // StabilityOptions::bounded_observations), and with the fields at the state's tolerance.
  const double points_kept = static_cast<double>(std::max<size_t>(1, keep.points.size()));
  struct Variant {
    double field_tolerance;
    bool bounded;
    const char* label;
  };
  const Variant variants[] = {
      {RodRecordOptions{}.stability_field_tolerance, true, "fields at 1e-8 (as continuation)"},
      {RodRecordOptions{}.stability_field_tolerance, false, "fields at 1e-8, no phase-speed bound"},
      {0.0, true, "fields at the state's tolerance"}};
  for (const Variant& v : variants) {
    StabilityOptions options;
    options.extended_contacts = false;
    options.field_tolerance = v.field_tolerance;
    options.bounded_observations = v.bounded;
    long rhs = 0, flows = 0;
    const double t0 = process_cpu_seconds();
    for (const auto& [problem, x] : keep.points) {
      const StabilityReport report = analyse_stability(problem, x, options);
      rhs += report.rhs_evaluations;
      flows += report.field_flows;
    }
    const double index = process_cpu_seconds() - t0;
    std::printf("  the index of each of its %zu points alone, %s: %.3f s (%.0f us, %.0f rhs and %.1f field "
                "flows per point) against %.3f s for the branch without it (+%.0f %%)\n",
                keep.points.size(), v.label, index, 1e6 * index / points_kept, static_cast<double>(rhs) / points_kept,
                static_cast<double>(flows) / points_kept, branch, 100 * index / branch);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 0;
  std::string only, branch;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--runs") == 0 && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (std::strcmp(argv[i], "--only") == 0 && i + 1 < argc) only = argv[++i];
    else if (std::strcmp(argv[i], "--branch") == 0 && i + 1 < argc) branch = argv[++i];
  }
  if (!branch.empty()) return measure_branch(branch, runs > 0 ? runs : 5);
  if (runs == 0) runs = 20;
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

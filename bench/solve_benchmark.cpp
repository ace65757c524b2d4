// Cost of one converged shooting solve (Newton to max|F| <= 1e-10, the default) on the two
// reference problems of the performance goals:
//   (a) the pinned planar Elastica, cases/simply_supported.toml, theta0 = 1 and 2.8, unknown P;
//   (b) the clamped twisted 3D rod, cases/twisted_clamped.toml, straight at phi = 6 and buckled
//       at phi = 11.58 (guess m_lateral = -1.7, n_lateral = 3.4, axial phase condition).
// Each is solved from the case's own guess and from a converged solution perturbed by ~1e-2
// (relative, with a unit floor), which is what a continuation step sees. Variants: single vs
// multiple shooting (4 segments, Elastica) and the Newton steps' matrices: variational with the
// variational equations at NewtonOptions::step_matrix_tolerance (the default), variational
// exact (step_matrix_tolerance = 0), finite-difference, and the default without Newton's coarse
// phase (coarse_tolerance = 0: every evaluation to the integrator's own tolerance).
//
// Two modes:
//   solve_benchmark [--benchmark_...]    Google Benchmark; counters per solve: rhs_evals
//                                        (ShootingProblem::rhs_evaluations() increase),
//                                        newton_its, F_evals (residual/Jacobian evaluations),
//                                        and the worst final residual, failures and fallbacks.
//   solve_benchmark --summary [--runs-planar N] [--runs-3d N]
//                                        N timed solves per scenario (default 200 planar, 50 3D),
//                                        median CPU us/solve (the thread's CPU time, which other
//                                        processes on shared cores do not inflate; the wall
//                                        time's minimum beside it) against the goals of issue 24
//                                        (planar <= 100 us, 3D <= 1 ms on one core),
//                                        variational/FD ratios and a breakdown of one Jacobian
//                                        evaluation at the solution.
// rhs_evals counts right-hand-side calls of both kinds: plain ones (residuals, parameter
// columns, finite differences) and the far costlier dual-number ones that carry the variational
// equations; the --summary breakdown separates them. Nothing here asserts on timings.
// (Google Benchmark's "Library was built as DEBUG" warning is about Debian's libbenchmark
// build, not this code, which is built with the project's build type.)
#include <benchmark/benchmark.h>

#include "allocation_count.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <time.h>

#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/shooting/detail/jacobian_lu.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace {

using namespace kirchhoff;
using Clock = std::chrono::steady_clock;

// CPU time of the calling thread in microseconds.
double thread_cpu_us() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e6 * static_cast<double>(t.tv_sec) + 1e-3 * static_cast<double>(t.tv_nsec);
}

constexpr double kPlanarGoalUs = 100.0;
constexpr double kSpatialGoalUs = 1000.0;
constexpr double kPerturbation = 1e-2;

enum class Guess { Case, Perturbed };
enum class Jacobian { Variational, ExactVariational, FiniteDifference, VariationalNoCoarse };

const char* jacobian_name(Jacobian j) {
  switch (j) {
    case Jacobian::Variational: return "variational";
    case Jacobian::ExactVariational: return "exact_variational";
    case Jacobian::FiniteDifference: return "fd_jacobian";
    case Jacobian::VariationalNoCoarse: return "variational_no_coarse";
  }
  return "?";
}

struct CaseSpec {
  std::string label;
  std::string file;
  ParameterOverrides overrides;
  std::string phase_condition;
  bool planar;
};

const std::vector<CaseSpec>& case_specs() {
  static const std::vector<CaseSpec> specs = {
      {"elastica_theta0=1", "simply_supported.toml", {{"theta0", 1.0}}, "", true},
      {"elastica_theta0=2.8", "simply_supported.toml", {{"theta0", 2.8}}, "", true},
      {"twisted_straight_phi=6", "twisted_clamped.toml", {{"phi", 6.0}}, "", false},
      {"twisted_buckled_phi=11.58", "twisted_clamped.toml",
       {{"phi", 11.58}, {"m_lateral", -1.7}, {"n_lateral", 3.4}}, "axial", false},
  };
  return specs;
}

struct Scenario {
  const CaseSpec* spec;
  int segments;
  Jacobian jacobian;
  Guess guess;

  std::string setup_key() const {
    return spec->label + "/" + (segments == 1 ? "single" : "multiple" + std::to_string(segments)) + "/" +
           jacobian_name(jacobian);
  }
  std::string name() const {
    return setup_key() + "/" + (guess == Guess::Case ? "case_guess" : "perturbed_guess");
  }
  double goal_us() const { return spec->planar ? kPlanarGoalUs : kSpatialGoalUs; }
};

std::vector<Scenario> scenarios() {
  std::vector<Scenario> out;
  for (const CaseSpec& spec : case_specs())
    for (Guess guess : {Guess::Case, Guess::Perturbed}) {
      out.push_back({&spec, 1, Jacobian::Variational, guess});
      out.push_back({&spec, 1, Jacobian::ExactVariational, guess});
      out.push_back({&spec, 1, Jacobian::FiniteDifference, guess});
      out.push_back({&spec, 1, Jacobian::VariationalNoCoarse, guess});
      if (spec.planar) out.push_back({&spec, 4, Jacobian::Variational, guess});
    }
  return out;
}

// A problem built once per (case, segments, Jacobian) with its two starting points.
struct Prepared {
  Case c;
  std::unique_ptr<ShootingProblem> problem;
  Eigen::VectorXd case_guess, solution, perturbed;
  std::string error;  // set when the setup failed; the scenario is then skipped
};

// x* + 1e-2 * sign_i * max(|x*_i|, 1) with a fixed sign pattern: a ~1e-2 relative move of every
// unknown (absolute 1e-2 for the ones near zero, e.g. lateral forces of the straight rod).
Eigen::VectorXd perturb(const Eigen::VectorXd& x) {
  Eigen::VectorXd out = x;
  unsigned state = 12345u;
  for (int i = 0; i < x.size(); ++i) {
    state = state * 1103515245u + 12345u;
    const double sign = (state >> 16) & 1u ? 1.0 : -1.0;
    out[i] += kPerturbation * sign * std::max(std::abs(x[i]), 1.0);
  }
  return out;
}

Prepared& prepared(const Scenario& sc) {
  static std::map<std::string, std::unique_ptr<Prepared>> cache;
  auto& slot = cache[sc.setup_key()];
  if (slot) return *slot;
  slot = std::make_unique<Prepared>();
  Prepared& p = *slot;
  try {
    p.c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/" + sc.spec->file, sc.spec->overrides,
                    sc.spec->phase_condition);
    ProblemDefinition d = p.c.definition;
    d.options.segments = sc.segments;
    d.options.newton.finite_difference_jacobian = sc.jacobian == Jacobian::FiniteDifference;
    if (sc.jacobian == Jacobian::ExactVariational) d.options.newton.step_matrix_tolerance = 0.0;
    if (sc.jacobian == Jacobian::VariationalNoCoarse) d.options.newton.coarse_tolerance = 0.0;
    p.problem = std::make_unique<ShootingProblem>(std::move(d));
    p.case_guess = p.problem->initial_unknowns(p.c.start_guess);
    const ShootingResult r = solve(*p.problem, p.case_guess);
    if (!r.summary.converged()) {
      p.error = "no converged solution from the case guess: " + r.summary.brief_report();
      return p;
    }
    p.solution = r.x;
    p.perturbed = perturb(r.x);
    // The perturbed start must come back to the same equilibrium (not jump to another branch).
    const ShootingResult back = solve(*p.problem, p.perturbed);
    if (!back.summary.converged() ||
        (back.x - p.solution).lpNorm<Eigen::Infinity>() > 1e-6 * (1.0 + p.solution.lpNorm<Eigen::Infinity>()))
      p.error = "the perturbed guess does not return to the solution: " + back.summary.brief_report();
  } catch (const std::exception& e) {
    p.error = std::string("setup failed: ") + e.what();
  }
  return p;
}

const Eigen::VectorXd& start_of(const Prepared& p, Guess g) {
  return g == Guess::Case ? p.case_guess : p.perturbed;
}

// ---------------------------------------------------------------------------------------------
// Google Benchmark mode

void bm_solve(benchmark::State& state, Scenario sc) {
  Prepared& p = prepared(sc);
  if (!p.error.empty()) {
    state.SkipWithError(p.error.c_str());
    return;
  }
  const ShootingProblem& problem = *p.problem;
  const Eigen::VectorXd& x0 = start_of(p, sc.guess);
  const long rhs_before = problem.rhs_evaluations();
  double iterations = 0, evaluations = 0, worst_residual = 0, failures = 0, fallbacks = 0;
  for (auto _ : state) {
    ShootingResult r = solve(problem, x0);
    benchmark::DoNotOptimize(r.x.data());
    iterations += r.summary.iterations;
    evaluations += static_cast<double>(r.summary.evaluations);
    worst_residual = std::max(worst_residual, r.summary.residual_norm);
    if (!r.summary.converged()) ++failures;
    if (r.summary.used_fallback_search) ++fallbacks;
  }
  using benchmark::Counter;
  const double rhs = static_cast<double>(problem.rhs_evaluations() - rhs_before);
  state.counters["rhs_evals"] = Counter(rhs, Counter::kAvgIterations);
  state.counters["newton_its"] = Counter(iterations, Counter::kAvgIterations);
  state.counters["F_evals"] = Counter(evaluations, Counter::kAvgIterations);
  state.counters["residual"] = Counter(worst_residual);
  state.counters["unknowns"] = Counter(problem.size());
  state.counters["failures"] = Counter(failures);
  state.counters["fallbacks"] = Counter(fallbacks);
}

void register_benchmarks() {
  for (const Scenario& sc : scenarios())
    benchmark::RegisterBenchmark(sc.name().c_str(), bm_solve, sc)->Unit(benchmark::kMicrosecond);
}

// ---------------------------------------------------------------------------------------------
// Summary mode

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Stats {
  bool ok = false;
  std::string error;
  double median_us = 0, min_us = 0, rhs = 0, iterations = 0, evaluations = 0, residual = 0;
  int failures = 0, fallbacks = 0, unknowns = 0;
};

Stats measure(const Scenario& sc, int runs) {
  Stats st;
  Prepared& p = prepared(sc);
  if (!p.error.empty()) {
    st.error = p.error;
    return st;
  }
  const ShootingProblem& problem = *p.problem;
  const Eigen::VectorXd& x0 = start_of(p, sc.guess);
  for (int i = 0; i < 3; ++i) benchmark::DoNotOptimize(solve(problem, x0).x.data());  // warm-up
  std::vector<double> us;
  us.reserve(runs);
  const long rhs_before = problem.rhs_evaluations();
  std::vector<double> wall;
  wall.reserve(runs);
  for (int i = 0; i < runs; ++i) {
    const double c0 = thread_cpu_us();
    const auto t0 = Clock::now();
    ShootingResult r = solve(problem, x0);
    const auto t1 = Clock::now();
    us.push_back(thread_cpu_us() - c0);
    benchmark::DoNotOptimize(r.x.data());
    wall.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    st.iterations += r.summary.iterations;
    st.evaluations += static_cast<double>(r.summary.evaluations);
    st.residual = std::max(st.residual, r.summary.residual_norm);
    if (!r.summary.converged()) ++st.failures;
    if (r.summary.used_fallback_search) ++st.fallbacks;
  }
  st.rhs = static_cast<double>(problem.rhs_evaluations() - rhs_before) / runs;
  st.iterations /= runs;
  st.evaluations /= runs;
  st.median_us = median(us);
  st.min_us = *std::min_element(wall.begin(), wall.end());
  st.unknowns = problem.size();
  st.ok = true;
  return st;
}

// Median time and RHS evaluations of `f` (one residual or Jacobian evaluation): the calling
// thread's CPU time, or with `wall` the wall time (for work spread over threads).
template <class F>
std::pair<double, double> time_call(const ShootingProblem& problem, int reps, F&& f, bool wall = false) {
  std::vector<double> us;
  f();
  const long rhs_before = problem.rhs_evaluations();
  for (int i = 0; i < reps; ++i) {
    const double c0 = thread_cpu_us();
    const auto t0 = Clock::now();
    f();
    us.push_back(wall ? std::chrono::duration<double, std::micro>(Clock::now() - t0).count() : thread_cpu_us() - c0);
  }
  return {median(us), static_cast<double>(problem.rhs_evaluations() - rhs_before) / reps};
}

// One residual, one variational Jacobian, one finite-difference Jacobian at the solution, and
// the integrator's work for a single pass over the rod with and without the variational
// equations (steps and RHS evaluations: RK78 costs 13 evaluations per attempted step).
void jacobian_breakdown(const CaseSpec& spec, int reps) {
  const Scenario sc{&spec, 1, Jacobian::Variational, Guess::Case};
  Prepared& p = prepared(sc);
  if (!p.error.empty()) {
    std::printf("  %-28s skipped: %s\n", spec.label.c_str(), p.error.c_str());
    return;
  }
  const ShootingProblem& problem = *p.problem;
  const Eigen::VectorXd& x = p.solution;
  Eigen::VectorXd F;
  Eigen::MatrixXd J, Jfd;
  std::string failure;
  const auto f_only = time_call(problem, reps, [&] { problem.evaluate(x, &F, nullptr, &failure); });
  const auto f_var = time_call(problem, reps, [&] { problem.evaluate(x, &F, &J, &failure); });
  const double step_tol = problem.definition().options.newton.step_matrix_tolerance;
  Eigen::MatrixXd J_step;
  const auto f_step = time_call(problem, reps, [&] { problem.evaluate_for_step(x, &F, &J_step, step_tol, &failure); });
  const double step_diff = (J_step - J).lpNorm<Eigen::Infinity>() / std::max(1.0, J.lpNorm<Eigen::Infinity>());
  const auto f_fd = time_call(problem, reps, [&] {
    problem.evaluate(x, &F, nullptr, &failure);
    finite_difference_jacobian(problem, x, problem.definition().options.newton.finite_difference_step, &Jfd);
  });
  const double jac_diff = (J - Jfd).lpNorm<Eigen::Infinity>() / std::max(1.0, J.lpNorm<Eigen::Infinity>());
  // Allocation calls of one evaluation at the solution (after the warm-up calls above).
  auto allocations_of = [](auto&& call) {
    const long before = bench::allocations();
    call();
    return bench::allocations() - before;
  };
  const long alloc_f = allocations_of([&] { problem.evaluate(x, &F, nullptr, &failure); });
  const long alloc_var = allocations_of([&] { problem.evaluate(x, &F, &J, &failure); });
  const long alloc_step = allocations_of([&] { problem.evaluate_for_step(x, &F, &J_step, step_tol, &failure); });

  const Parameters params = problem.parameters_at(x);
  const auto eq = problem.equations(params);
  const IntegratorOptions& io = problem.definition().options.integrator;
  const SegmentFlow plain = eq->flow(problem.start_state(x), 0.0, eq->model().length, false, io);
  const SegmentFlow sens = eq->flow(problem.start_state(x), 0.0, eq->model().length, true, io);
  const int n_params = problem.size() - problem.segments() * problem.state_size();
  // Unknown parameters the rod model depends on: their columns re-integrate F twice each (the
  // others only enter the closed-form boundary conditions), except the unfolding couple's, which
  // the flows carry (SegmentFlow::dy_dunfolding).
  int n_model_params = 0;
  for (const auto& name : problem.definition().unknown_parameters)
    n_model_params +=
        static_cast<int>(problem.definition().model_parameters.count(name) && !is_unfolding_parameter(name));

  std::printf("  %-28s unknowns %2d (state %2d + %d parameter)\n", spec.label.c_str(), problem.size(),
              problem.state_size(), n_params);
  std::printf("    one pass over the rod: state only %4ld steps %6ld rhs | with variational eqs %4ld steps %6ld rhs "
              "(on %d-component state)\n",
              plain.steps, plain.rhs_evaluations, sens.steps, sens.rhs_evaluations,
              problem.state_size() * (problem.state_size() + 1));
  std::printf("    residual F            %9.1f us %7.0f rhs\n", f_only.first, f_only.second);
  std::printf("    allocation calls      F %ld, F + J variational %ld, F + J step matrix %ld (malloc/calloc/realloc)\n",
              alloc_f, alloc_var, alloc_step);
  std::printf("    F + J variational     %9.1f us %7.0f rhs  (of which %d parameter column(s) by re-integrating "
              "F twice each: ~%.0f rhs, ~%.1f us)\n",
              f_var.first, f_var.second, n_model_params, 2.0 * n_model_params * f_only.second,
              2.0 * n_model_params * f_only.first);
  std::printf("    F + J step matrix     %9.1f us %7.0f rhs  (variational equations at %.0e%s), |J_step - J| %.1e, "
              "rcond(J) %.1e\n",
              f_step.first, f_step.second, step_tol,
              problem.has_step_matrices(step_tol) ? "" : ": not offered, the exact matrix", step_diff,
              JacobianLU(J).reciprocal_condition());
  // Unknown parameters the rod model depends on (the axial phase condition's "unfolding"):
  // every new value rebuilds the equations (the workspace keeps the last three builds, so a
  // Jacobian's plus and minus values and x itself are built once): timed here with a new value
  // at every call.
  const auto& model_params = problem.definition().model_parameters;
  for (const auto& name : problem.definition().unknown_parameters) {
    if (!model_params.count(name)) continue;
    const int k = problem.segments() * problem.state_size() + static_cast<int>(
        std::find(problem.definition().unknown_parameters.begin(), problem.definition().unknown_parameters.end(), name) -
        problem.definition().unknown_parameters.begin());
    Eigen::VectorXd x_moved = x;
    const auto alternating = time_call(problem, reps, [&] {
      x_moved[k] += 1e-12 * (1.0 + std::abs(x[k]));  // a value not built before
      problem.evaluate(x_moved, &F, nullptr, &failure);
    });
    std::printf("    residual F, '%s' new at every call (equations rebuilt): %.1f us, i.e. ~%.1f us per rebuild\n",
                name.c_str(), alternating.first, alternating.first - f_only.first);
  }
  std::printf("    F + J finite diff.    %9.1f us %7.0f rhs  (2 x %d residuals)  var/FD time %.2f, |J_var - J_fd| %.1e\n",
              f_fd.first, f_fd.second, problem.size(), f_var.first / f_fd.first, jac_diff);
}

void threads_ratio();

int run_summary(int runs_planar, int runs_3d) {
  const std::vector<Scenario> all = scenarios();
  std::map<std::string, Stats> results;
  std::printf("Kirchhoff shooting solves, Newton to max|F| <= 1e-10; medians of N timed solves (one thread, CPU time;\n");
  std::printf("min_wall_us: the shortest wall time). Goals (issue 24): planar Elastica <= %.0f us, twisted 3D rod <= %.0f us;\n",
              kPlanarGoalUs, kSpatialGoalUs);
  std::printf("'goal' = median / goal (<= 1 meets it).\n\n");
  std::printf("%-70s %4s %10s %11s %9s %7s %6s %9s %6s %s\n", "scenario", "N", "median_us", "min_wall_us", "rhs/solve",
              "its", "F_ev", "residual", "goal", "notes");
  for (const Scenario& sc : all) {
    const int runs = sc.spec->planar ? runs_planar : runs_3d;
    const Stats st = measure(sc, runs);
    results[sc.name()] = st;
    if (!st.ok) {
      std::printf("%-70s skipped: %s\n", sc.name().c_str(), st.error.c_str());
      continue;
    }
    std::string notes;
    if (st.failures) notes += std::to_string(st.failures) + " not converged; ";
    if (st.fallbacks) notes += std::to_string(st.fallbacks) + " used the NLopt fallback; ";
    std::printf("%-70s %4d %10.1f %11.1f %9.0f %7.2f %6.2f %9.1e %6.2f %s\n", sc.name().c_str(), runs, st.median_us,
                st.min_us, st.rhs, st.iterations, st.evaluations, st.residual, st.median_us / sc.goal_us(),
                notes.c_str());
    std::fflush(stdout);
  }

  // The default (variational step matrices, coarse phase) against one variant, single shooting,
  // each guess: time, right-hand sides and, where asked, Newton iterations, default / variant.
  auto against_default = [&](const char* title, Jacobian variant, bool iterations) {
    std::printf("\n%s\n", title);
    for (const CaseSpec& spec : case_specs())
      for (Guess g : {Guess::Case, Guess::Perturbed}) {
        const Stats& v = results[Scenario{&spec, 1, Jacobian::Variational, g}.name()];
        const Stats& o = results[Scenario{&spec, 1, variant, g}.name()];
        if (!v.ok || !o.ok) continue;
        std::printf("  %-28s %-16s time %.2f (%.1f / %.1f us)  rhs %.2f (%.0f / %.0f)", spec.label.c_str(),
                    g == Guess::Case ? "case_guess" : "perturbed_guess", v.median_us / o.median_us, v.median_us,
                    o.median_us, v.rhs / o.rhs, v.rhs, o.rhs);
        if (iterations) std::printf("  its %.2f / %.2f", v.iterations, o.iterations);
        std::printf("\n");
      }
  };
  against_default("Step matrices / exact matrices (NewtonOptions::step_matrix_tolerance; same process, single shooting):",
                  Jacobian::ExactVariational, true);
  against_default("With / without Newton's coarse phase (NewtonOptions::coarse_tolerance; same process, single shooting):",
                  Jacobian::VariationalNoCoarse, true);
  against_default("Variational / finite-difference Jacobian (same process, single shooting):", Jacobian::FiniteDifference,
                  false);

  std::printf("\nSingle / multiple (4 segments) shooting, Elastica, variational Jacobian:\n");
  for (const CaseSpec& spec : case_specs()) {
    if (!spec.planar) continue;
    for (Guess g : {Guess::Case, Guess::Perturbed}) {
      const Stats& s1 = results[Scenario{&spec, 1, Jacobian::Variational, g}.name()];
      const Stats& s4 = results[Scenario{&spec, 4, Jacobian::Variational, g}.name()];
      if (!s1.ok || !s4.ok) continue;
      std::printf("  %-28s %-16s time %.2f (%.1f / %.1f us)  its %.2f / %.2f\n", spec.label.c_str(),
                  g == Guess::Case ? "case_guess" : "perturbed_guess", s1.median_us / s4.median_us, s1.median_us,
                  s4.median_us, s1.iterations, s4.iterations);
    }
  }

  std::printf("\nOne evaluation at the solution (median of repeated calls):\n");
  for (const CaseSpec& spec : case_specs()) jacobian_breakdown(spec, spec.planar ? runs_planar : runs_3d);
  threads_ratio();
  return 0;
}

// Multiple shooting's segments integrated by one thread and by the machine's threads
// (ShootingOptions::threads), same process: plectoneme.toml at L/2R = 200 (40 segments, 574
// unknowns), F + J at its starting guess.
void threads_ratio() {
  std::printf("\nMultiple shooting, segments on one thread / on all (%u) hardware threads (wall time):\n",
              std::thread::hardware_concurrency());
  Case c = load_case(std::string(KIRCHHOFF_CASES_DIR) + "/plectoneme.toml", {{"slenderness", 200.0}});
  std::map<int, std::pair<double, double>> times;
  for (int threads : {1, 0}) {
    c.definition.options.threads = threads;
    const ShootingProblem problem(c.definition);
    const Eigen::VectorXd x = problem.initial_unknowns(c.start_guess);
    Eigen::VectorXd F(problem.size());
    Eigen::MatrixXd J(problem.size(), problem.size());
    times[threads] = time_call(problem, 5, [&] { problem.evaluate(x, &F, &J, nullptr); }, true);
    const auto f_only = time_call(problem, 20, [&] { problem.evaluate(x, &F, nullptr, nullptr); }, true);
    times[threads + 10] = f_only;
  }
  std::printf("  %-28s F + J %9.0f / %9.0f us  ratio %.2f   F %7.0f / %7.0f us  ratio %.2f\n",
              "plectoneme, L/2R = 200", times[1].first, times[0].first, times[1].first / times[0].first,
              times[11].first, times[10].first, times[11].first / times[10].first);
}

int positive_int(const char* text, const char* flag) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (!end || *end || v < 1 || v > 1000000) throw std::invalid_argument(std::string(flag) + " needs a positive integer");
  return static_cast<int>(v);
}

}  // namespace

int main(int argc, char** argv) {
  bool summary = false;
  int runs_planar = 200, runs_3d = 50;
  std::vector<char*> rest{argv[0]};
  try {
    for (int i = 1; i < argc; ++i) {
      if (std::strcmp(argv[i], "--summary") == 0) {
        summary = true;
      } else if (std::strcmp(argv[i], "--runs-planar") == 0 && i + 1 < argc) {
        runs_planar = positive_int(argv[++i], "--runs-planar");
      } else if (std::strcmp(argv[i], "--runs-3d") == 0 && i + 1 < argc) {
        runs_3d = positive_int(argv[++i], "--runs-3d");
      } else {
        rest.push_back(argv[i]);
      }
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  if (summary) return run_summary(runs_planar, runs_3d);

  int bench_argc = static_cast<int>(rest.size());
  register_benchmarks();
  benchmark::Initialize(&bench_argc, rest.data());
  if (benchmark::ReportUnrecognizedArguments(bench_argc, rest.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

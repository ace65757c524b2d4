// Throughput of pseudo-arclength continuation (points per second on one core) along the two
// reference branches of the performance goals, against AUTO-07p and a naive natural-parameter
// continuation run on the same core in the same process:
//   (1) the first buckled Euler branch: cases/euler_column.toml (pinned, load P), straight from
//       P = 1 with theta_guess = 0 to the first branch point (untimed), then switch_branch and
//       follow to the event theta0 = 3.0 (timed). P is checked against Love's Elastica,
//       analytic::PinnedElastica{1, 1, theta0}.load(), over the regular points with
//       theta0 > 1e-3 (branch-point-type points are skipped: the touching-ends point is a
//       singular point of this problem, see tests/continuation_test.cpp).
//   (2) the clamped twisted rod's buckled branch: cases/twisted_clamped.toml (tension 0),
//       straight from phi = 6 to the first (double) branch point (untimed), then
//       axial_symmetry_branch and run_along to the event end_to_end = 0.5 (timed), with the
//       invariants on; reports the worst spreads of m3 and n.m along the branch.
//   (3) naive continuations for the ratio: the simply supported Elastica
//       (cases/simply_supported.toml, theta0 imposed, P unknown) stepped in theta0 from 0.02 to
//       3.0 in as many points as (1), each point a kirchhoff::solve from the previous unknowns;
//       the twisted rod with the axial phase condition stepped through the phi values of (2) the
//       same way (a true natural-parameter continuation in phi cannot pass the branch structure,
//       so it borrows the branch's phi values). Note that solve() on a problem with the axial
//       phase condition evaluates one more Jacobian at the solution (its degeneracy check).
//   (4) the same engine at a fixed small step (a quarter of the branch's max_step: initial and
//       max step equal, no growth), over the same branch: what the step control buys.
//   (5) the branches (1) and (2) with the tangent predictor (StepControl::Predictor::Tangent)
//       instead of the default quadratic one: what the predictor buys.
//   (6) the branch (1) with its flows marched by RKF78 (IntegratorOptions::closed_form off):
//       what the closed-form flow of a planar rod under end loads buys.
// Goals (issue 24): >= 10x AUTO-07p's points per second, stated there as >= 35,000 planar and
// >= 2,500 3D points/s on the project's 2-core machine. AUTO-07p is not run by this program
// unless --auto-euler DIR / --auto-twist DIR name prepared AUTO run directories (an executable
// *.exe with its fort.2 and fort.3, as ../shared/anchors/auto07p/ sets them up): then it is timed
// in this process, alternating with our runs, by its children's CPU time, and the ratio printed
// is a measurement. Without them no ratio to AUTO is printed; the only AUTO figures are quoted
// constants below, each with its source. Times are CPU time of this process (the runs are
// single-threaded), medians of the repetitions; wall time is printed beside them.
//
// Modes:
//   continuation_benchmark [--reps N] [--euler-max-step H] [--twist-max-step H]
//                          [--auto-euler DIR] [--auto-twist DIR] [--tight-march]
//                                        the timed table (default; --summary is accepted too):
//                                        N repetitions of each timed run (default 7), medians;
//                                        max steps default to 1.0 (88 points) and 0.23 (129);
//                                        AUTO-07p timed side by side when its run directories
//                                        are given (see above).
//   continuation_benchmark --once euler|euler-inv|twist
//                                        one untimed branch after its set-up, for profilers
//                                        (perf, valgrind --tool=callgrind with
//                                        --toggle-collect='kirchhoff::Continuation::run_along*');
//                                        euler-points|twist-points lists the branch's points
//                                        (type, parameter, test functions, corrector iterations);
//                                        euler-predictor|twist-predictor compares the tangent
//                                        predictor's error with a quadratic one's along it.
//   continuation_benchmark --benchmark [--benchmark_...]
//                                        Google Benchmark, one iteration = one whole branch;
//                                        counters: points, points/s, rhs evaluations per point.
// Nothing here asserts on timings.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/detail/derived_quantities.hpp"
#include "kirchhoff/analysis/point_record.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/continuation/rod_continuation.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace {

using namespace kirchhoff;
using Clock = std::chrono::steady_clock;

// The goals, as issue 24 states them (10x AUTO-07p's points per second on the project's machine):
// constants, not measurements.
constexpr double kPlanarGoalIssue = 35000.0;
constexpr double kSpatialGoal = 2500.0;
// Quoted, not measured here: AUTO-07p's points per second on the two branches, measured side by
// side with this benchmark on the project's 2-core machine, the latest such run
// (docs/performance.md, "The spatial rod's variational equations written out"; its section
// "AUTO-07p side by side" gives the set-up). Printed for orientation only.
constexpr double kAutoPlanarQuoted = 2733.0;  // AUTO-07p, NTST = 20, NCOL = 5, EPSL = EPSU = 1e-10
constexpr double kAutoSpatialQuoted = 279.0;   // AUTO-07p, NTST = 10

// Step limits that give about as many points as AUTO-07p's runs (133 and 138); tunable.
double g_euler_max_step = 1.0;
double g_twist_max_step = 0.23;
// --tight-march: march_sensitivity_tol = 0 (every matrix at the state's tolerance, as before
// that option).
bool g_tight_march = false;
// AUTO-07p run directories for the side-by-side measurement (empty: AUTO is not run).
std::string g_auto_euler_dir, g_auto_twist_dir;

std::string case_path(const std::string& name) { return std::string(KIRCHHOFF_CASES_DIR) + "/" + name; }

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// CPU time of this process (every run here is single-threaded): what another process on the
// shared cores does not inflate, unlike the wall time.
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int count_type(const ContinuationResult& r, PointType type) {
  return static_cast<int>(std::count_if(r.points.begin(), r.points.end(),
                                        [&](const ContinuationPoint& p) { return p.type == type; }));
}

// ---------------------------------------------------------------------------------------------
// Set-ups (untimed): the straight branches up to their first branch point.

struct EulerSetup {
  Case c;
  std::unique_ptr<ShootingProblem> problem;
  ContinuationPoint branch_point;
  std::string error;
};

// marched: the same column with its flows marched by RKF78 (IntegratorOptions::closed_form off),
// the baseline the closed-form flow is measured against in this process.
EulerSetup make_euler_setup(bool marched) {
    EulerSetup s;
    try {
      s.c = load_case(case_path("euler_column.toml"), {{"P", 1.0}, {"theta_guess", 0.0}});
      s.c.definition.options.integrator.closed_form = !marched;
      s.problem = std::make_unique<ShootingProblem>(s.c.definition);
      RodContinuationOptions o;
      o.parameter = "P";
      o.target = 12.0;
      o.initial_step = 0.5;
      o.max_step = 5.0;
      o.samples = 21;
      o.derived = {"theta0", "end_to_end"};
      o.stop_at_branch_point = 1;
      RodContinuation straight(*s.problem, o);
      const ContinuationResult r = straight.run(s.problem->initial_unknowns(s.c.start_guess));
      if (r.reason != StopReason::BranchPointStop)
        s.error = std::string("straight Euler column: no branch point (") + to_string(r.reason) + ") " + r.message;
      else
        s.branch_point = r.points.back();
    } catch (const std::exception& e) {
      s.error = std::string("Euler set-up failed: ") + e.what();
    }
    return s;
}

const EulerSetup& euler_setup(bool marched = false) {
  if (marched) {
    static const EulerSetup march = make_euler_setup(true);
    return march;
  }
  static const EulerSetup closed_form = make_euler_setup(false);
  return closed_form;
}

struct TwistSetup {
  Case c;
  std::unique_ptr<ShootingProblem> straight_problem;
  std::unique_ptr<RodContinuation> straight;
  ContinuationPoint branch_point;
  SymmetricBranchStart start;
  std::unique_ptr<ShootingProblem> switched;  // with the axial phase condition
  std::string error;
};

const TwistSetup& twist_setup() {
  static TwistSetup s = [] {
    TwistSetup s;
    try {
      s.c = load_case(case_path("twisted_clamped.toml"), {{"phi", 6.0}, {"tension", 0.0}});
      s.straight_problem = std::make_unique<ShootingProblem>(s.c.definition);
      RodContinuationOptions o;
      o.parameter = "phi";
      o.target = 15.0;
      o.initial_step = 0.5;
      o.max_step = 1.0;
      o.samples = 41;
      o.derived = {"end_to_end", "M"};
      o.stop_at_branch_point = 1;
      s.straight = std::make_unique<RodContinuation>(*s.straight_problem, o);
      const ContinuationResult r = s.straight->run(s.straight_problem->initial_unknowns(s.c.start_guess));
      if (r.reason != StopReason::BranchPointStop) {
        s.error = std::string("straight twisted rod: no branch point (") + to_string(r.reason) + ") " + r.message;
        return s;
      }
      s.branch_point = r.points.back();
      s.start = axial_symmetry_branch(*s.straight, s.branch_point);
      s.switched = std::make_unique<ShootingProblem>(s.start.definition);
    } catch (const std::exception& e) {
      s.error = std::string("twisted-rod set-up failed: ") + e.what();
    }
    return s;
  }();
  return s;
}

// ---------------------------------------------------------------------------------------------
// The timed runs

RodContinuationOptions euler_branch_options(bool invariants) {
  RodContinuationOptions o;
  o.parameter = "P";
  o.initial_step = 0.05;
  o.max_step = g_euler_max_step;
  o.events = {{"theta0", 3.0, true}};
  o.derived = {"theta0"};
  o.compute_invariants = invariants;
  // theta0 is read at s = 0: without the invariants each point is described at its start alone
  // (make_start_solution; samples unused); with them, the usual profile of 101 points.
  o.samples = invariants ? 101 : 2;
  if (g_tight_march) o.march_sensitivity_tol = 0;
  return o;
}

RodContinuationOptions twist_branch_options() {
  RodContinuationOptions o;
  o.parameter = "phi";
  o.initial_step = 0.05;
  o.max_step = g_twist_max_step;
  o.events = {{"end_to_end", 0.5, true}};
  o.derived = {"end_to_end"};
  o.compute_invariants = true;
  o.samples = 101;
  if (g_tight_march) o.march_sensitivity_tol = 0;
  return o;
}

struct Run {
  bool ok = false;
  std::string error;
  ContinuationResult result;
  double seconds = 0, cpu = 0;  // wall and CPU time
  long rhs = 0;
  Continuation::EvaluationCount evaluations;  // residuals alone, and residuals with their matrix
};

// One timed branch of `branch`: `go` runs it.
template <class Go>
Run timed(RodContinuation& branch, Go&& go) {
  Run run;
  const long rhs0 = branch.rhs_evaluations();
  const Continuation::EvaluationCount e0 = branch.evaluations();
  const double c0 = cpu_seconds();
  const auto t0 = Clock::now();
  run.result = go();
  run.seconds = seconds_since(t0);
  run.cpu = cpu_seconds() - c0;
  run.rhs = branch.rhs_evaluations() - rhs0;
  run.evaluations.residuals = branch.evaluations().residuals - e0.residuals;
  run.evaluations.matrices = branch.evaluations().matrices - e0.matrices;
  run.ok = run.result.reason == StopReason::EventStop;
  if (!run.ok) run.error = std::string("stopped: ") + to_string(run.result.reason) + " " + run.result.message;
  return run;
}

// A fixed step (fixed_step > 0): initial and max step fixed_step times the branch's max_step,
// so the step never grows (it still shrinks where a corrector fails): the naive run of (4).
void fix_step(RodContinuationOptions& o, double fixed_step) {
  if (!(fixed_step > 0)) return;
  o.max_step *= fixed_step;
  o.initial_step = o.max_step;
  o.max_points = 100000;
}

using Predictor = StepControl::Predictor;

Run euler_branch(bool invariants, double fixed_step = 0, Predictor predictor = Predictor::Quadratic,
                 bool marched = false) {
  const EulerSetup& s = euler_setup(marched);
  if (!s.error.empty()) {
    Run run;
    run.error = s.error;
    return run;
  }
  RodContinuationOptions o = euler_branch_options(invariants);
  fix_step(o, fixed_step);
  o.predictor = predictor;
  RodContinuation branch(*s.problem, o);
  return timed(branch, [&] { return branch.switch_branch(s.branch_point); });
}

Run twist_branch(double fixed_step = 0, Predictor predictor = Predictor::Quadratic) {
  const TwistSetup& s = twist_setup();
  if (!s.error.empty()) {
    Run run;
    run.error = s.error;
    return run;
  }
  RodContinuationOptions o = twist_branch_options();
  fix_step(o, fixed_step);
  o.predictor = predictor;
  RodContinuation branch(*s.switched, o);
  return timed(branch, [&] {
    return branch.run_along(s.start.x, s.start.parameter, s.start.direction, PointType::BranchPoint);
  });
}

// Naive natural-parameter continuation: solve() at each parameter value from the previous
// unknowns. `values` are the parameter values after the (untimed) start x0.
struct NaiveRun {
  int points = 0, failures = 0;
  double seconds = 0, cpu = 0, iterations = 0;
  long rhs = 0;
  std::vector<Eigen::VectorXd> x;
};

NaiveRun naive(ShootingProblem& problem, const std::string& parameter, const std::vector<double>& values,
               Eigen::VectorXd x) {
  NaiveRun n;
  n.x.reserve(values.size());
  const long rhs0 = problem.rhs_evaluations();
  const double c0 = cpu_seconds();
  const auto t0 = Clock::now();
  for (double v : values) {
    problem.set_parameter(parameter, v);
    ShootingResult r = solve(problem, x);
    n.iterations += r.summary.iterations;
    if (r.summary.converged())
      x = r.x;
    else
      ++n.failures;
    n.x.push_back(r.x);
    ++n.points;
  }
  n.seconds = seconds_since(t0);
  n.cpu = cpu_seconds() - c0;
  n.rhs = problem.rhs_evaluations() - rhs0;
  return n;
}

struct NaiveEulerSetup {
  std::unique_ptr<ShootingProblem> problem;
  Eigen::VectorXd x0;  // converged at theta0 = 0.02
  std::string error;
};

constexpr double kNaiveTheta0Start = 0.02, kNaiveTheta0End = 3.0;

NaiveEulerSetup& naive_euler_setup() {
  static NaiveEulerSetup s = [] {
    NaiveEulerSetup s;
    try {
      const Case c = load_case(case_path("simply_supported.toml"), {{"theta0", kNaiveTheta0Start}, {"P", 10.0}});
      s.problem = std::make_unique<ShootingProblem>(c.definition);
      const ShootingResult r = solve(*s.problem, s.problem->initial_unknowns(c.start_guess));
      if (!r.summary.converged())
        s.error = "simply supported Elastica at theta0 = 0.02: " + r.summary.brief_report();
      s.x0 = r.x;
    } catch (const std::exception& e) {
      s.error = std::string("naive Euler set-up failed: ") + e.what();
    }
    return s;
  }();
  return s;
}

std::vector<double> naive_theta0_values(int points) {
  std::vector<double> v(points);
  for (int i = 0; i < points; ++i)
    v[i] = kNaiveTheta0Start + (kNaiveTheta0End - kNaiveTheta0Start) * (i + 1) / points;
  return v;
}

struct NaiveTwistSetup {
  std::unique_ptr<ShootingProblem> problem;
  std::string error;
};

NaiveTwistSetup& naive_twist_setup() {
  static NaiveTwistSetup s = [] {
    NaiveTwistSetup s;
    try {
      const Case c = load_case(case_path("twisted_clamped.toml"), {{"tension", 0.0}}, "axial");
      s.problem = std::make_unique<ShootingProblem>(c.definition);
      const TwistSetup& t = twist_setup();
      if (t.error.empty() && s.problem->size() != t.switched->size())
        s.error = "the axial case has " + std::to_string(s.problem->size()) + " unknowns, the switched problem " +
                  std::to_string(t.switched->size());
    } catch (const std::exception& e) {
      s.error = std::string("naive twisted-rod set-up failed: ") + e.what();
    }
    return s;
  }();
  return s;
}

// ---------------------------------------------------------------------------------------------
// Google Benchmark mode: one iteration = one whole branch.

// Machine-independent counts per point beside the rate: corrector iterations, matrices
// [F_x F_lambda] (variational Jacobians), residuals alone, right-hand sides.
struct BranchTotals {
  double points = 0, rhs = 0, iterations = 0, matrices = 0, residuals = 0;
  void add(const Run& r) {
    points += static_cast<double>(r.result.points.size());
    rhs += static_cast<double>(r.rhs);
    for (const auto& p : r.result.points) iterations += p.newton_iterations;
    matrices += static_cast<double>(r.evaluations.matrices);
    residuals += static_cast<double>(r.evaluations.residuals);
  }
};

void set_branch_counters(benchmark::State& state, const BranchTotals& t) {
  using benchmark::Counter;
  const double per = t.points > 0 ? 1.0 / t.points : 0.0;
  state.counters["points"] = Counter(t.points, Counter::kAvgIterations);
  state.counters["points_per_s"] = Counter(t.points, Counter::kIsRate);
  state.counters["rhs_per_point"] = Counter(t.rhs * per);
  state.counters["corrector_its_per_point"] = Counter(t.iterations * per);
  state.counters["jacobians_per_point"] = Counter(t.matrices * per);
  state.counters["residuals_per_point"] = Counter(t.residuals * per);
}

template <class Go>
void bm_branch(benchmark::State& state, Go&& go) {
  BranchTotals totals;
  for (auto _ : state) {
    const Run r = go();
    if (!r.ok) {
      state.SkipWithError(r.error.c_str());
      return;
    }
    totals.add(r);
  }
  set_branch_counters(state, totals);
}

void bm_euler_branch(benchmark::State& state, bool invariants) {
  bm_branch(state, [&] { return euler_branch(invariants); });
}

void bm_twist_branch(benchmark::State& state) {
  bm_branch(state, [] { return twist_branch(); });
}

// The naive run of (4): the same branch at a fixed step of a quarter of max_step.
constexpr double kNaiveFixedStep = 0.25;

void bm_euler_fixed(benchmark::State& state) {
  bm_branch(state, [] { return euler_branch(false, kNaiveFixedStep); });
}

void bm_twist_fixed(benchmark::State& state) {
  bm_branch(state, [] { return twist_branch(kNaiveFixedStep); });
}

void bm_naive_euler(benchmark::State& state) {
  NaiveEulerSetup& s = naive_euler_setup();
  if (!s.error.empty()) {
    state.SkipWithError(s.error.c_str());
    return;
  }
  const auto values = naive_theta0_values(static_cast<int>(state.range(0)));
  BranchTotals totals;  // corrector iterations: Newton iterations per solve; no matrices counted
  for (auto _ : state) {
    const NaiveRun n = naive(*s.problem, "theta0", values, s.x0);
    totals.points += n.points;
    totals.rhs += static_cast<double>(n.rhs);
    totals.iterations += n.iterations;
  }
  set_branch_counters(state, totals);
}

void register_benchmarks() {
  benchmark::RegisterBenchmark("euler_buckled_branch/derived_only", bm_euler_branch, false)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("euler_buckled_branch/invariants_101", bm_euler_branch, true)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("twisted_buckled_branch/invariants_101", bm_twist_branch)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("euler_buckled_branch/naive_fixed_step", bm_euler_fixed)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("twisted_buckled_branch/naive_fixed_step", bm_twist_fixed)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("naive_theta0_elastica", bm_naive_euler)->Arg(130)->Unit(benchmark::kMillisecond);
}

// ---------------------------------------------------------------------------------------------
// Table mode

struct BranchStats {
  bool ok = false;
  std::string error;
  int points = 0, regular = 0, branch_points = 0, events = 0;
  double median_s = 0, min_s = 0, median_cpu = 0, points_per_s = 0;  // points_per_s: by CPU time
  double rhs_per_point = 0, corrector_its_per_point = 0, jacobians_per_point = 0, residuals_per_point = 0;
  ContinuationResult last;
};

template <class F>
BranchStats time_branch(int reps, F&& run_once) {
  BranchStats st;
  std::vector<double> secs, cpus;
  for (int i = 0; i < reps; ++i) {
    Run r = run_once();
    if (!r.ok) {
      st.error = r.error;
      return st;
    }
    secs.push_back(r.seconds);
    cpus.push_back(r.cpu);
    if (i + 1 == reps) {
      st.points = static_cast<int>(r.result.points.size());
      st.rhs_per_point = static_cast<double>(r.rhs) / st.points;
      st.jacobians_per_point = static_cast<double>(r.evaluations.matrices) / st.points;
      st.residuals_per_point = static_cast<double>(r.evaluations.residuals) / st.points;
      double its = 0;
      for (const auto& p : r.result.points) its += p.newton_iterations;
      st.corrector_its_per_point = its / st.points;
      st.regular = count_type(r.result, PointType::Regular);
      st.branch_points = count_type(r.result, PointType::BranchPoint);
      st.events = count_type(r.result, PointType::Event);
      st.last = std::move(r.result);
    }
  }
  st.median_s = median(secs);
  st.min_s = *std::min_element(secs.begin(), secs.end());
  st.median_cpu = median(cpus);
  st.points_per_s = st.points / st.median_cpu;
  st.ok = true;
  return st;
}

struct NaiveStats {
  bool ok = false;
  std::string error;
  int points = 0, failures = 0;
  double median_s = 0, median_cpu = 0, points_per_s = 0, iterations_per_point = 0, rhs_per_point = 0;
  NaiveRun last;
};

template <class F>
NaiveStats time_naive(int reps, F&& run_once) {
  NaiveStats st;
  std::vector<double> secs, cpus;
  for (int i = 0; i < reps; ++i) {
    NaiveRun n = run_once();
    secs.push_back(n.seconds);
    cpus.push_back(n.cpu);
    if (i + 1 == reps) {
      st.points = n.points;
      st.failures = n.failures;
      st.iterations_per_point = n.iterations / n.points;
      st.rhs_per_point = static_cast<double>(n.rhs) / n.points;
      st.last = std::move(n);
    }
  }
  st.median_s = median(secs);
  st.median_cpu = median(cpus);
  st.points_per_s = st.points / st.median_cpu;
  st.ok = true;
  return st;
}

void print_header() {
  std::printf("%-44s %6s %6s %8s %8s %9s %7s %6s %5s %5s %6s\n", "run", "points", "reg/bp", "cpu_ms", "wall_ms",
              "points/s", "rhs/pt", "its/pt", "J/pt", "F/pt", "goal");
}

void print_branch(const char* label, const BranchStats& st, double goal) {
  if (!st.ok) {
    std::printf("%-44s failed: %s\n", label, st.error.c_str());
    return;
  }
  char types[32];
  std::snprintf(types, sizeof types, "%d/%d", st.regular, st.branch_points);
  std::printf("%-44s %6d %6s %8.2f %8.2f %9.0f %7.0f %6.2f %5.2f %5.2f %6.3f\n", label, st.points, types,
              1e3 * st.median_cpu, 1e3 * st.median_s, st.points_per_s, st.rhs_per_point, st.corrector_its_per_point,
              st.jacobians_per_point, st.residuals_per_point, goal > 0 ? st.points_per_s / goal : NAN);
}

// Naive natural-parameter runs: its/pt are Newton iterations per solve; J/pt and F/pt are not
// counted there (-).
void print_naive(const char* label, const NaiveStats& st, double goal) {
  if (!st.ok) {
    std::printf("%-44s failed: %s\n", label, st.error.c_str());
    return;
  }
  char fails[32];
  std::snprintf(fails, sizeof fails, "%dF", st.failures);
  std::printf("%-44s %6d %6s %8.2f %8.2f %9.0f %7.0f %6.2f %5s %5s %6.3f\n", label, st.points, fails,
              1e3 * st.median_cpu, 1e3 * st.median_s, st.points_per_s, st.rhs_per_point, st.iterations_per_point, "-",
              "-", goal > 0 ? st.points_per_s / goal : NAN);
}

// Max relative error of P against the Elastica over regular points with theta0 > 1e-3.
struct EulerAccuracy {
  double max_rel = 0, at_theta0 = NAN;
  int compared = 0;
  double touching_rel = NAN;  // the touching-ends branch point (skipped above), for information
  double final_theta0 = NAN, final_rel = NAN;
};

EulerAccuracy euler_accuracy(const ContinuationResult& r) {
  EulerAccuracy a;
  for (const auto& p : r.points) {
    const double theta0 = p.derived.count("theta0") ? p.derived.at("theta0") : NAN;
    if (!(theta0 > 1e-3)) continue;
    const double exact = analytic::PinnedElastica{1.0, 1.0, theta0}.load();
    const double rel = std::abs(p.parameter / exact - 1.0);
    if (p.type == PointType::BranchPoint) {
      a.touching_rel = rel;
      continue;
    }
    if (rel > a.max_rel) {
      a.max_rel = rel;
      a.at_theta0 = theta0;
    }
    ++a.compared;
  }
  if (!r.points.empty()) {
    const auto& last = r.points.back();
    a.final_theta0 = last.derived.count("theta0") ? last.derived.at("theta0") : NAN;
    if (a.final_theta0 > 0 && a.final_theta0 < M_PI)
      a.final_rel = std::abs(last.parameter / analytic::PinnedElastica{1.0, 1.0, a.final_theta0}.load() - 1.0);
  }
  return a;
}

// Worst spreads of the invariants along the twisted branch (absolute, and relative to their scale).
struct TwistInvariants {
  double m3 = 0, m3_rel = 0, nm = 0, nm_rel = 0, H_rel = 0, unfolding = 0;
  int H_not_flat = 0;
  double phi_min = INFINITY, phi_max = -INFINITY;
  int phi_turns = 0;  // sign changes of dphi along the branch (folds in phi)
};

TwistInvariants twist_invariants(const ContinuationResult& r) {
  TwistInvariants t;
  double previous_dphi = 0;
  for (size_t i = 0; i < r.points.size(); ++i) {
    const auto& p = r.points[i];
    const auto& inv = invariants_of(p);
    t.m3 = std::max(t.m3, inv.m3.spread);
    t.m3_rel = std::max(t.m3_rel, inv.m3.spread / std::max(1.0, inv.m3.scale));
    t.nm = std::max(t.nm, inv.n_dot_m.spread);
    t.nm_rel = std::max(t.nm_rel, inv.n_dot_m.spread / std::max(1.0, inv.n_dot_m.scale));
    t.H_rel = std::max(t.H_rel, inv.H.spread / std::max(1.0, inv.H.scale));
    if (!H_is_flat(p)) ++t.H_not_flat;
    if (p.x.size() > 0) t.unfolding = std::max(t.unfolding, std::abs(p.x[p.x.size() - 1]));
    t.phi_min = std::min(t.phi_min, p.parameter);
    t.phi_max = std::max(t.phi_max, p.parameter);
    if (i > 0) {
      const double dphi = p.parameter - r.points[i - 1].parameter;
      if (previous_dphi != 0 && dphi != 0 && (dphi > 0) != (previous_dphi > 0)) ++t.phi_turns;
      if (dphi != 0) previous_dphi = dphi;
    }
  }
  return t;
}

// What march() did besides plain steps, read back from the accepted points (in list order):
//   - determinant sign changes between consecutive regular points: each started an Illinois
//     location; when no branch point was accepted between the two, that location failed (a
//     corrector failure inside it discards the estimate);
//   - local minima of the smallest singular value over three consecutive regular points (without
//     a sign change in the last step): each started a Brent search over two steps, ~35 corrected
//     points, whether or not a branch point is there; a branch point accepted right after the
//     middle point is its result. (The first of the two points of a sign change is not a
//     minimum when the minimum falls in the second half of the step; the Brent search of the
//     next step then finds the same branch point again, listed after the point behind it.)
struct TestFunctionWork {
  int determinant_changes = 0, determinant_unlocated = 0, singular_minima = 0, singular_minima_found = 0;
};

TestFunctionWork test_function_work(const ContinuationResult& r) {
  TestFunctionWork w;
  std::vector<const ContinuationPoint*> regular;
  std::vector<bool> bp_after;  // a branch point follows this regular point in the list
  for (size_t i = 1; i < r.points.size(); ++i) {
    const auto& p = r.points[i];
    if (p.type == PointType::Regular) {
      regular.push_back(&p);
      bp_after.push_back(false);
    } else if (p.type == PointType::BranchPoint && !regular.empty()) {
      bp_after.back() = true;
    }
  }
  for (size_t k = 1; k < regular.size(); ++k)
    if ((regular[k - 1]->determinant < 0) != (regular[k]->determinant < 0)) {
      ++w.determinant_changes;
      if (!bp_after[k - 1]) ++w.determinant_unlocated;
    }
  for (size_t k = 1; k + 1 < regular.size(); ++k) {
    const bool simple = (regular[k]->determinant < 0) != (regular[k + 1]->determinant < 0);
    if (!simple && regular[k]->smallest_singular < regular[k - 1]->smallest_singular &&
        regular[k]->smallest_singular < regular[k + 1]->smallest_singular) {
      ++w.singular_minima;
      if (bp_after[k]) ++w.singular_minima_found;
    }
  }
  return w;
}

void print_test_function_work(const ContinuationResult& r) {
  const TestFunctionWork w = test_function_work(r);
  std::printf("    test functions: %d determinant sign change(s) (Illinois; %d without a located point), %d local\n"
              "    minimum/minima of the smallest singular value (Brent over two steps; %d gave a branch point)\n",
              w.determinant_changes, w.determinant_unlocated, w.singular_minima, w.singular_minima_found);
}

// Median CPU time of f over reps calls (after one warm-up).
template <class F>
double median_us(int reps, F&& f) {
  f();
  std::vector<double> us;
  for (int i = 0; i < reps; ++i) {
    const double c0 = cpu_seconds();
    f();
    us.push_back(1e6 * (cpu_seconds() - c0));
  }
  return median(us);
}

// A looser tolerance for the variational equations than the state's 1e-12 (cost_breakdown).
constexpr double kLooseSensitivityTol = 1e-8;

// Cost of the pieces of one continuation point at a point of the branch: residual only (a chord
// iteration), residual + variational Jacobian, the lambda column, the factorisations and SVD of
// the bordered matrix, and describe()'s sampling + derived quantities + invariants.
void cost_breakdown(const char* label, const ShootingProblem& base, const ContinuationPoint& p,
                    const std::string& parameter, const std::vector<std::string>& derived, int samples, int reps) {
  ShootingProblem problem = base;
  problem.set_parameter(parameter, p.parameter);
  const Eigen::VectorXd& x = p.x;
  const int n = problem.size();
  Eigen::VectorXd F, y_end, dF;
  Eigen::MatrixXd J;
  std::string failure;
  long rhs0 = problem.rhs_evaluations();
  const double t_f = median_us(reps, [&] { problem.evaluate(x, &F, nullptr, &failure); });
  const double rhs_f = static_cast<double>(problem.rhs_evaluations() - rhs0) / (reps + 1);
  rhs0 = problem.rhs_evaluations();
  const double t_fj = median_us(reps, [&] { problem.evaluate_with_end(x, &F, &J, &y_end, &failure); });
  const double rhs_fj = static_cast<double>(problem.rhs_evaluations() - rhs0) / (reps + 1);
  rhs0 = problem.rhs_evaluations();
  const double t_dl = median_us(reps, [&] { problem.parameter_derivative(x, parameter, &dF, &failure, &y_end); });
  const double rhs_dl = static_cast<double>(problem.rhs_evaluations() - rhs0) / (reps + 1);
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
  M.topLeftCorner(n, n) = J;
  M.block(0, n, n, 1) = dF;
  M.row(n) = p.tangent.transpose();
  double sink = 0;
  const double t_lu = median_us(reps, [&] { sink += M.partialPivLu().determinant(); });
  const double t_svd = median_us(reps, [&] { sink += Eigen::JacobiSVD<Eigen::MatrixXd>(M).singularValues()[n]; });
  // What make_point uses away from branch points: the eigenvalues of M^T M.
  const double t_eig = median_us(reps, [&] {
    sink += Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M.transpose() * M, Eigen::EigenvaluesOnly).eigenvalues()[0];
  });
  ShootingResult r;
  r.x = x;
  r.summary.status = SolverStatus::Converged;
  r.parameters = problem.parameters_at(x);
  rhs0 = problem.rhs_evaluations();
  const double t_desc = median_us(reps, [&] { sink += make_solution(problem, r, samples, derived).derived.size(); });
  const double t_desc2 = median_us(reps, [&] { sink += make_solution(problem, r, 2, derived).derived.size(); });
  // What a continuation recording only quantities read at s = 0 describes (point_record.cpp).
  const bool start_only = derived_read_start_only(derived);
  const double t_start =
      start_only ? median_us(reps, [&] { sink += make_start_solution(problem, r, derived).derived.size(); }) : 0.0;
  benchmark::DoNotOptimize(sink);
  std::printf("  %s, %d unknowns + parameter, at %s = %.4g:\n", label, n, parameter.c_str(), p.parameter);
  std::printf("    residual F (one chord iteration)       %8.1f us  %6.0f rhs\n", t_f, rhs_f);
  std::printf("    F + variational Jacobian                %8.1f us  %6.0f rhs\n", t_fj, rhs_fj);
  {
    // The same with the variational equations at a looser tolerance in their own pass
    // (IntegratorOptions::sensitivity_tol; the state, so F, at the case's): what a corrector or
    // tangent that does not locate branch points could use.
    ProblemDefinition loose_definition = problem.definition();
    loose_definition.options.integrator.sensitivity_tol = kLooseSensitivityTol;
    const ShootingProblem loose(loose_definition);
    Eigen::MatrixXd J_loose;
    const long before = loose.rhs_evaluations();
    const double t_loose = median_us(reps, [&] { loose.evaluate_with_end(x, &F, &J_loose, &y_end, &failure); });
    const double rhs_loose = static_cast<double>(loose.rhs_evaluations() - before) / (reps + 1);
    std::printf("    F + J, sensitivity_tol %.0e            %8.1f us  %6.0f rhs  (|J - J_tight| / |J| = %.1e)\n",
                kLooseSensitivityTol, t_loose, rhs_loose,
                (J_loose - J).lpNorm<Eigen::Infinity>() / J.lpNorm<Eigen::Infinity>());
    // The same matrix alone, where F is known (a converged point's tangent, a corrector's matrix
    // after its residual): one pass of state and variations at the looser tolerance.
    Eigen::MatrixXd J_alone;
    const long before_alone = loose.rhs_evaluations();
    const double t_alone =
        median_us(reps, [&] { loose.matrix_at_sensitivity_tolerance(x, &J_alone, &y_end, &failure); });
    const double rhs_alone = static_cast<double>(loose.rhs_evaluations() - before_alone) / (reps + 1);
    std::printf("    J alone, sensitivity_tol %.0e          %8.1f us  %6.0f rhs  (|J - J_tight| / |J| = %.1e)\n",
                kLooseSensitivityTol, t_alone, rhs_alone,
                (J_alone - J).lpNorm<Eigen::Infinity>() / J.lpNorm<Eigen::Infinity>());
  }
  std::printf("    F_lambda column (parameter_derivative)  %8.1f us  %6.0f rhs\n", t_dl, rhs_dl);
  std::printf("    LU of the bordered matrix               %8.2f us\n", t_lu);
  std::printf("    JacobiSVD of the bordered matrix        %8.2f us\n", t_svd);
  std::printf("    eigenvalues of its M^T M (the tests')   %8.2f us\n", t_eig);
  std::printf("    describe: make_solution(%3d samples)    %8.1f us  (derived:", samples, t_desc);
  for (const auto& d : derived) std::printf(" %s", d.c_str());
  std::printf(", invariants always)\n");
  std::printf("    describe: make_solution(  2 samples)    %8.1f us\n", t_desc2);
  if (start_only) std::printf("    describe: make_start_solution (s = 0)   %8.1f us\n", t_start);
  {
    // Where the Jacobian's RHS calls go: one pass over the rod with and without the variational
    // equations (RK78: 13 calls per attempted step); unknown model parameters add two plain
    // passes each (central differences).
    const auto eq = problem.equations(problem.parameters_at(x));
    const IntegratorOptions& io = problem.definition().options.integrator;
    const double L = eq->model().length;
    const SegmentFlow plain = eq->flow(problem.start_state(x), 0.0, L, false, io);
    const SegmentFlow sens = eq->flow(problem.start_state(x), 0.0, L, true, io);
    const double t_plain = median_us(reps, [&] { sink += eq->flow(problem.start_state(x), 0.0, L, false, io).y[0]; });
    const double t_sens = median_us(reps, [&] { sink += eq->flow(problem.start_state(x), 0.0, L, true, io).y[0]; });
    std::printf("    one pass over the rod: state only %4ld steps %5ld rhs %7.1f us | with variational eqs %4ld steps "
                "%5ld rhs %7.1f us\n",
                plain.steps, plain.rhs_evaluations, t_plain, sens.steps, sens.rhs_evaluations, t_sens);
  }
  // Unknowns the rod model depends on (the axial phase condition's "unfolding") rebuild the
  // equations at every new value: at every corrector iterate, and at a Jacobian's plus and minus
  // values (the workspace keeps the last three builds). Timed with a new value at every call.
  const auto& model_params = problem.definition().model_parameters;
  const auto& unknowns = problem.definition().unknown_parameters;
  for (size_t j = 0; j < unknowns.size(); ++j) {
    if (!model_params.count(unknowns[j])) continue;
    Eigen::VectorXd moved = x;
    const int k = problem.segments() * problem.state_size() + static_cast<int>(j);
    const double t_alt = median_us(reps, [&] {
      moved[k] += 1e-12 * (1.0 + std::abs(x[k]));  // a value not built before
      problem.evaluate(moved, &F, nullptr, &failure);
    });
    std::printf("    residual F with '%s' changed (rebuild)  %8.1f us  (~%.1f us per equations rebuild)\n",
                unknowns[j].c_str(), t_alt, t_alt - t_f);
  }
  (void)rhs0;
}

// ---------------------------------------------------------------------------------------------
// AUTO-07p side by side (optional): one run of the AUTO executable in `dir` (its constants in
// fort.2, its restart file in fort.3, OMP_NUM_THREADS=1), timed by the CPU time of the child,
// and its points: the labelled rows of fort.7 (first three columns integers, label not 0), as
// ../shared/anchors/auto07p/autotime.py counts them.
struct AutoRun {
  bool ok = false;
  std::string error;
  double cpu = 0;
  int points = 0;
};

double children_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

AutoRun run_auto(const std::string& dir) {
  AutoRun run;
  std::string exe;
  for (const char* name : {"euler.exe", "twist.exe"})
    if (std::ifstream(dir + "/" + name)) exe = name;
  if (exe.empty()) {
    run.error = "no euler.exe or twist.exe in " + dir;
    return run;
  }
  const double c0 = children_cpu_seconds();
  std::fflush(nullptr);  // or the child's freopen writes this process's buffered output a second time
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(127);
    setenv("OMP_NUM_THREADS", "1", 1);
    if (!std::freopen("/dev/null", "w", stdout)) _exit(127);
    execl(("./" + exe).c_str(), exe.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    run.error = "AUTO run in " + dir + " failed";
    return run;
  }
  run.cpu = children_cpu_seconds() - c0;
  std::ifstream fort7(dir + "/fort.7");
  std::string line;
  while (std::getline(fort7, line)) {
    std::istringstream in(line);
    std::vector<std::string> f{std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
    if (f.size() < 8 || f[0] == "0") continue;
    bool integers = true;
    for (int k = 0; k < 3; ++k) integers = integers && f[k].find_first_not_of("-0123456789") == std::string::npos;
    if (integers) ++run.points;
  }
  run.ok = run.points > 0;
  if (!run.ok) run.error = "no points in " + dir + "/fort.7";
  return run;
}

// Ours and AUTO's runs alternating, reps each; the ratio of points per CPU second.
template <class Ours>
void auto_ratio(const char* label, const std::string& dir, int reps, Ours&& ours) {
  std::vector<double> our_rate, auto_rate;
  int auto_points = 0, our_points = 0;
  for (int i = 0; i < reps; ++i) {
    const Run r = ours();
    const AutoRun a = run_auto(dir);
    if (!r.ok || !a.ok) {
      std::printf("  %s: %s\n", label, (!r.ok ? r.error : a.error).c_str());
      return;
    }
    our_points = static_cast<int>(r.result.points.size());
    auto_points = a.points;
    our_rate.push_back(our_points / r.cpu);
    auto_rate.push_back(a.points / a.cpu);
  }
  std::printf("  %s: Kirchhoff %.0f points/s (%d points), AUTO-07p %.0f points/s (%d points, %s), ratio %.2f "
              "(medians of %d alternating runs, CPU time)\n",
              label, median(our_rate), our_points, median(auto_rate), auto_points, dir.c_str(),
              median(our_rate) / median(auto_rate), reps);
}

void auto_side_by_side(int reps, const BranchStats& euler, const BranchStats& twist) {
  std::printf("\nAUTO-07p\n");
  if (g_auto_euler_dir.empty() && g_auto_twist_dir.empty()) {
    std::printf("  not run here (--auto-euler DIR / --auto-twist DIR time it side by side). Quoted, not measured in\n"
                "  this run: %.0f planar and %.0f 3D points/s on the project's machine (docs/performance.md);\n"
                "  against those, this run's %.0f and %.0f points/s would be %.2fx and %.2fx.\n",
                kAutoPlanarQuoted, kAutoSpatialQuoted, euler.points_per_s, twist.points_per_s,
                euler.points_per_s / kAutoPlanarQuoted, twist.points_per_s / kAutoSpatialQuoted);
    return;
  }
  if (!g_auto_euler_dir.empty()) auto_ratio("planar", g_auto_euler_dir, reps, [] { return euler_branch(false); });
  if (!g_auto_twist_dir.empty()) auto_ratio("3D", g_auto_twist_dir, reps, [] { return twist_branch(); });
}

int run_table(int reps) {
  const auto t_start = Clock::now();
  std::printf("Kirchhoff pseudo-arclength continuation: points per second of CPU time (one thread), medians of %d runs.\n",
              reps);
  std::printf("Goals (issue 24, constants): >= %.0f planar and >= %.0f 3D points/s; 'goal' = points/s / goal.\n",
              kPlanarGoalIssue, kSpatialGoal);
  std::printf("reg/bp = regular / branch-point-type points (naive: failed solves). Per point: rhs = right-hand-side\n");
  std::printf("calls (plain and variational alike), its = corrector iterations (naive: Newton iterations per solve),\n");
  std::printf("J = matrices [F_x F_lambda] evaluated (variational Jacobians), F = residuals evaluated alone.\n\n");

  const EulerSetup& es = euler_setup();
  const TwistSetup& ts = twist_setup();
  if (es.error.empty())
    std::printf("Euler column: straight branch from P = 1, first branch point at P = %.10f (pi^2 = %.10f)\n",
                es.branch_point.parameter, M_PI * M_PI);
  if (ts.error.empty())
    std::printf("Twisted rod:  straight branch from phi = 6, first branch point at phi = %.10f (multiplicity %d)\n",
                ts.branch_point.parameter, ts.branch_point.multiplicity);
  std::printf("\n");
  print_header();

  // (1) Euler branch
  euler_branch(false);  // warm-up
  const BranchStats e_fast = time_branch(reps, [] { return euler_branch(false); });
  print_branch("euler buckled, derived theta0 at s = 0", e_fast, kPlanarGoalIssue);
  const BranchStats e_inv = time_branch(reps, [] { return euler_branch(true); });
  print_branch("euler buckled, invariants on, 101 samples", e_inv, kPlanarGoalIssue);
  const BranchStats e_tangent = time_branch(reps, [] { return euler_branch(false, 0, Predictor::Tangent); });
  print_branch("euler buckled, tangent predictor", e_tangent, kPlanarGoalIssue);
  const BranchStats e_marched =
      time_branch(reps, [] { return euler_branch(false, 0, Predictor::Quadratic, true); });
  print_branch("euler buckled, flows marched (RKF78)", e_marched, kPlanarGoalIssue);

  // (3a) naive Euler
  NaiveStats n_euler;
  NaiveEulerSetup& nes = naive_euler_setup();
  const int n_points = e_fast.ok ? e_fast.points : 130;
  if (!nes.error.empty()) {
    n_euler.error = nes.error;
  } else {
    const auto values = naive_theta0_values(n_points);
    naive(*nes.problem, "theta0", values, nes.x0);  // warm-up
    n_euler = time_naive(reps, [&] { return naive(*nes.problem, "theta0", values, nes.x0); });
  }
  char label[96];
  std::snprintf(label, sizeof label, "naive theta0 %.2f..%.1f, solve() per point", kNaiveTheta0Start, kNaiveTheta0End);
  print_naive(label, n_euler, kPlanarGoalIssue);
  // (4a) the same branch at a fixed step
  const BranchStats e_fixed = time_branch(reps, [] { return euler_branch(false, kNaiveFixedStep); });
  print_branch("naive: euler at a fixed step (max_step / 4)", e_fixed, kPlanarGoalIssue);

  // (2) twisted branch
  twist_branch();  // warm-up
  const BranchStats t_inv = time_branch(reps, [] { return twist_branch(); });
  print_branch("twisted buckled, invariants on, 101 samples", t_inv, kSpatialGoal);
  const BranchStats t_tangent = time_branch(reps, [] { return twist_branch(0, Predictor::Tangent); });
  print_branch("twisted buckled, tangent predictor", t_tangent, kSpatialGoal);

  // (3b) naive twisted: solve() at the branch's phi values from the previous solution
  NaiveStats n_twist;
  double naive_twist_deviation = NAN;
  int naive_twist_off_branch = 0;
  NaiveTwistSetup& nts = naive_twist_setup();
  if (!t_inv.ok) {
    n_twist.error = "no branch to take the phi values from";
  } else if (!nts.error.empty()) {
    n_twist.error = nts.error;
  } else {
    // Start (untimed) at the branch's first regular point; step through the following ones.
    const auto& pts = t_inv.last.points;
    const Eigen::VectorXd x0 = pts[1].x;
    std::vector<double> values;
    for (size_t i = 2; i < pts.size(); ++i) values.push_back(pts[i].parameter);
    nts.problem->set_parameter("phi", pts[1].parameter);
    naive(*nts.problem, "phi", values, x0);  // warm-up
    n_twist = time_naive(reps, [&] { return naive(*nts.problem, "phi", values, x0); });
    naive_twist_deviation = 0;
    for (size_t i = 0; i < n_twist.last.x.size(); ++i) {
      const double d = (n_twist.last.x[i] - pts[i + 2].x).lpNorm<Eigen::Infinity>();
      naive_twist_deviation = std::max(naive_twist_deviation, d);
      if (d > 1e-6) ++naive_twist_off_branch;
    }
  }
  print_naive("naive phi (branch's values, axial phase cond.)", n_twist, kSpatialGoal);
  // (4b) the same branch at a fixed step
  const BranchStats t_fixed = time_branch(reps, [] { return twist_branch(kNaiveFixedStep); });
  print_branch("naive: twisted at a fixed step (max_step / 4)", t_fixed, kSpatialGoal);

  // Accuracy and invariants
  std::printf("\nAccuracy\n");
  if (e_fast.ok) {
    const EulerAccuracy a = euler_accuracy(e_fast.last);
    std::printf("  Euler (derived only): max |P / P_elastica - 1| = %.2e over %d regular points with theta0 > 1e-3 "
                "(worst at theta0 = %.4f); AUTO-07p <= 4e-9\n",
                a.max_rel, a.compared, a.at_theta0);
    std::printf("    skipped touching-ends branch point: %.2e (singular point, ~sqrt(1e-10) expected); final event "
                "point theta0 = %.12f, error %.2e\n",
                a.touching_rel, a.final_theta0, a.final_rel);
    std::printf("    points by type: %d regular, %d branch point (switching origin + touching ends), %d event\n",
                e_fast.regular, e_fast.branch_points, e_fast.events);
    print_test_function_work(e_fast.last);
  }
  if (e_inv.ok) {
    const EulerAccuracy a = euler_accuracy(e_inv.last);
    std::printf("  Euler (invariants on): max |P / P_elastica - 1| = %.2e over %d points\n", a.max_rel, a.compared);
  }
  if (n_euler.ok) {
    double worst = 0;
    const auto values = naive_theta0_values(n_euler.points);
    for (size_t i = 0; i < n_euler.last.x.size(); ++i) {
      const double P = nes.problem->parameters_at(n_euler.last.x[i]).get("P");
      worst = std::max(worst, std::abs(P / analytic::PinnedElastica{1.0, 1.0, values[i]}.load() - 1.0));
    }
    std::printf("  naive Euler: max |P / P_elastica - 1| = %.2e over %d points, %d failed solves\n", worst,
                n_euler.points, n_euler.failures);
  }
  if (t_inv.ok) {
    const TwistInvariants t = twist_invariants(t_inv.last);
    std::printf("  twisted: max spread m3 = %.2e (rel. to max(1, scale) %.2e), n.m = %.2e (rel. %.2e), H rel. %.2e, "
                "%d points with H not flat; max |unfolding| = %.1e\n",
                t.m3, t.m3_rel, t.nm, t.nm_rel, t.H_rel, t.H_not_flat, t.unfolding);
    std::printf("    phi in [%.4f, %.4f], %d turn(s) of phi along the branch; final end_to_end = %.12f\n", t.phi_min,
                t.phi_max, t.phi_turns, t_inv.last.points.back().derived.at("end_to_end"));
    print_test_function_work(t_inv.last);
  }
  if (n_twist.ok)
    std::printf("  naive twisted: %d failed solves, max |x - x_branch| = %.2e, %d point(s) off the branch (> 1e-6)\n",
                n_twist.failures, naive_twist_deviation, naive_twist_off_branch);

  std::printf("\nRatios (same process, CPU time)\n");
  if (e_fast.ok && n_euler.ok)
    std::printf("  planar: pseudo-arclength / naive solve() per point = %.2f  (%.0f / %.0f points/s)\n",
                e_fast.points_per_s / n_euler.points_per_s, e_fast.points_per_s, n_euler.points_per_s);
  if (e_fast.ok && e_fixed.ok)
    std::printf("  planar: pseudo-arclength / fixed step = %.2f in points/s (%.0f / %.0f), %.2f in time for the branch "
                "(%.1f / %.1f ms)\n",
                e_fast.points_per_s / e_fixed.points_per_s, e_fast.points_per_s, e_fixed.points_per_s,
                e_fixed.median_cpu / e_fast.median_cpu, 1e3 * e_fast.median_cpu, 1e3 * e_fixed.median_cpu);
  if (e_fast.ok && e_inv.ok)
    std::printf("  planar: invariants on (101 samples) cost %.2fx the time per point of derived-only (theta0 read at s = 0)\n",
                e_fast.points_per_s / e_inv.points_per_s);
  if (e_fast.ok && e_tangent.ok)
    std::printf("  planar: tangent / quadratic predictor = %.2f in time for the branch (%.1f / %.1f ms; %d / %d points)\n",
                e_tangent.median_cpu / e_fast.median_cpu, 1e3 * e_tangent.median_cpu, 1e3 * e_fast.median_cpu,
                e_tangent.points, e_fast.points);
  if (e_fast.ok && e_marched.ok)
    std::printf("  planar: closed-form flows / marched (RKF78) = %.2f in points/s (%.0f / %.0f; %d / %d points)\n",
                e_fast.points_per_s / e_marched.points_per_s, e_fast.points_per_s, e_marched.points_per_s, e_fast.points,
                e_marched.points);
  if (t_inv.ok && t_tangent.ok)
    std::printf("  3D:     tangent / quadratic predictor = %.2f in time for the branch (%.1f / %.1f ms; %d / %d points)\n",
                t_tangent.median_cpu / t_inv.median_cpu, 1e3 * t_tangent.median_cpu, 1e3 * t_inv.median_cpu,
                t_tangent.points, t_inv.points);
  if (t_inv.ok && n_twist.ok)
    std::printf("  3D:     pseudo-arclength / naive solve() per point = %.2f  (%.0f / %.0f points/s)\n",
                t_inv.points_per_s / n_twist.points_per_s, t_inv.points_per_s, n_twist.points_per_s);
  if (t_inv.ok && t_fixed.ok)
    std::printf("  3D:     pseudo-arclength / fixed step = %.2f in points/s (%.0f / %.0f), %.2f in time for the branch "
                "(%.1f / %.1f ms)\n",
                t_inv.points_per_s / t_fixed.points_per_s, t_inv.points_per_s, t_fixed.points_per_s,
                t_fixed.median_cpu / t_inv.median_cpu, 1e3 * t_inv.median_cpu, 1e3 * t_fixed.median_cpu);
  if (e_fast.ok)
    std::printf("  planar: points/s / goal = %.0f / %.0f = %.3f\n", e_fast.points_per_s, kPlanarGoalIssue,
                e_fast.points_per_s / kPlanarGoalIssue);
  if (t_inv.ok)
    std::printf("  3D:     points/s / goal = %.0f / %.0f = %.3f\n", t_inv.points_per_s, kSpatialGoal,
                t_inv.points_per_s / kSpatialGoal);
  auto_side_by_side(reps, e_fast, t_inv);

  std::printf("\nWhere a point's time goes: the pieces at a mid-branch point (median CPU us)\n");
  if (e_fast.ok) {
    const auto& p = e_fast.last.points[e_fast.last.points.size() / 2];
    cost_breakdown("Euler column", *es.problem, p, "P", {"theta0"}, 101, 200);
  }
  if (t_inv.ok) {
    const auto& p = t_inv.last.points[t_inv.last.points.size() / 2];
    cost_breakdown("twisted rod", *ts.switched, p, "phi", {"end_to_end"}, 101, 50);
  }
  std::printf("\ntotal wall time %.1f s\n", seconds_since(t_start));
  return 0;
}

// One untimed branch (after its set-up), for profilers: perf record / valgrind --tool=callgrind.
int run_once(const std::string& which) {
  Run r;
  if (which == "euler") {
    euler_setup();
    r = euler_branch(false);
  } else if (which == "euler-inv") {
    euler_setup();
    r = euler_branch(true);
  } else if (which == "twist") {
    twist_setup();
    r = twist_branch();
  } else {
    std::fprintf(stderr, "error: --once takes euler, euler-inv, twist, euler-points or twist-points\n");
    return 2;
  }
  if (!r.ok) {
    std::fprintf(stderr, "%s\n", r.error.c_str());
    return 1;
  }
  std::printf("%s: %zu points in %.2f ms, %ld rhs\n", which.c_str(), r.result.points.size(), 1e3 * r.seconds, r.rhs);
  return 0;
}

// How far the predictors land from the next corrected point along a computed branch: the tangent
// (Euler) predictor z_k + h t_k that the engine uses, and a quadratic one that adds the tangent's
// change over the last step, z_k + h t_k + h^2 / (2 h_prev) (t_k - t_{k-1}). Over consecutive
// regular points; with the corrector's contraction rate r per chord iteration, a start closer by
// a factor q saves log(q) / log(1 / r) iterations.
int predictor_study(bool twist) {
  const Run r = twist ? twist_branch() : euler_branch(false);
  if (!r.ok) {
    std::fprintf(stderr, "%s\n", r.error.c_str());
    return 1;
  }
  const auto& pts = r.result.points;
  auto z = [](const ContinuationPoint& p) {
    Eigen::VectorXd v(p.x.size() + 1);
    v << p.x, p.parameter;
    return v;
  };
  std::vector<double> linear, quadratic;
  for (size_t k = 1; k + 1 < pts.size(); ++k) {
    const auto &a = pts[k - 1], &b = pts[k], &c = pts[k + 1];
    if (a.type != PointType::Regular || b.type != PointType::Regular || c.type != PointType::Regular) continue;
    const double h_prev = b.arclength - a.arclength, h = c.arclength - b.arclength;
    if (!(h_prev > 0 && h > 0)) continue;
    const Eigen::VectorXd lin = z(b) + h * b.tangent;
    const Eigen::VectorXd quad = lin + 0.5 * h * h / h_prev * (b.tangent - a.tangent);
    linear.push_back((lin - z(c)).lpNorm<Eigen::Infinity>());
    quadratic.push_back((quad - z(c)).lpNorm<Eigen::Infinity>());
  }
  std::vector<double> ratio(linear.size());
  for (size_t i = 0; i < linear.size(); ++i) ratio[i] = linear[i] / std::max(quadratic[i], 1e-300);
  double its = 0;
  for (const auto& p : pts) its += p.newton_iterations;
  std::printf("%s: %zu steps between regular points; predictor error (max norm in (x, lambda)): tangent median %.2e, "
              "quadratic median %.2e; median ratio %.1f; corrector iterations per point %.2f\n",
              twist ? "twist" : "euler", linear.size(), median(linear), median(quadratic), median(ratio),
              its / static_cast<double>(pts.size()));
  return 0;
}

double positive_double(const char* text, const char* flag) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (!end || *end || !(v > 0) || !std::isfinite(v)) throw std::invalid_argument(std::string(flag) + " needs a positive number");
  return v;
}

int positive_int(const char* text, const char* flag) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (!end || *end || v < 1 || v > 10000) throw std::invalid_argument(std::string(flag) + " needs a positive integer");
  return static_cast<int>(v);
}

}  // namespace

int main(int argc, char** argv) {
  bool gbench = false;
  int reps = 7;
  std::string once;
  std::vector<char*> rest{argv[0]};
  try {
    for (int i = 1; i < argc; ++i) {
      if (std::strcmp(argv[i], "--benchmark") == 0) {
        gbench = true;
      } else if (std::strcmp(argv[i], "--summary") == 0) {
        gbench = false;
      } else if (std::strcmp(argv[i], "--once") == 0 && i + 1 < argc) {
        once = argv[++i];
      } else if (std::strcmp(argv[i], "--reps") == 0 && i + 1 < argc) {
        reps = positive_int(argv[++i], "--reps");
      } else if (std::strcmp(argv[i], "--tight-march") == 0) {
        g_tight_march = true;
      } else if (std::strcmp(argv[i], "--euler-max-step") == 0 && i + 1 < argc) {
        g_euler_max_step = positive_double(argv[++i], "--euler-max-step");
      } else if (std::strcmp(argv[i], "--twist-max-step") == 0 && i + 1 < argc) {
        g_twist_max_step = positive_double(argv[++i], "--twist-max-step");
      } else if (std::strcmp(argv[i], "--auto-euler") == 0 && i + 1 < argc) {
        g_auto_euler_dir = argv[++i];
      } else if (std::strcmp(argv[i], "--auto-twist") == 0 && i + 1 < argc) {
        g_auto_twist_dir = argv[++i];
      } else {
        rest.push_back(argv[i]);
      }
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  if (once == "euler-predictor" || once == "twist-predictor") return predictor_study(once == "twist-predictor");
  if (once == "euler-points" || once == "twist-points") {
    Run r = once == "twist-points" ? twist_branch() : euler_branch(false);
    if (!r.ok) std::fprintf(stderr, "%s\n", r.error.c_str());
    for (const auto& p : r.result.points)
      std::printf("%3d %-12s %s=%.6f det=% .3e ss=%.3e its=%d\n", p.index, to_string(p.type),
                  once == "twist-points" ? "phi" : "P", p.parameter, p.determinant,
                  p.smallest_singular, p.newton_iterations);
    return 0;
  }
  if (!once.empty()) return run_once(once);
  if (!gbench) {
    if (rest.size() > 1) {
      std::fprintf(stderr, "error: unknown argument '%s' (Google Benchmark flags need --benchmark)\n", rest[1]);
      return 2;
    }
    return run_table(reps);
  }
  int bench_argc = static_cast<int>(rest.size());
  register_benchmarks();
  benchmark::Initialize(&bench_argc, rest.data());
  if (benchmark::ReportUnrecognizedArguments(bench_argc, rest.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

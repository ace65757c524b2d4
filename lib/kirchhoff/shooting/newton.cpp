#include "kirchhoff/shooting/newton.hpp"

#include <chrono>
#include <cmath>
#include <nlopt.hpp>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/shooting/detail/jacobian_lu.hpp"

namespace kirchhoff {

const char* to_string(SolverStatus status) {
  switch (status) {
    case SolverStatus::Converged: return "converged";
    case SolverStatus::MaxIterations: return "max_iterations";
    case SolverStatus::SingularJacobian: return "singular_jacobian";
    case SolverStatus::IntegrationFailed: return "integration_failed";
    case SolverStatus::LineSearchFailed: return "line_search_failed";
    case SolverStatus::UnfoldingNotZero: return "unfolding_not_zero";
    case SolverStatus::NotFinite: return "not_finite";
    case SolverStatus::CheckFailed: return "check_failed";
    case SolverStatus::TimeLimit: return "time_limit";
  }
  return "unknown";
}

std::string NewtonOptions::validate() const {
  if (max_iterations < 1) return "max_iterations must be >= 1";
  if (!(residual_tolerance > 0)) return "residual_tolerance must be > 0";
  if (!(finite_difference_step > 0)) return "finite_difference_step must be > 0";
  if (max_backtracks < 0) return "max_backtracks must be >= 0";
  if (!(step_matrix_tolerance >= 0)) return "step_matrix_tolerance must be >= 0 (0: exact matrices)";
  if (!(coarse_tolerance >= 0 && coarse_tolerance <= kMaxCoarseTolerance)) {
    std::ostringstream os;
    os << "coarse_tolerance must be in [0, " << kMaxCoarseTolerance << "] (0: no coarse iterations)";
    return os.str();
  }
  if (!(max_seconds >= 0 && max_seconds <= 1e9)) return "max_seconds must be in [0, 1e9] (0: no limit)";
  return {};
}

std::string NewtonSummary::brief_report() const {
  std::ostringstream os;
  os << to_string(status) << " after " << iterations << " iterations, residual " << residual_norm;
  if (used_fallback_search) os << " (starting point from NLopt search)";
  if (!message.empty()) os << ": " << message;
  return os.str();
}

bool step_at_round_off(double step, double x_norm, double residual, double step_tolerance,
                       double residual_tolerance) {
  return step <= step_tolerance * (1.0 + x_norm) && residual <= 1e3 * residual_tolerance;
}

double max_abs_or_nan(const Eigen::VectorXd& v) {
  if (!v.allFinite()) return NAN;
  return v.size() == 0 ? 0.0 : v.lpNorm<Eigen::Infinity>();
}

std::chrono::steady_clock::time_point deadline_after(double seconds) {
  using Clock = std::chrono::steady_clock;
  if (!(seconds >= 0 && seconds <= 1e9)) throw std::invalid_argument("the time limit must be in [0, 1e9] seconds");
  if (seconds == 0) return Clock::time_point::max();
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

namespace {

// Wall-clock deadline of a solve: the earlier of its own limit (none when 0) and the options'
// deadline.
class Deadline {
 public:
  explicit Deadline(const NewtonOptions& options)
      : end_(options.max_seconds > 0 ? std::min(options.deadline, deadline_after(options.max_seconds))
                                     : options.deadline) {}
  bool limited() const { return end_ != std::chrono::steady_clock::time_point::max(); }
  bool passed() const { return limited() && std::chrono::steady_clock::now() >= end_; }
  double remaining_seconds() const {
    return std::max(1e-3, std::chrono::duration<double>(end_ - std::chrono::steady_clock::now()).count());
  }

 private:
  std::chrono::steady_clock::time_point end_;
};

}  // namespace

bool finite_difference_jacobian(const NonlinearSystem& system, const Eigen::VectorXd& x, double step,
                                Eigen::MatrixXd* J) {
  const int n = system.size();
  J->resize(n, n);
  Eigen::VectorXd xp = x, Fp, Fm;
  std::string failure;
  for (int j = 0; j < n; ++j) {
    const double h = step * (1.0 + std::abs(x[j]));
    xp[j] = x[j] + h;
    if (!system.evaluate(xp, &Fp, nullptr, &failure)) return false;
    xp[j] = x[j] - h;
    if (!system.evaluate(xp, &Fm, nullptr, &failure)) return false;
    xp[j] = x[j];
    J->col(j) = (Fp - Fm) / (2.0 * h);
  }
  return true;
}

namespace {

// Largest linear convergence rate (tolerance x condition number) accepted of a step matrix: two
// digits per iteration once the quadratic phase is over, so a solve ends at most a step or two
// later than on the exact matrices.
constexpr double kStepMatrixRate = 1e-2;

// The coarse phase (NewtonOptions::coarse_tolerance) lasts while max |F| exceeds this many times
// its tolerance: the coarse F's error is about the tolerance times the state's scale (1 to 1e2 on
// the rods here), so above that |F| is known to a percent or better and its steps are Newton's.
constexpr double kCoarseReach = 1e4;
// The coarse F's error, at most, in units of its tolerance (the state's scale).
constexpr double kCoarseError = 1e2;

// Whether the next full Newton step will likely converge, after a full step from |F_previous|
// to |F|: quadratic convergence (|F_next| ~ |F|^3 / |F_previous|^2) takes |F| below the tolerance.
bool expect_convergence(double norm, double previous_norm, double tolerance) {
  if (!(previous_norm > 0)) return false;
  const double ratio = norm / previous_norm;
  return norm * ratio * ratio <= tolerance;
}

// One solve's evaluations of F, with J when asked: coarse (NonlinearSystem::has_coarse_evaluations,
// F and J both) while the coarse phase lasts, then exact, by finite differences, or a step matrix
// (NonlinearSystem::has_step_matrices: F as evaluate's, a cheaper J). Step matrices are cleared
// for the rest of the solve when one is too ill-conditioned or its step fails; without them every
// evaluation after the coarse phase is exactly evaluate's, as it was before they existed.
class Evaluations {
 public:
  Evaluations(const NonlinearSystem& system, const NewtonOptions& options, NewtonSummary* summary)
      : system_(system),
        options_(options),
        summary_(summary),
        step_matrices_(options.step_matrix_tolerance > 0 && !options.finite_difference_jacobian &&
                       system.has_step_matrices(options.step_matrix_tolerance)),
        coarse_(options.coarse_tolerance > 0 && !options.finite_difference_jacobian &&
                system.has_coarse_evaluations(options.coarse_tolerance)) {}

  bool operator()(const Eigen::VectorXd& at, Eigen::VectorXd* f, Eigen::MatrixXd* jac) {
    ++summary_->evaluations;
    not_finite_ = false;
    bool ok = false;
    if (coarse_) {
      // An evaluation that fails coarse is made again exactly, and ends the coarse phase.
      ok = system_.evaluate_coarse(at, f, jac, options_.coarse_tolerance, &failure_) && f->allFinite() &&
           (!jac || jac->allFinite());
      if (ok) return true;
      end_coarse_phase();
      ++summary_->evaluations;
    }
    if (jac && step_matrices_)
      ok = system_.evaluate_for_step(at, f, jac, options_.step_matrix_tolerance, &failure_);
    else if (jac && options_.finite_difference_jacobian)
      ok = system_.evaluate(at, f, nullptr, &failure_) &&
           finite_difference_jacobian(system_, at, options_.finite_difference_step, jac);
    else
      ok = system_.evaluate(at, f, jac, &failure_);
    if (!ok) return false;
    // A NaN or inf is never a residual: it is reported, never compared with the tolerance.
    if (!f->allFinite() || (jac && !jac->allFinite())) {
      not_finite_ = true;
      failure_ = std::string("the ") + (f->allFinite() ? "Jacobian" : "residual") + " holds NaN or inf";
      return false;
    }
    return true;
  }

  // J at `at`, where *f is F already (at the same accuracy the phase evaluates F to): a step or
  // coarse matrix alone (NonlinearSystem::step_matrix, coarse_matrix), else F and J again.
  bool matrix(const Eigen::VectorXd& at, Eigen::VectorXd* f, Eigen::MatrixXd* jac) {
    if (!coarse_ && !step_matrices_) return (*this)(at, f, jac);
    ++summary_->evaluations;
    not_finite_ = false;
    const bool ok = coarse_ ? system_.coarse_matrix(at, jac, options_.coarse_tolerance, &failure_)
                            : system_.step_matrix(at, jac, options_.step_matrix_tolerance, &failure_);
    if (ok && jac->allFinite()) return true;
    // As a failed evaluation: made again (exactly, where the coarse phase ends), F with it.
    if (coarse_) end_coarse_phase();
    return (*this)(at, f, jac);
  }

  bool step_matrices() const { return step_matrices_; }
  void use_exact_matrices() { step_matrices_ = false; }
  bool coarse() const { return coarse_; }
  // Whether a coarse |F| of `norm` ends the coarse phase (within kCoarseReach of its tolerance).
  bool coarse_reached(double norm) const { return coarse_ && norm <= kCoarseReach * options_.coarse_tolerance; }
  void end_coarse_phase() { coarse_ = false; }

  // The summary of a solve ended by the last failed evaluation, at residual `norm`.
  NewtonSummary failed(double norm) const {
    NewtonSummary summary = *summary_;
    summary.status = not_finite_ ? SolverStatus::NotFinite : SolverStatus::IntegrationFailed;
    summary.residual_norm = norm;
    summary.message = failure_;
    return summary;
  }

 private:
  const NonlinearSystem& system_;
  const NewtonOptions& options_;
  NewtonSummary* summary_;
  bool step_matrices_;
  bool coarse_;
  std::string failure_;
  bool not_finite_ = false;  // the last failed evaluation returned NaN or inf (not an integrator failure)
};

// The accepted point of a backtracking line search along dx from x.
struct LineStep {
  bool accepted = false;
  double alpha = 1.0;
  bool has_matrix = false;  // J_trial holds the matrix at x_trial
};

// Backtracking on |F|_2: the first step length that decreases it (sufficient decrease with the
// usual 1e-4 slope fraction). A trial whose residual is NaN or inf fails to evaluate and is
// backed away from. The full step's trial carries its matrix when `matrix_with_full_step`.
LineStep line_search(Evaluations& evaluate, const NewtonOptions& options, const Deadline& deadline,
                     const Eigen::VectorXd& x, const Eigen::VectorXd& dx, double merit, bool matrix_with_full_step,
                     Eigen::VectorXd* x_trial, Eigen::VectorXd* F_trial, Eigen::MatrixXd* J_trial) {
  LineStep step;
  for (int k = 0; k <= options.max_backtracks && !deadline.passed(); ++k, step.alpha *= 0.5) {
    *x_trial = x + step.alpha * dx;
    step.has_matrix = k == 0 && matrix_with_full_step;
    if (evaluate(*x_trial, F_trial, step.has_matrix ? J_trial : nullptr) &&
        F_trial->squaredNorm() <= (1.0 - 1e-4 * step.alpha) * merit) {
      step.accepted = true;
      return step;
    }
  }
  return step;
}

// Ends the coarse phase at x: F (with J, when given) evaluated there exactly, its max |F| in *norm.
bool leave_coarse_phase(Evaluations& evaluate, const Eigen::VectorXd& x, Eigen::VectorXd* F, double* norm,
                        Eigen::MatrixXd* J = nullptr) {
  evaluate.end_coarse_phase();
  if (!evaluate(x, F, J)) return false;
  *norm = max_abs_or_nan(*F);
  return true;
}

NewtonSummary newton_until(const NonlinearSystem& system, Eigen::VectorXd& x, const NewtonOptions& options,
                           const Deadline& deadline) {
  NewtonSummary summary;
  Evaluations evaluate(system, options, &summary);
  Eigen::VectorXd F, F_trial, x_trial;
  Eigen::MatrixXd J, J_trial;

  // F alone first: a converged guess (or iterate) never pays for a Jacobian.
  if (!evaluate(x, &F, nullptr)) return evaluate.failed(INFINITY);
  double norm = max_abs_or_nan(F);
  summary.residual_norm = norm;
  // With step matrices, the full step's trial carries its matrix (its F is the one a trial alone
  // gives), so an accepted full step needs no evaluation at the new x. Not when the last step
  // was damped (the full step is then likely rejected) nor when the trial likely converges.
  bool have_matrix = false;  // J is the (step) matrix at x
  bool last_step_full = true;
  double previous_norm = NAN;
  for (int it = 0; it < options.max_iterations; ++it) {
    if (evaluate.coarse_reached(norm)) {
      // With the matrix the next step needs, unless |F| is within the coarse F's error (a start
      // that may be converged already: F alone, as without a coarse phase).
      const bool with_matrix = norm > kCoarseError * options.coarse_tolerance;
      if (!leave_coarse_phase(evaluate, x, &F, &norm, with_matrix ? &J : nullptr)) return evaluate.failed(norm);
      have_matrix = with_matrix;
    }
    // The residual reported is the one judged: every path back to this test (the coarse phase
    // left on an ill-conditioned matrix, the exact matrix taken over) has just evaluated it anew.
    summary.residual_norm = norm;
    if (norm <= options.residual_tolerance) {
      summary.status = SolverStatus::Converged;
      return summary;
    }
    if (deadline.passed()) {
      summary.status = SolverStatus::TimeLimit;
      summary.message = "the wall-clock limit was reached";
      return summary;
    }
    // (F is at x: the start's, a step's trial or the coarse phase's end.)
    if (!have_matrix && !evaluate.matrix(x, &F, &J)) return evaluate.failed(norm);
    have_matrix = false;
    const JacobianLU lu(J);
    const double rcond = lu.reciprocal_condition();
    // Too ill-conditioned for the coarse matrices' error (as for the step matrices below): the
    // rest of the solve on exact evaluations.
    if (evaluate.coarse() && !(options.coarse_tolerance <= kStepMatrixRate * rcond)) {
      if (!leave_coarse_phase(evaluate, x, &F, &norm)) return evaluate.failed(norm);
      --it;
      continue;
    }
    // A step matrix's error (~ its tolerance, relative) times the condition number is the rate
    // of the linear convergence it ends in: above kStepMatrixRate (or singular), the exact one.
    if (evaluate.step_matrices() && !(options.step_matrix_tolerance <= kStepMatrixRate * rcond)) {
      evaluate.use_exact_matrices();
      --it;
      continue;
    }
    if (!(rcond > options.singular_rcond)) {
      summary.status = SolverStatus::SingularJacobian;
      summary.message = "reciprocal condition number " + std::to_string(rcond);
      return summary;
    }
    const Eigen::VectorXd dx = -lu.solve(F);
    // (In the coarse phase the aim is its end, where the exact F and matrix are evaluated anyway.)
    const double aim = evaluate.coarse() ? kCoarseReach * options.coarse_tolerance : options.residual_tolerance;
    const bool matrix_with_full_step = (evaluate.step_matrices() || evaluate.coarse()) && last_step_full &&
                                       !expect_convergence(norm, previous_norm, aim);
    const LineStep step = line_search(evaluate, options, deadline, x, dx, F.squaredNorm(), matrix_with_full_step,
                                      &x_trial, &F_trial, &J_trial);
    if (!step.accepted && evaluate.coarse() && !deadline.passed()) {  // retried on exact evaluations
      if (!leave_coarse_phase(evaluate, x, &F, &norm)) return evaluate.failed(norm);
      --it;
      continue;
    }
    if (!step.accepted && evaluate.step_matrices() && !deadline.passed()) {  // retried on the exact matrix
      evaluate.use_exact_matrices();
      --it;
      continue;
    }
    ++summary.iterations;
    // At the exact solution of an ill-conditioned shooting problem no step lowers the residual's
    // noise: where Newton's own step is at round-off, that is convergence, not a failed search.
    if (!step.accepted && step_at_round_off(dx.lpNorm<Eigen::Infinity>(), x.lpNorm<Eigen::Infinity>(), norm,
                                            options.step_tolerance, options.residual_tolerance)) {
      summary.status = SolverStatus::Converged;
      summary.message = "step at round-off";
      return summary;
    }
    if (!step.accepted) {
      const bool timed_out = deadline.passed();  // once: status and message must agree
      summary.status = timed_out ? SolverStatus::TimeLimit : SolverStatus::LineSearchFailed;
      summary.message =
          timed_out ? "the wall-clock limit was reached in the line search" : "no step length decreased the residual";
      return summary;
    }
    x = x_trial;
    F = F_trial;
    if (step.has_matrix) {
      J.swap(J_trial);
      have_matrix = true;
    }
    previous_norm = norm;
    last_step_full = step.alpha == 1.0;
    norm = max_abs_or_nan(F);
    summary.residual_norm = norm;
    summary.history.push_back(norm);
    if (step_at_round_off(step.alpha * dx.lpNorm<Eigen::Infinity>(), x.lpNorm<Eigen::Infinity>(), norm,
                          options.step_tolerance, options.residual_tolerance)) {
      summary.status = SolverStatus::Converged;
      summary.message = "step at round-off";
      return summary;
    }
  }
  summary.status = norm <= options.residual_tolerance ? SolverStatus::Converged : SolverStatus::MaxIterations;
  return summary;
}

}  // namespace

NewtonSummary newton_solve(const NonlinearSystem& system, Eigen::VectorXd& x, const NewtonOptions& options) {
  return newton_until(system, x, options, Deadline(options));
}

namespace {

struct SearchContext {
  const NonlinearSystem* system;
  long evaluations = 0;
};

// Objective |F|^2 / 2 with gradient J^T F; an unevaluable point is a large value, so the
// search backs away from regions where the integrator fails.
double least_squares_objective(unsigned n, const double* x, double* grad, void* data) {
  auto* ctx = static_cast<SearchContext*>(data);
  ++ctx->evaluations;
  Eigen::Map<const Eigen::VectorXd> xv(x, n);
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  std::string failure;
  if (!ctx->system->evaluate(xv, &F, grad ? &J : nullptr, &failure) || !F.allFinite() ||
      (grad && !J.allFinite())) {
    if (grad) std::fill(grad, grad + n, 0.0);
    return 1e300;
  }
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = J.transpose() * F;
  return 0.5 * F.squaredNorm();
}

}  // namespace

NewtonSummary solve_with_fallback(const NonlinearSystem& system, Eigen::VectorXd& x, const NewtonOptions& options) {
  const Eigen::VectorXd guess = x;
  const Deadline deadline(options);
  NewtonSummary summary = newton_until(system, x, options, deadline);
  if (summary.converged() || !options.fallback_search || deadline.passed()) return summary;

  SearchContext ctx{&system};
  nlopt::opt search(nlopt::LD_LBFGS, static_cast<unsigned>(system.size()));
  search.set_min_objective(least_squares_objective, &ctx);
  search.set_maxeval(options.fallback_evaluations);
  search.set_ftol_abs(0.5 * options.residual_tolerance * options.residual_tolerance);
  if (deadline.limited()) search.set_maxtime(deadline.remaining_seconds());
  std::vector<double> start(guess.data(), guess.data() + guess.size());
  double value = 0.0;  // NLopt's objective at its end (unused: the residual there is recomputed)
  try {
    search.optimize(start, value);
  } catch (const std::exception&) {
    // NLopt stops with roundoff_limited or similar: the point reached is still a candidate.
  }
  Eigen::VectorXd candidate = Eigen::Map<Eigen::VectorXd>(start.data(), start.size());
  const Eigen::VectorXd searched = candidate;
  NewtonSummary second = newton_until(system, candidate, options, deadline);
  second.used_fallback_search = true;
  second.evaluations += summary.evaluations + ctx.evaluations;
  if (second.converged()) {
    x = candidate;
    return second;
  }
  // Neither start converged: the better one is returned, saying what both tried.
  Eigen::VectorXd F_searched;
  std::string failure;
  const double reached = system.evaluate(searched, &F_searched, nullptr, &failure) ? max_abs_or_nan(F_searched) : NAN;
  std::ostringstream tried;
  tried << "tried 2 starts: Newton from the guess (" << to_string(summary.status) << " after " << summary.iterations
        << " iterations, residual " << summary.residual_norm << "), then from the point an NLopt least-squares search "
        << "reached in " << ctx.evaluations << " evaluations (residual " << reached << " there; Newton: "
        << to_string(second.status) << " after " << second.iterations << " iterations, residual "
        << second.residual_norm << "); best residual " << std::min(summary.residual_norm, second.residual_norm)
        << " against the tolerance " << options.residual_tolerance;
  NewtonSummary& best = second.residual_norm < summary.residual_norm ? second : summary;
  if (&best == &second) x = candidate;
  best.evaluations = second.evaluations;
  best.append_to_message(tried.str());
  return best;
}

}  // namespace kirchhoff

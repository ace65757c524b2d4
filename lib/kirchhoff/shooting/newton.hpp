// Damped Newton for small dense square systems F(x) = 0 (the shooting residuals), with a
// summary that says why it stopped, a finite-difference Jacobian as a checked fallback, and an
// NLopt least-squares search for a starting point when Newton from the user's guess fails.
#pragma once

#include <Eigen/Dense>
#include <chrono>
#include <string>
#include <vector>

namespace kirchhoff {

class NonlinearSystem {
 public:
  virtual ~NonlinearSystem() = default;
  virtual int size() const = 0;  // number of unknowns = number of residuals
  // Fills F (and J when non-null). Returns false when the residual cannot be evaluated (the
  // integrator gave up), with the reason in *failure.
  virtual bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                        std::string* failure) const = 0;

  // Cheaper matrices for Newton's steps (NewtonOptions::step_matrix_tolerance): whether
  // evaluate_for_step at this tolerance gives F bit-identical to evaluate's F alone (so the
  // converged point, decided by F, is unchanged) and J to about `tolerance` relative, for less
  // than evaluate's F + J. The default: no such matrices, Newton calls evaluate.
  virtual bool has_step_matrices(double tolerance) const {
    (void)tolerance;
    return false;
  }
  virtual bool evaluate_for_step(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, double tolerance,
                                 std::string* failure) const {
    (void)tolerance;
    return evaluate(x, F, J, failure);
  }

  // Coarse evaluations for Newton's iterations far from the root (NewtonOptions::coarse_tolerance):
  // F, and J when asked, computed to about `tolerance` relative for less than evaluate. The
  // default: none, evaluate_coarse is evaluate.
  virtual bool has_coarse_evaluations(double tolerance) const {
    (void)tolerance;
    return false;
  }
  virtual bool evaluate_coarse(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, double tolerance,
                               std::string* failure) const {
    (void)tolerance;
    return evaluate(x, F, J, failure);
  }

  // The step matrix, or the coarse one, alone at x, for a caller that has F there already (Newton
  // after a step accepted without its matrix). Where F comes from a pass of its own at a tighter
  // tolerance than J (evaluate_for_step, evaluate_coarse), a system may skip that pass; J is then
  // the same matrix to about `tolerance`. The default: evaluate_for_step's (evaluate_coarse's) J.
  virtual bool step_matrix(const Eigen::VectorXd& x, Eigen::MatrixXd* J, double tolerance,
                           std::string* failure) const {
    Eigen::VectorXd F;
    return evaluate_for_step(x, &F, J, tolerance, failure);
  }
  virtual bool coarse_matrix(const Eigen::VectorXd& x, Eigen::MatrixXd* J, double tolerance,
                             std::string* failure) const {
    Eigen::VectorXd F;
    return evaluate_coarse(x, &F, J, tolerance, failure);
  }
};

enum class SolverStatus {
  Converged,          // max_i |F_i| <= residual_tolerance
  MaxIterations,      // max_iterations Newton steps without converging
  SingularJacobian,   // reciprocal condition number of J below singular_rcond
  IntegrationFailed,  // the residual could not be evaluated at the current iterate
  LineSearchFailed,   // no step length in [2^-max_backtracks, 1] decreased |F|
  UnfoldingNotZero,   // converged, but the symmetry-unfolding parameter is not 0 (|mu| >
                      // kUnfoldingTolerance): a solution of the unfolded system, not an equilibrium
  NotFinite,          // the residual or its Jacobian holds a NaN or an infinity
  CheckFailed,        // Newton converged, but the solution failed its own checks afterwards
                      // (verification.hpp: residual recomputed, finite values, admissibility)
  TimeLimit,          // the wall-clock limit (NewtonOptions::max_seconds) was reached
};
const char* to_string(SolverStatus status);

// The loosest NewtonOptions::coarse_tolerance: its phase ends at max |F| <= 1e4 times it, so
// beyond 1e-4 it would reach a residual of 1.
constexpr double kMaxCoarseTolerance = 1e-4;

struct NewtonOptions {
  int max_iterations = 50;
  double residual_tolerance = 1e-10;  // on max_i |F_i|; the integrator is run at 1e-12
  // Converged as well when the Newton step is this small relative to x and |F| is within
  // 1e3 x residual_tolerance: the iterate has stopped moving at round-off.
  double step_tolerance = 1e-14;
  int max_backtracks = 20;
  double singular_rcond = 1e-15;  // below this LU's estimate, J is treated as singular
  bool finite_difference_jacobian = false;  // fallback; the default is the variational Jacobian
  double finite_difference_step = 1e-6;     // central differences: error ~ h^2 ~ 1e-12
  // Newton's steps on matrices held to this relative tolerance where the system offers them
  // (NonlinearSystem::has_step_matrices: shooting problems without obstacles or contacts, whose
  // variational equations are then integrated to it, IntegratorOptions::sensitivity_tol). The
  // residual stays exact, so the converged point is decided as before; the convergence stays
  // quadratic down to ~tolerance x condition number and is linear with that rate below it. 1e-8:
  // as the continuation's march matrices (RodContinuationOptions::march_sensitivity_tol). A step
  // matrix whose condition number times this tolerance exceeds 1e-2 (the linear rate it would
  // converge at), or on which the step fails (no step length decreases |F|), is replaced by the
  // exact one, and the exact matrices are kept to the end of the solve. 0: the exact matrices
  // throughout, every evaluation as evaluate's.
  double step_matrix_tolerance = 1e-8;
  // The iterations far from the root on coarse evaluations where the system offers them
  // (NonlinearSystem::has_coarse_evaluations: shooting problems without obstacles or contacts,
  // integrated to this tolerance, F and J alike): a step from a residual of 1e-1 needs neither to
  // twelve digits, and RK78 takes about (1e-12 / tolerance)^(1/8) as many steps. The coarse phase
  // ends once the coarse max |F| is within kCoarseReach (1e4) times this tolerance, or at the first
  // coarse step that fails (no step length decreases |F|, an ill-conditioned or unevaluable
  // point); F is then evaluated exactly where it ended, and every evaluation after that is as
  // without a coarse phase: the converged point is decided on exact residuals. 0: none.
  double coarse_tolerance = 1e-7;
  bool fallback_search = true;  // run an NLopt least-squares search when Newton fails
  int fallback_evaluations = 2000;
  // Wall-clock limit of one solve in seconds (0: none), and an instant no solve runs past (a
  // command's limit for all the solves it makes: the rounds of an active-set loop, a fallback
  // search). Checked between evaluations, so a solve ends within the limit plus one evaluation
  // (an integration is itself bounded by IntegratorOptions::max_steps). Status time_limit.
  double max_seconds = 0.0;
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();

  std::string validate() const;  // empty when valid
};

struct NewtonSummary {
  SolverStatus status = SolverStatus::MaxIterations;
  int iterations = 0;
  double residual_norm = 0.0;  // max_i |F_i| at the returned x (the best one seen)
  std::string message;
  std::vector<double> history;  // residual norm after each iteration
  long evaluations = 0;
  bool used_fallback_search = false;

  bool converged() const { return status == SolverStatus::Converged; }
  std::string brief_report() const;
  // Why it stopped, for a user: its message, or its brief report where it gave none (out of
  // iterations).
  std::string why_stopped() const { return message.empty() ? brief_report() : message; }
  // Adds a clause to the message, after a "; " where it already says something.
  void append_to_message(const std::string& clause) { message = message.empty() ? clause : message + "; " + clause; }
};

// Solves F(x) = 0 starting from x; on return x holds the best iterate found.
NewtonSummary newton_solve(const NonlinearSystem& system, Eigen::VectorXd& x, const NewtonOptions& options);

// Newton, and when it fails and options.fallback_search is set, an NLopt minimisation of
// |F|^2 / 2 from the original guess followed by Newton again.
NewtonSummary solve_with_fallback(const NonlinearSystem& system, Eigen::VectorXd& x, const NewtonOptions& options);

// The instant `seconds` from now (0: none, time_point::max()), for NewtonOptions::deadline.
// Throws std::invalid_argument outside [0, 1e9].
std::chrono::steady_clock::time_point deadline_after(double seconds);

// max_i |v_i|, or NaN when any entry is NaN or infinite. (Eigen's lpNorm<Infinity> takes a
// maximum whose comparisons ignore a NaN, so a NaN residual could pass a `<= tolerance` test.)
double max_abs_or_nan(const Eigen::VectorXd& v);

// Newton's second test of convergence (NewtonOptions::step_tolerance): a Newton step `step`
// (max-norm) from x (max-norm `x_norm`) within step_tolerance of x's size, while max |F| is
// within 1e3 x residual_tolerance. An ill-conditioned shooting problem (a rod in tension under a
// large dead load, where the residual's sensitivity to the start grows like exp(sqrt(P) L))
// cannot lower its residual further: the iterate has stopped moving at round-off.
bool step_at_round_off(double step, double x_norm, double residual, double step_tolerance,
                       double residual_tolerance);

// Central-difference Jacobian; returns false when an evaluation fails.
bool finite_difference_jacobian(const NonlinearSystem& system, const Eigen::VectorXd& x, double step,
                                Eigen::MatrixXd* J);

}  // namespace kirchhoff

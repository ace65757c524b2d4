// Deflated Newton (Farrell, Birkisson & Funke 2015, "Deflation techniques for finding distinct
// solutions of nonlinear PDEs"): once roots r_1 .. r_k of F are known, Newton is run on
//   G(x) = M(x) F(x),   M(x) = prod_i (1 / ||x - r_i||^p + sigma),
// which has the same roots as F except the r_i, where M blows up fast enough (p >= 1 beyond the
// order of the root) that G no longer vanishes. So Newton from the same starting point cannot
// return to a known root and converges to another one, or fails.
//
// The Newton step on G needs no new linear algebra (their section 3.1): with d = -J_F^-1 F the
// ordinary Newton step and v = grad M / M = grad log M, the Sherman-Morrison formula applied to
// J_G = M J_F + F grad M^T gives
//   delta = d / (1 - v.d).
// Near a new root M is smooth and delta -> d, so convergence stays quadratic; convergence is
// judged on F itself (the equations the user asked for), not on G.
//
// The norm is ||S (x - r)||_2 with S = diag(1 / scale_j): the shooting unknowns mix positions,
// angles, forces, moments and arclengths whose magnitudes differ by orders of magnitude, and an
// unscaled norm would deflate only along the largest ones.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "kirchhoff/shooting/newton.hpp"

namespace kirchhoff {

class DeflationOperator {
 public:
  // `scale`: the typical magnitude of each unknown (all > 0). p = 2, sigma = 1 are the paper's
  // usual choices: p = 2 removes a simple root with margin, sigma = 1 keeps M -> 1 far from the
  // known roots so distant iterates take ordinary Newton steps.
  explicit DeflationOperator(Eigen::VectorXd scale, double power = 2.0, double shift = 1.0);

  void add_root(const Eigen::VectorXd& root);
  const std::vector<Eigen::VectorXd>& roots() const { return roots_; }
  const Eigen::VectorXd& scale() const { return scale_; }

  // M(x); 1 with no roots (plus sigma - 1 per root far away, the product of the factors).
  double value(const Eigen::VectorXd& x) const;
  // grad M / M = sum_i grad m_i / m_i, m_i = ||x - r_i||_S^-p + sigma.
  Eigen::VectorXd log_gradient(const Eigen::VectorXd& x) const;
  // Smallest scaled distance ||x - r_i||_S to a known root (infinity with none).
  double nearest_root_distance(const Eigen::VectorXd& x) const;
  // Scaled distance between two points.
  double distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) const;

 private:
  Eigen::VectorXd scale_;
  double power_, shift_;
  std::vector<Eigen::VectorXd> roots_;
};

struct DeflatedNewtonOptions {
  int max_iterations = 60;       // deflated iterates wander further than plain Newton's
  double residual_tolerance = 1e-10;  // on max_i |F_i|, as NewtonOptions
  int max_backtracks = 10;
  // Largest step in scaled units (max_j |delta_j| / scale_j): a step of two radians or two rod
  // lengths leaves the region the linearisation describes, and an integration across it mostly
  // fails; longer steps are shortened to this.
  double max_scaled_step = 2.0;
  // A step factor 1 / (1 - v.d) with |1 - v.d| below this would be a jump to infinity: the
  // iterate sits where the deflated system is singular, so the run stops there.
  double min_denominator = 1e-8;
  // A converged point this close (scaled distance) to a known root is that root reached anyway
  // (possible when the deflation is too weak at the start): reported as not converged.
  double known_root_distance = 1e-6;
  // Converged also where the plain Newton step is at round-off (step_at_round_off, as
  // NewtonOptions::step_tolerance): a root of an ill-conditioned problem that no iterate can
  // bring within residual_tolerance.
  double step_tolerance = 1e-14;
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
};

// Deflated Newton from x (on return the last iterate). The summary's status is Converged only when
// max |F| <= residual_tolerance (or the Newton step is at round-off, message "step at round-off")
// at a point that is not a known root; otherwise why it stopped.
NewtonSummary deflated_newton(const NonlinearSystem& system, Eigen::VectorXd& x, const DeflationOperator& deflation,
                              const DeflatedNewtonOptions& options = {});

}  // namespace kirchhoff

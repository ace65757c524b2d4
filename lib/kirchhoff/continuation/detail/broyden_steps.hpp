// Internal: Broyden's secant updates of the corrector's chord matrix.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <optional>
#include <vector>

namespace kirchhoff::detail {

// Broyden's ("good") update of the chord's matrix B, applied in product form to its inverse (C.
// T. Kelley, Iterative Methods for Linear and Nonlinear Equations, SIAM 1995, sec. 7.3): after
// steps s_0 .. s_k, H_k = (I + s_k s_{k-1}^T / |s_{k-1}|^2) ... (I + s_1 s_0^T / |s_0|^2) B_0^-1,
// and the next step is s_{k+1} = w / (1 - s_k^T w / |s_k|^2) with w = -H_k G(z_{k+1}). The chord on
// the previous point's matrix contracts linearly (by about 0.05 per iteration along the Euler
// column's branch); the secant updates make it superlinear for n vectors of storage per step and
// no new residual or matrix.
class BroydenSteps {
 public:
  // From the chord step -B_0^-1 G at the current iterate, Broyden's step, which the caller takes
  // (the updates assume every returned step was); none where the update degenerates (the new
  // step would undo the last), for the caller to leave the chord.
  std::optional<Eigen::VectorXd> next(Eigen::VectorXd w) {
    for (size_t j = 0; j + 1 < steps_.size(); ++j) w += steps_[j + 1] * (steps_[j].dot(w) / squared_norms_[j]);
    if (!steps_.empty()) {
      const double denominator = 1.0 - steps_.back().dot(w) / squared_norms_.back();
      if (!(std::abs(denominator) > kSmallestDenominator)) return std::nullopt;
      w /= denominator;
    }
    const double squared = w.squaredNorm();
    if (!(squared > 0.0) || !std::isfinite(squared)) return std::nullopt;
    steps_.push_back(w);
    squared_norms_.push_back(squared);
    return w;
  }

 private:
  // Below this the rank-one update is near singular (s_k^T w ~ |s_k|^2: the chord step repeats
  // the last one), and its step would be arbitrarily long.
  static constexpr double kSmallestDenominator = 0.1;
  std::vector<Eigen::VectorXd> steps_;
  std::vector<double> squared_norms_;
};

}  // namespace kirchhoff::detail

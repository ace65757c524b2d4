// What evaluating a ShootingProblem changes, apart from its description (Pinocchio's Data beside
// its Model): the equations built for the model parameters' last few values, the copies its worker
// threads integrate with, and the count of right-hand sides. A problem holds one; a copy of the
// problem copies it (the equations are immutable and shared), so each thread that evaluates a
// problem of its own has its own workspace, as before.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <vector>

#include "kirchhoff/equations/rod_equations.hpp"
#include "kirchhoff/model/parameters.hpp"

namespace kirchhoff {

class ShootingWorkspace {
 public:
  using Build = std::function<std::shared_ptr<const RodEquations>()>;

  // The equations for the model parameters' values, which for_each_value(visit) hands to visit
  // one by one: those built for the same values if one of the last kKept builds was (compared in
  // place, so that a known key allocates nothing), else build()'s in place of the least recently
  // used. Kept three: a Jacobian's column of a model parameter (the unfolding couple) asks for
  // the equations at the parameter's plus and minus values between two uses of its own. The
  // workers' copies are those of the equations handed out last, dropped when they change.
  template <class ForEachValue>
  std::shared_ptr<const RodEquations> equations(ForEachValue&& for_each_value, const Build& build) {
    int use = -1;
    for (int k = 0; k < kKept && use < 0; ++k)
      if (kept_[k].equations && same_key(kept_[k].key, for_each_value)) use = k;
    const bool rebuilt = use < 0;
    if (rebuilt) {
      use = 0;
      for (int k = 1; k < kKept; ++k)
        if (kept_[k].last_used < kept_[use].last_used) use = k;
      kept_[use].key.clear();
      for_each_value([&](double v) { kept_[use].key.push_back(v); });
      kept_[use].equations = build();
    }
    kept_[use].last_used = ++uses_;
    if (rebuilt || use != current_) workers_.clear();
    current_ = use;
    return kept_[use].equations;
  }

  // At least `count` copies of the equations for the extra worker threads (worker w >= 1 takes
  // copy w - 1; worker 0 uses equations()), built here, before the threads start: a thread's own
  // copy, as the equations are not shared between threads while they integrate.
  const std::vector<std::shared_ptr<const RodEquations>>& workers(int count, const Build& build) {
    while (static_cast<int>(workers_.size()) < count) workers_.push_back(build());
    return workers_;
  }

  // What one evaluation of the residual works in (ShootingProblem::evaluate and residual), kept
  // from one evaluation to the next so that, once they have their sizes, a residual allocates
  // nothing. Their contents mean nothing between evaluations; an evaluation made inside another
  // (a parameter column's residual) starts only after the outer residual is done with them, and
  // takes the parameters and the end state it is given, not these.
  struct Buffers {
    Parameters parameters;                // at the unknowns (evaluate)
    Eigen::VectorXd y_end;                // the last segment's end state (evaluate)
    Eigen::VectorXd F_unused;             // F of a matrix evaluated alone (step_matrix), not returned
    std::vector<Eigen::VectorXd> starts;  // each segment's start state, out of the unknowns
    std::vector<SegmentFlow> flows;       // each segment's flow (a residual's)
    // Each segment's flow with its sensitivities (a Jacobian's), apart from `flows` so that the
    // matrices keep their storage from one Jacobian to the next, residuals evaluated between.
    std::vector<SegmentFlow> sensitivity_flows;
    Eigen::MatrixXd gauge_jacobian;                // the gauge conditions' rows (start_rows)
    std::vector<double> start_values, end_values;  // the end conditions' rows
    std::vector<StateRow> start_jacobian, end_jacobian;
    // A Jacobian's columns of parameters that enter the end conditions only (evaluate).
    Eigen::VectorXd y0;
    Parameters plus, minus;
    std::vector<double> rows_plus, rows_minus;
  };
  Buffers& buffers() { return buffers_; }

  void count_rhs(long evaluations) { rhs_evaluations_ += evaluations; }
  long rhs_evaluations() const { return rhs_evaluations_; }

 private:
  struct Kept {
    std::vector<double> key;  // the model parameters' values
    std::shared_ptr<const RodEquations> equations;
    long last_used = 0;
  };
  template <class ForEachValue>
  static bool same_key(const std::vector<double>& key, ForEachValue&& for_each_value) {
    size_t count = 0;
    bool same = true;
    for_each_value([&](double v) {
      same = same && count < key.size() && key[count] == v;
      ++count;
    });
    return same && count == key.size();
  }
  static constexpr int kKept = 3;
  std::array<Kept, kKept> kept_;
  int current_ = -1;  // the one equations() handed out last (the workers' copies are of it)
  long uses_ = 0;
  std::vector<std::shared_ptr<const RodEquations>> workers_;
  long rhs_evaluations_ = 0;
  Buffers buffers_;
};

}  // namespace kirchhoff

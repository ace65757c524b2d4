// What evaluating a ShootingProblem changes, apart from its description (Pinocchio's Data beside
// its Model): the equations built for the model parameters' last values, the copies its worker
// threads integrate with, and the count of right-hand sides. A problem holds one; a copy of the
// problem copies it (the equations are immutable and shared), so each thread that evaluates a
// problem of its own has its own workspace, as before.
#pragma once

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
  // one by one: those built last if the values are unchanged (compared in place, so that an
  // unchanged key allocates nothing), else build()'s (and the workers' copies are dropped).
  template <class ForEachValue>
  std::shared_ptr<const RodEquations> equations(ForEachValue&& for_each_value, const Build& build) {
    size_t count = 0;
    bool same = equations_ != nullptr;
    for_each_value([&](double v) {
      same = same && count < key_.size() && key_[count] == v;
      ++count;
    });
    if (same && count == key_.size()) return equations_;
    key_.clear();
    for_each_value([&](double v) { key_.push_back(v); });
    equations_ = build();
    workers_.clear();
    return equations_;
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
  std::vector<double> key_;
  std::shared_ptr<const RodEquations> equations_;
  std::vector<std::shared_ptr<const RodEquations>> workers_;
  long rhs_evaluations_ = 0;
  Buffers buffers_;
};

}  // namespace kirchhoff

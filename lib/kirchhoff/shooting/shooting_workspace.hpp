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

namespace kirchhoff {

class ShootingWorkspace {
 public:
  using Build = std::function<std::shared_ptr<const RodEquations>()>;

  // The equations for the model parameters' values `key`: those built last if the key is
  // unchanged, else build()'s (and the workers' copies are dropped).
  std::shared_ptr<const RodEquations> equations(const std::vector<double>& key, const Build& build) {
    if (!equations_ || key != key_) {
      equations_ = build();
      key_ = key;
      workers_.clear();
    }
    return equations_;
  }

  // At least `count` copies of the equations for the extra worker threads (worker w >= 1 takes
  // copy w - 1; worker 0 uses equations()), built here, before the threads start: a thread's own
  // copy, as the equations are not shared between threads while they integrate.
  const std::vector<std::shared_ptr<const RodEquations>>& workers(int count, const Build& build) {
    while (static_cast<int>(workers_.size()) < count) workers_.push_back(build());
    return workers_;
  }

  void count_rhs(long evaluations) { rhs_evaluations_ += evaluations; }
  long rhs_evaluations() const { return rhs_evaluations_; }

 private:
  std::vector<double> key_;
  std::shared_ptr<const RodEquations> equations_;
  std::vector<std::shared_ptr<const RodEquations>> workers_;
  long rhs_evaluations_ = 0;
};

}  // namespace kirchhoff

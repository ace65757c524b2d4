// Following a rod with the continuation engine (continuation.hpp, which knows no rod): a rod's
// shooting problem becomes a ShootingSystem, its points are described by the rod layer's recorder
// (point_record.hpp) with the options below, and the rod's branches are switched: at a simple
// branch point along the null vector of [F_x F_lambda], at the double branch point of an
// isotropic twisted rod in the problem with the axial phase condition.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/continuation/shooting_system.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// What the rod layer's recorder computes at each point.
struct RodRecordOptions {
  int samples = 101;              // profile points for invariants and derived quantities
  bool compute_invariants = true;  // false skips sampling (derived quantities still need it)
  // The stability index of every point (stability.hpp): about one Jacobian's worth of
  // integration per point. Folds and branch points then show the exchange of stability.
  bool compute_stability = false;
  // The tolerance of the index's Jacobi fields at each point (StabilityOptions::field_tolerance;
  // 0: the state's). The index counts phase passages and compares singular values with 1e-6, so
  // fields to 1e-8 give the same indices and zero modes (stability_branch_test checks them along
  // branches against the state's tolerance), with fewer steps where the tolerance, not the
  // phases' turning, sets them (the Euler column: 560 right-hand sides per point, not 699).
  double stability_field_tolerance = 1e-8;

  std::string validate() const;
};

// The engine's options and the rod layer's: how points are recorded, and the tolerance of the
// march's matrices. Built from engine options alone (explicitly, so that no rod setting is lost
// by passing through a function that takes the engine's), the rod settings are the defaults.
struct RodContinuationOptions : ContinuationOptions, RodRecordOptions {
  RodContinuationOptions() = default;
  explicit RodContinuationOptions(ContinuationOptions engine) : ContinuationOptions(std::move(engine)) {}

  // The matrices [F_x F_lambda] of the march's steps (the correctors', and the tangents of the
  // regular points they reach) with the variational equations held to this tolerance
  // (IntegratorOptions::sensitivity_tol) instead of the state's: a chord or a tangent needs the
  // matrix to a few digits only, and every point is corrected on the exact residual (the state
  // keeps its tolerance). Located special points (branch points, folds, events, the end: their
  // correctors and their own matrices) keep the problem's own: their test functions reach 1e-12.
  // Not applied to problems with obstacles or contacts (their events and energy differences
  // follow Newton's last iterates to better than the looser matrices' 1e-9; docs/performance.md)
  // nor where the problem's own sensitivity_tol is already looser. 0: the problem's own everywhere.
  double march_sensitivity_tol = 1e-8;

  // The engine's groups, then the rod's.
  std::string validate() const;
};

// A continuation of a rod's shooting problem: the problem is copied, its value of
// options.parameter is the starting one. Without a recorder in the options its points are
// described by the rod layer's (rod_point_recorder, with the options' RodRecordOptions).
class RodContinuation : public Continuation {
 public:
  RodContinuation(const ShootingProblem& problem, const RodContinuationOptions& options);

  // The rod's shooting problem followed.
  const ShootingProblem& problem() const;
  // The right-hand sides its evaluations integrated so far: the problem's and those of the
  // march's looser twin (ShootingSystem), which problem() does not count.
  long rhs_evaluations() const;
};

// Branch switching at the double branch point of an isotropic twisted rod (the straight rod's
// first bifurcation, where the buckling modes form a circle). The bifurcating branch is followed
// in the same problem with add_axial_phase_condition; this gives that problem, the branch point
// in its unknowns (unfolding = 0) and the buckling direction satisfying the phase condition,
// ready for Continuation::run_along.
struct SymmetricBranchStart {
  ProblemDefinition definition;  // with the phase condition
  Eigen::VectorXd x;             // unknowns at the branch point
  double parameter = 0.0;
  Eigen::VectorXd direction;     // (dx, dlambda), unit
};
SymmetricBranchStart axial_symmetry_branch(RodContinuation& straight, const ContinuationPoint& branch_point,
                                           double sign = 1.0);

// The options the bifurcating branch is followed with (no target; it stops on the events,
// bounds or point count): also those a run resumed on that branch must use.
RodContinuationOptions bifurcating_branch_options(RodContinuationOptions options);

// Follows the branch bifurcating at `branch_point`, found by `run`: along the null vector of
// [F_x F_lambda] at a simple branch point, or, at the double branch point of a spatial rod, in the
// problem with the axial phase condition (axial_symmetry_branch), with
// bifurcating_branch_options(options). `sink_for` gives the sink for the new branch's points from
// the problem they belong to and whether the phase condition was added.
using BranchSinkFactory = std::function<PointSink(const ShootingProblem&, bool with_phase_condition)>;
ContinuationResult follow_bifurcating_branch(RodContinuation& run, const ContinuationPoint& branch_point,
                                             RodContinuationOptions options, double side,
                                             const BranchSinkFactory& sink_for);

}  // namespace kirchhoff

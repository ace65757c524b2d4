// Following a rod with the continuation engine: the engine's constructor for a rod's shooting
// problem (continuation.hpp; the problem becomes a ShootingSystem and its points are described by
// the rod layer's recorder) is defined here, beside the rod's branch switching: at a simple branch
// point along the null vector of [F_x F_lambda], at the double branch point of an isotropic
// twisted rod in the problem with the axial phase condition.
#pragma once

#include <functional>

#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/continuation/shooting_system.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

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
SymmetricBranchStart axial_symmetry_branch(Continuation& straight, const ContinuationPoint& branch_point,
                                           double sign = 1.0);

// The options the bifurcating branch is followed with (no target; it stops on the events,
// bounds or point count): also those a run resumed on that branch must use.
ContinuationOptions bifurcating_branch_options(ContinuationOptions options);

// Follows the branch bifurcating at `branch_point`, found by `run`: along the null vector of
// [F_x F_lambda] at a simple branch point, or, at the double branch point of a spatial rod, in the
// problem with the axial phase condition (axial_symmetry_branch), with
// bifurcating_branch_options(options). `sink_for` gives the sink for the new branch's points from
// the problem they belong to and whether the phase condition was added.
using BranchSinkFactory = std::function<PointSink(const ShootingProblem&, bool with_phase_condition)>;
ContinuationResult follow_bifurcating_branch(Continuation& run, const ContinuationPoint& branch_point,
                                             ContinuationOptions options, double side,
                                             const BranchSinkFactory& sink_for);

}  // namespace kirchhoff

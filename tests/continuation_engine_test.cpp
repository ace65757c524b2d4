// The continuation engine on systems that are not rods (ParameterisedSystem): its folds, branch
// points, switching, events and resume on algebraic problems whose branches are known in closed
// form, so that nothing of the shooting layer stands between the engine and the check.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>

#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/continuation/detail/broyden_steps.hpp"
#include "kirchhoff/continuation/detail/singular_point_index.hpp"

namespace kirchhoff {
namespace {

// F(x, lambda) for one unknown, with its two partial derivatives.
class ScalarSystem : public ParameterisedSystem {
 public:
  explicit ScalarSystem(double lambda0) : lambda0_(lambda0) {}
  int size() const override { return 1; }
  double parameter() const override { return lambda0_; }
  bool residual(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, std::string*) override {
    *F = Eigen::VectorXd::Constant(1, f(x[0], lambda));
    return true;
  }
  bool matrix(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, Eigen::MatrixXd* A, std::string* failure,
              bool) override {
    residual(x, lambda, F, failure);
    A->resize(1, 2);
    (*A) << f_x(x[0], lambda), f_lambda(x[0], lambda);
    return true;
  }

 protected:
  virtual double f(double x, double lambda) const = 0;
  virtual double f_x(double x, double lambda) const = 0;
  virtual double f_lambda(double x, double lambda) const = 0;

 private:
  double lambda0_;
};

// x^2 + lambda^2 = 1: one closed branch with folds at lambda = +1 and -1 (where x = 0).
class Circle final : public ScalarSystem {
 public:
  using ScalarSystem::ScalarSystem;

 private:
  double f(double x, double l) const override { return x * x + l * l - 1.0; }
  double f_x(double x, double) const override { return 2.0 * x; }
  double f_lambda(double, double l) const override { return 2.0 * l; }
};

// x (lambda - x^2) = 0: the trivial branch x = 0 and the parabola x^2 = lambda cross at a simple
// branch point at the origin (the pitchfork's normal form).
class Pitchfork final : public ScalarSystem {
 public:
  using ScalarSystem::ScalarSystem;

 private:
  double f(double x, double l) const override { return x * (l - x * x); }
  double f_x(double x, double l) const override { return l - 3.0 * x * x; }
  double f_lambda(double x, double) const override { return x; }
};

// x1 (lambda - 2 x1) = 0, x2 = x1^2: the trivial branch x = 0 and the line x1 = lambda / 2 cross
// transversally at the origin, not at right angles (a transcritical point).
class Transcritical final : public ParameterisedSystem {
 public:
  explicit Transcritical(double lambda0) : lambda0_(lambda0) {}
  int size() const override { return 2; }
  double parameter() const override { return lambda0_; }
  bool residual(const Eigen::VectorXd& x, double l, Eigen::VectorXd* F, std::string*) override {
    *F = Eigen::Vector2d(x[0] * (l - 2.0 * x[0]), x[1] - x[0] * x[0]);
    return true;
  }
  bool matrix(const Eigen::VectorXd& x, double l, Eigen::VectorXd* F, Eigen::MatrixXd* A, std::string* failure,
              bool) override {
    residual(x, l, F, failure);
    A->resize(2, 3);
    *A << l - 4.0 * x[0], 0.0, x[0], -2.0 * x[0], 1.0, 0.0;
    return true;
  }

 private:
  double lambda0_;
};

ContinuationOptions options_for(const char* parameter) {
  ContinuationOptions o;
  o.parameter = parameter;
  o.initial_step = 0.05;
  o.max_step = 0.1;
  return o;
}

const Eigen::VectorXd kNearOne = Eigen::VectorXd::Constant(1, 0.9);

// The corrector's tolerance is on max |F|: every point lies on its branch to it (1e-10, the
// engine's default for a system that names none).
constexpr double kOnBranch = 1e-10;

TEST(ContinuationEngine, FollowsACircleThroughBothFolds) {
  ContinuationOptions o = options_for("lambda");
  o.max_points = 100;  // one turn is 2 pi of arclength, at most 0.1 per step: ~63 points
  Continuation run(std::make_unique<Circle>(0.0), o);
  const ContinuationResult r = run.run(kNearOne);
  ASSERT_EQ(r.reason, StopReason::MaxPoints) << r.message;
  std::vector<double> folds;
  for (const auto& p : r.points) {
    EXPECT_LE(std::abs(p.x[0] * p.x[0] + p.parameter * p.parameter - 1.0), kOnBranch) << "point " << p.index;
    if (p.type == PointType::Fold) folds.push_back(p.parameter);
  }
  // Along +lambda from (x, lambda) = (1, 0): the fold at lambda = 1, then the one at -1. A fold is
  // located where the tangent's lambda component vanishes, i.e. x = 0 to the location's tolerance
  // t; lambda = sqrt(1 - x^2) is then 1 to t^2 / 2.
  ASSERT_GE(folds.size(), 2u);
  EXPECT_NEAR(folds[0], 1.0, 1e-9);
  EXPECT_NEAR(folds[1], -1.0, 1e-9);
  // Nothing of a rod is recorded: there is no recorder (and the engine has no rod to ask for:
  // RodContinuation, rod_continuation.hpp, is the one that follows a shooting problem).
  EXPECT_TRUE(r.points.front().derived.empty());
}

// A step that passes the target and a stopping event just beyond it finds both; the run ends at
// the target, which it reached: ReachedTarget, not the event's stop (a contact leg's homotopy, whose
// lift-off event lay past its target, reported "stopped (event)" at fraction 1).
TEST(ContinuationEngine, TargetReachedBeforeAStoppingEventInTheSameStepIsReached) {
  ContinuationOptions o = options_for("lambda");
  o.initial_step = 0.5;
  o.max_step = 0.5;
  o.target = 0.3;
  o.detect_folds = false;
  // On the circle from (x, lambda) = (1, 0): lambda = 0.3 at x = 0.954, lambda = 0.35 at x = 0.937.
  o.events.push_back({"x", 0.937, true, ""});
  o.recorder = PointRecorder{[](ParameterisedSystem&, ContinuationPoint* p) { p->derived["x"] = p->x[0]; }, {}};
  Continuation run(std::make_unique<Circle>(0.0), o);
  const ContinuationResult r = run.run(Eigen::VectorXd::Constant(1, 1.0));
  ASSERT_EQ(r.reason, StopReason::ReachedTarget) << r.message;
  EXPECT_EQ(r.points.back().type, PointType::Endpoint);
  // The end is corrected again at the target itself (ParameterValue::refine): lambda = 0.3 to round-off.
  EXPECT_NEAR(r.points.back().parameter, 0.3, 1e-12);
  // The step that reached the target (from lambda = 0.25: the tangent's turn limits the first
  // step) had the event inside it too; it is beyond the end and not on the branch.
  for (const auto& p : r.points) EXPECT_NE(p.type, PointType::Event) << "at lambda = " << p.parameter;
}

TEST(ContinuationEngine, FindsThePitchforkAndSwitchesOntoTheParabola) {
  ContinuationOptions o = options_for("lambda");
  o.target = 1.0;
  o.stop_at_branch_point = 1;
  Continuation trivial(std::make_unique<Pitchfork>(-1.0), o);
  const ContinuationResult r = trivial.run(Eigen::VectorXd::Constant(1, 0.1));
  ASSERT_EQ(r.reason, StopReason::BranchPointStop) << r.message;
  const ContinuationPoint& bp = r.points.back();
  ASSERT_EQ(bp.type, PointType::BranchPoint);
  // On the trivial branch the bordered matrix [lambda 0; 0 1] has the determinant lambda: located
  // by the secant to its zero, it stops within the corrector's tolerance of the origin.
  EXPECT_NEAR(bp.parameter, 0.0, 1e-9);
  EXPECT_NEAR(bp.x[0], 0.0, 1e-12);
  EXPECT_EQ(bp.multiplicity, 1);

  // Switching: [F_x F_lambda] vanishes at the origin, so the direction is the one orthogonal to the
  // trivial branch's tangent, dx, with a positive first component: the upper half x = +sqrt(lambda).
  // An event on x, recorded by a recorder of this system, stops it at x = 0.5, lambda = 0.25.
  ContinuationOptions b = options_for("lambda");
  b.events = {{"x", 0.5, true, ""}};
  PointRecorder recorder;
  recorder.describe = [](ParameterisedSystem&, ContinuationPoint* p) { p->derived["x"] = p->x[0]; };
  b.recorder = recorder;
  Continuation parabola(std::make_unique<Pitchfork>(bp.parameter), b);
  const ContinuationResult s = parabola.switch_branch(bp);
  ASSERT_EQ(s.reason, StopReason::EventStop) << s.message;
  for (size_t i = 1; i < s.points.size(); ++i) {
    const ContinuationPoint& p = s.points[i];
    EXPECT_GT(p.x[0], 0.0) << "point " << p.index;
    // |F| = x |lambda - x^2| <= tolerance, and x is O(0.1-1) here.
    EXPECT_NEAR(p.parameter, p.x[0] * p.x[0], 1e-8) << "point " << p.index;
  }
  EXPECT_EQ(s.points.back().type, PointType::Event);
  EXPECT_NEAR(s.points.back().x[0], 0.5, 1e-9);
  EXPECT_NEAR(s.points.back().parameter, 0.25, 1e-8);
}

// At a transcritical point the branch switched onto leaves along its own tangent,
// (dx1, dx2, dlambda) = (1, 0, 2) / sqrt(5), from the algebraic bifurcation equation: not along the
// null vector orthogonal to the trivial branch's tangent (1, 0, 0), which is no branch's.
TEST(ContinuationEngine, SwitchesAtATranscriticalPointAlongTheOtherBranchsTangent) {
  ContinuationOptions o = options_for("lambda");
  o.target = 1.0;
  o.stop_at_branch_point = 1;
  Continuation trivial(std::make_unique<Transcritical>(-1.0), o);
  const ContinuationResult r = trivial.run(Eigen::Vector2d(0.05, 0.0));
  ASSERT_EQ(r.reason, StopReason::BranchPointStop) << r.message;
  const ContinuationPoint& bp = r.points.back();
  ASSERT_EQ(bp.type, PointType::BranchPoint);
  EXPECT_NEAR(bp.parameter, 0.0, 1e-9);
  // The branch point's tangent is the trivial branch's, (0, 0, 1): the second differences of F
  // (steps 1e-3) are exact on this quadratic F up to round-off, ~1e-16 / 1e-6.
  EXPECT_NEAR(std::abs(bp.tangent[2]), 1.0, 1e-8);

  Continuation other(std::make_unique<Transcritical>(bp.parameter), options_for("lambda"));
  const Eigen::MatrixXd d = other.bifurcation_directions(bp, 1);
  const Eigen::Vector3d expected = Eigen::Vector3d(1.0, 0.0, 2.0) / std::sqrt(5.0);
  EXPECT_NEAR(std::abs(d.col(0).dot(expected)), 1.0, 1e-8) << d.transpose();
  o = options_for("lambda");
  o.max_points = 20;
  Continuation line(std::make_unique<Transcritical>(bp.parameter), o);
  const ContinuationResult s = line.switch_branch(bp);
  ASSERT_GE(s.points.size(), 5u);
  for (size_t i = 1; i < s.points.size(); ++i) {
    const ContinuationPoint& p = s.points[i];
    EXPECT_NEAR(p.x[0], 0.5 * p.parameter, kOnBranch) << "point " << p.index;
    EXPECT_GT(std::abs(p.x[0]), 1e-3) << "point " << p.index;
  }
}

// A march resumed from its state at one of its points takes the same steps as the uninterrupted
// one, bit for bit (MarchState), for any system, with or without branch-point detection: the
// point before the saved one serves the quadratic predictor either way (without it the resumed
// run's first step is predicted from the tangent alone and lands on other bits).
void expect_resumed_march_repeats_the_uninterrupted_one(bool detect_branch_points) {
  ContinuationOptions o = options_for("lambda");
  o.max_points = 40;
  o.detect_branch_points = detect_branch_points;
  std::vector<MarchState> states;
  o.on_resumable = [&](const MarchState& s) { states.push_back(s); };
  Continuation whole(std::make_unique<Circle>(0.0), o);
  const ContinuationResult r = whole.run(kNearOne);
  ASSERT_GE(states.size(), 10u);
  const MarchState middle = states[8];

  ContinuationOptions quiet = o;
  quiet.on_resumable = nullptr;
  Continuation resumed(std::make_unique<Circle>(0.0), quiet);
  const ContinuationResult rest = resumed.resume(middle);
  // The resumed run's points are those after `middle.current` in the whole run.
  size_t k = 0;
  while (k < r.points.size() && r.points[k].index != middle.current.index) ++k;
  ASSERT_LT(k, r.points.size());
  ASSERT_EQ(rest.points.size(), r.points.size() - k - 1);
  for (size_t i = 0; i < rest.points.size(); ++i) {
    const ContinuationPoint& a = r.points[k + 1 + i];
    const ContinuationPoint& b = rest.points[i];
    EXPECT_EQ(a.type, b.type);
    EXPECT_EQ(a.parameter, b.parameter) << "point " << a.index;
    EXPECT_EQ(a.x[0], b.x[0]) << "point " << a.index;
  }
}

TEST(ContinuationEngine, ResumedMarchRepeatsTheUninterruptedOne) {
  expect_resumed_march_repeats_the_uninterrupted_one(true);
}

TEST(ContinuationEngine, ResumedMarchWithoutBranchPointsRepeatsTheUninterruptedOne) {
  expect_resumed_march_repeats_the_uninterrupted_one(false);
}

// The quadratic predictor (the default) against the tangent alone, on the circle at a fixed
// step h = 0.1: the tangent's prediction lies h^2 / 2 = 5e-3 off the circle, the quadratic one's
// O(h^3) (its curvature is estimated from the last two tangents), so the correctors need fewer
// iterations in all; both runs' points lie on the circle.
TEST(ContinuationEngine, QuadraticPredictorNeedsFewerCorrectorIterations) {
  auto total_iterations = [](StepControl::Predictor predictor) {
    ContinuationOptions o = options_for("lambda");
    o.initial_step = o.max_step = 0.1;
    o.max_points = 50;
    o.predictor = predictor;
    Continuation run(std::make_unique<Circle>(0.0), o);
    const ContinuationResult r = run.run(kNearOne);
    EXPECT_EQ(r.reason, StopReason::MaxPoints) << r.message;
    int sum = 0;
    for (const auto& p : r.points) {
      EXPECT_LE(std::abs(p.x[0] * p.x[0] + p.parameter * p.parameter - 1.0), kOnBranch) << "point " << p.index;
      if (p.type == PointType::Regular) sum += p.newton_iterations;
    }
    return sum;
  };
  const int tangent = total_iterations(StepControl::Predictor::Tangent);
  const int quadratic = total_iterations(StepControl::Predictor::Quadratic);
  EXPECT_LT(quadratic, tangent);
  std::cout << "corrector iterations on 50 points: tangent " << tangent << ", quadratic " << quadratic << "\n";
}

// Broyden's updates of a chord matrix B0 != A on a linear system A z = b: by Gay's theorem
// (D. M. Gay, SIAM J. Numer. Anal. 16, 1979) the iterates reach the solution in at most 2n steps
// in exact arithmetic, whatever B0; here to round-off (1e-12 of the first residual). The chord
// on B0 alone contracts by the spectral radius of I - B0^-1 A, 0.5 (its 2-norm 0.51), per step:
// 0.5^8 = 3.9e-3 of the first residual after 2n steps, above the 1e-3 checked, so the test would
// fail on plain chord steps.
PointRecord counted(std::optional<int> index, int zero_modes) {
  PointRecord r;
  r.stability_index = index;
  r.zero_modes = zero_modes;
  return r;
}

// A fold or branch point between regular points of indices a and b has index min(a, b) and the
// |a - b| crossing eigenvalues among its zero modes, where its own count lies between a and b or
// its zero modes beyond its neighbours' explain the change (|a - b| of them: a simple and a double
// crossing, with a symmetry's zero mode on both sides); it is made undefined where neither holds; an
// undefined count, here or at a neighbour, is left as it is, and so is the count between equal
// neighbours where it has a zero mode beyond theirs (made undefined where it has not).
TEST(SingularPointIndex, IsTheNeighboursLowerIndexWhereTheZeroModesExplainTheChange) {
  auto settled = [](PointRecord p, const PointRecord& a, const PointRecord& b) {
    detail::settle_singular_point_index(&p, a, b);
    return p.stability_index;
  };
  auto zero_modes = [](PointRecord p, const PointRecord& a, const PointRecord& b) {
    detail::settle_singular_point_index(&p, a, b);
    return p.zero_modes;
  };
  // The crossing eigenvalue decisively positive at the located point (the soft wall's branch point
  // with its fields at the state's tolerance; clamped_clamped.toml's where the ends meet): the row
  // still has it as its zero mode.
  EXPECT_EQ(settled(counted(0, 0), counted(0, 0), counted(1, 0)), 0);
  EXPECT_EQ(zero_modes(counted(0, 0), counted(0, 0), counted(1, 0)), 1);
  EXPECT_EQ(settled(counted(1, 0), counted(0, 0), counted(1, 0)), 0);  // or negative
  EXPECT_EQ(zero_modes(counted(1, 0), counted(0, 0), counted(1, 0)), 1);
  EXPECT_EQ(zero_modes(counted(2, 1), counted(1, 1), counted(2, 1)), 2);  // beside a symmetry's zero mode
  EXPECT_EQ(zero_modes(counted(0, 1), counted(0, 0), counted(0, 0)), 1);  // equal neighbours: its own
  EXPECT_EQ(settled(counted(0, 1), counted(0, 0), counted(1, 0)), 0);
  EXPECT_EQ(settled(counted(2, 1), counted(0, 0), counted(1, 0)), 0);  // the soft wall's branch point
  EXPECT_EQ(settled(counted(2, 1), counted(1, 0), counted(0, 0)), 0);  // the same, walked the other way
  EXPECT_EQ(settled(counted(1, 2), counted(0, 0), counted(2, 0)), 0);  // a double branch point
  EXPECT_EQ(settled(counted(3, 2), counted(1, 1), counted(2, 1)), 1);  // beside a symmetry's zero mode
  EXPECT_EQ(settled(counted(1, 1), counted(1, 1), counted(2, 1)), 1);  // agrees
  EXPECT_EQ(settled(counted(0, 1), counted(1, 0), counted(1, 0)), 0);  // no change: an eigenvalue touching zero from below
  // No change and no zero mode of its own: the touching eigenvalue was taken for one sign, which
  // may be wrong either way (the soft wall's branch point revisited: 1 and none, where it is 0
  // with one). Undefined, with the zero mode every singular point has.
  EXPECT_EQ(settled(counted(1, 0), counted(1, 0), counted(1, 0)), std::nullopt);
  EXPECT_EQ(zero_modes(counted(1, 0), counted(1, 0), counted(1, 0)), 1);
  EXPECT_EQ(settled(counted(0, 1), counted(0, 1), counted(0, 1)), std::nullopt);  // beside a symmetry's
  EXPECT_EQ(zero_modes(counted(0, 1), counted(0, 1), counted(0, 1)), 2);
  EXPECT_EQ(settled(counted(2, 0), counted(0, 0), counted(1, 0)), std::nullopt);  // no zero mode to explain it
  EXPECT_EQ(settled(counted(1, 2), counted(0, 1), counted(2, 1)), 0);  // of two crossing, one negative, one zero
  EXPECT_EQ(zero_modes(counted(1, 2), counted(0, 1), counted(2, 1)), 3);
  EXPECT_EQ(settled(counted(3, 0), counted(0, 1), counted(2, 1)), std::nullopt);  // past both, no zero mode
  // Its own count undefined (degenerate exactly there: the clamped column where its ends meet,
  // from a probe): the neighbours settle it where they differ, not where they agree.
  EXPECT_EQ(settled(counted(std::nullopt, 0), counted(0, 0), counted(1, 0)), 0);
  EXPECT_EQ(zero_modes(counted(std::nullopt, 0), counted(0, 0), counted(1, 0)), 1);
  EXPECT_EQ(settled(counted(std::nullopt, 0), counted(3, 1), counted(1, 1)), 1);
  EXPECT_EQ(zero_modes(counted(std::nullopt, 0), counted(3, 1), counted(1, 1)), 3);
  EXPECT_EQ(settled(counted(std::nullopt, 0), counted(1, 0), counted(1, 0)), std::nullopt);
  EXPECT_EQ(settled(counted(2, 1), counted(std::nullopt, 0), counted(1, 0)), 2);
  // The reason goes with an empty index only: settled, the degenerate count's reason is cleared (a
  // probe: the run's note said row 138 of the clamped column had no index where its CSV row had
  // 0); made empty here, the row gets one.
  auto reason = [](PointRecord p, const PointRecord& a, const PointRecord& b) {
    detail::settle_singular_point_index(&p, a, b);
    return p.stability_reason;
  };
  PointRecord degenerate = counted(std::nullopt, 0);
  degenerate.stability_reason = "a degenerate constraint";
  EXPECT_EQ(reason(degenerate, counted(0, 0), counted(1, 0)), "");
  EXPECT_EQ(reason(degenerate, counted(1, 0), counted(1, 0)), "a degenerate constraint");
  EXPECT_NE(reason(counted(1, 0), counted(1, 0), counted(1, 0)), "");
  EXPECT_NE(reason(counted(2, 0), counted(0, 0), counted(1, 0)), "");
}

TEST(BroydenSteps, SolveALinearSystemInAtMostTwiceItsSizeSteps) {
  constexpr int n = 4;
  Eigen::Matrix4d A;
  A << 4, 1, 0, 0.5,  //
      1, 3, 1, 0,     //
      0, 1, 5, 1,     //
      0.5, 0, 1, 2;
  const Eigen::Vector4d b(1.0, -2.0, 0.5, 3.0);
  Eigen::Matrix4d B0 = 2.0 * A;  // I - B0^-1 A = I / 2
  B0(0, 1) += 0.3;               // and not a multiple of A
  const Eigen::PartialPivLU<Eigen::Matrix4d> lu(B0);
  auto residual_after = [&](bool broyden_updates) {
    detail::BroydenSteps broyden;
    Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
    for (int k = 0; k < 2 * n; ++k) {
      if ((A * z - b).norm() <= 1e-13 * b.norm()) break;  // solved (a zero step would not update)
      const Eigen::VectorXd chord = -lu.solve(A * z - b);
      if (!broyden_updates) {
        z += chord;
        continue;
      }
      const std::optional<Eigen::VectorXd> step = broyden.next(chord);
      if (!step) return std::numeric_limits<double>::infinity();  // a degenerate update: not expected on this system
      z += *step;
    }
    return (A * z - b).norm() / b.norm();
  };
  EXPECT_LT(residual_after(true), 1e-12);
  EXPECT_GT(residual_after(false), 1e-3);
}

TEST(ContinuationEngine, RefusesNoSystemAndAStartThatDoesNotConverge) {
  EXPECT_THROW(Continuation(std::unique_ptr<ParameterisedSystem>{}, options_for("lambda")), std::invalid_argument);
  // No real x solves x^2 + lambda^2 = 1 at lambda = 2: Newton's iterates wander, and the run says so.
  Continuation outside(std::make_unique<Circle>(2.0), options_for("lambda"));
  const ContinuationResult r = outside.run(kNearOne);
  EXPECT_EQ(r.reason, StopReason::StartFailed);
  EXPECT_NE(r.message.find("does not converge at lambda = 2"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace kirchhoff

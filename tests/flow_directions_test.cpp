// RodEquations::flow_directions: given directions carried by the variational equations, in one
// integration continued across adjacent intervals, are Phi directions.
#include <Eigen/Geometry>

#include "kirchhoff/equations/rod_equations.hpp"
#include <gtest/gtest.h>

namespace kirchhoff {
namespace {

// Both sides integrate at 1e-12 per step with RK78 but with different steps (one interval against
// five, different dual sizes): they differ by at most 1.3e-12 on these cases (1e-13 of the
// entries' size); 1e-10 leaves a margin while a wrong column (a seed left out, a padded column
// leaking in) is O(1).
constexpr double kSameFlowTolerance = 1e-10;

RodModel curved_rod(bool with_field) {
  RodModel m;
  m.length = 1.2;
  m.B = {Profile(1.0), Profile(1.5), Profile(0.8)};
  m.u_hat = {Profile(0.3), Profile(0.8), Profile(0.1)};
  if (with_field) m.field = std::make_shared<UniformGravity>(2.5, Vec3::UnitY());
  return m;
}

RodPoint start_point(bool planar) {
  RodPoint p;
  p.r = Vec3(0.1, -0.2, 0.0);
  p.R = Eigen::AngleAxisd(0.7, Vec3::UnitZ()).toRotationMatrix() * planar_reference_frame();
  p.n = Vec3(-3.0, 1.5, planar ? 0.0 : 0.4);
  p.m = Vec3(planar ? 0.0 : 0.2, planar ? 0.0 : -0.3, 0.4);
  return p;
}

// Compares, for `columns` random directions, five carried intervals against Phi over the rod
// (the reference equations' Phi when given: the same rod computed another way).
void expect_phi_directions(const RodEquations& eq, const RodPoint& p, int columns,
                           const RodEquations* reference = nullptr) {
  IntegratorOptions options;
  options.closed_form = false;  // (the march's carried steps; the closed form's fields: stability_test)
  const double L = eq.model().length;
  const Eigen::VectorXd y0 = eq.state(p);
  const Eigen::MatrixXd D = Eigen::MatrixXd::Random(eq.state_size(), columns);
  const SegmentFlow whole = (reference ? *reference : eq).flow(y0, 0.0, L, true, options);
  CarriedSteps carried;
  DirectionalFlow flow{y0, D};
  for (int i = 0; i < 5; ++i) {
    const DirectionalFlow next = eq.flow_directions(flow.y, flow.directions, L * i / 5, L * (i + 1) / 5, options, &carried);
    EXPECT_GT(carried.directions, 0.0);
    flow = next;
  }
  const Eigen::MatrixXd expected = whole.Phi * D;
  ASSERT_EQ(flow.directions.cols(), columns);
  EXPECT_LT((flow.directions - expected).norm(), kSameFlowTolerance * (1.0 + expected.norm()))
      << (eq.is_planar() ? "planar" : "spatial") << ", " << columns << " columns";
  EXPECT_LT((flow.y - whole.y).norm(), kSameFlowTolerance * (1.0 + whole.y.norm()));
}

TEST(FlowDirections, ArePhiTimesTheDirectionsForEveryDualSize) {
  for (bool with_field : {false, true}) {
    const RodModel model = curved_rod(with_field);
    // Planar: 1..6 columns (carried themselves below the 4 or 6 seeds, through Phi from there).
    const auto planar = make_planar_equations(model);
    for (int k = 1; k <= 7; ++k) expect_phi_directions(*planar, start_point(true), k);
    // Spatial: the sizes compiled (3, 4, 5, 6, 8, 10, 13), padded ones, and more than the seeds.
    const auto spatial = make_spatial_equations(model);
    for (int k : {2, 3, 5, 7, 9, 11, 14}) expect_phi_directions(*spatial, start_point(false), k);
  }
}

// Without a field the spatial rod's matrices and directions follow its variational equations
// written out (spatial_variations.hpp). The reference is the same rod with a field that exerts no
// force, whose equations keep the dual numbers: on an extensible, shearable rod with an unfolding
// couple every term of the written-out equations acts (the force directions through the stretch,
// the couple's mu dR e3), and both ways must give the same Phi and directions to round-off.
TEST(FlowDirections, WrittenOutSpatialVariationsAgreeWithTheDualNumbers) {
  RodModel model = curved_rod(false);
  model.extensible = true;
  model.A = {Profile(20.0), Profile(30.0), Profile(40.0)};
  model.v_hat = {Profile(0.02), Profile(-0.01), Profile(1.05)};
  model.symmetry_unfolding = 0.3;
  RodModel with_dual_numbers = model;
  with_dual_numbers.field = std::make_shared<UniformGravity>(0.0, Vec3::UnitY());
  const auto written_out = make_spatial_equations(model);
  const auto reference = make_spatial_equations(with_dual_numbers);
  const IntegratorOptions options;
  const Eigen::VectorXd y0 = written_out->state(start_point(false));
  const Eigen::MatrixXd Phi = written_out->flow(y0, 0.0, model.length, true, options).Phi;
  const Eigen::MatrixXd expected = reference->flow(y0, 0.0, model.length, true, options).Phi;
  EXPECT_LT((Phi - expected).norm(), kSameFlowTolerance * (1.0 + expected.norm())) << Phi - expected;
  for (int k : {2, 3, 5, 7, 9, 11, 14}) expect_phi_directions(*written_out, start_point(false), k, reference.get());
}

// With sensitivity_tol looser than the state's, the state comes from a pass of its own at the
// state's tolerance (as flow() does it) and the directions at the looser one.
TEST(FlowDirections, LooseSensitivitiesKeepTheStateTight) {
  const auto eq = make_spatial_equations(curved_rod(false));
  IntegratorOptions options, loose;
  loose.sensitivity_tol = 1e-8;
  const Eigen::VectorXd y0 = eq->state(start_point(false));
  const Eigen::MatrixXd D = Eigen::MatrixXd::Identity(14, 14).middleCols(3, 5);
  CarriedSteps carried, loose_carried;
  const DirectionalFlow tight = eq->flow_directions(y0, D, 0.0, 1.2, options, &carried);
  const DirectionalFlow coarse = eq->flow_directions(y0, D, 0.0, 1.2, loose, &loose_carried);
  EXPECT_GT(loose_carried.state, 0.0);
  // The state: the same 1e-12 integration both times (the dual pass's state is not used).
  EXPECT_LT((coarse.y - tight.y).norm(), kSameFlowTolerance);
  // The directions: to ~1e-8 per step, not to the state's 1e-12; 1e-6 of their size bounds the
  // difference over a unit rod while a direction integrated wrongly would be O(1).
  EXPECT_LT((coarse.directions - tight.directions).norm(), 1e-6 * tight.directions.norm());
  EXPECT_GT((coarse.directions - tight.directions).norm(), 0.0);
}

// Handing the proposed step on makes the pieces one integration: fewer right-hand sides than
// restarting each piece from a small trial step (IntegratorOptions::initial_step), the same end.
TEST(FlowDirections, CarriedStepsSaveTheRestarts) {
  const auto eq = make_planar_equations(curved_rod(false));
  IntegratorOptions options;
  options.closed_form = false;  // (a march's steps: a closed-form flow has none to carry)
  const Eigen::VectorXd y0 = eq->state(start_point(true));
  const Eigen::MatrixXd D = Eigen::MatrixXd::Identity(6, 6).leftCols(2);
  const int pieces = 16;
  long carried_rhs = 0, restarted_rhs = 0;
  CarriedSteps carried;
  DirectionalFlow a{y0, D}, b{y0, D};
  for (int i = 0; i < pieces; ++i) {
    const double s0 = 1.2 * i / pieces, s1 = 1.2 * (i + 1) / pieces;
    a = eq->flow_directions(a.y, a.directions, s0, s1, options, &carried);
    CarriedSteps fresh;
    b = eq->flow_directions(b.y, b.directions, s0, s1, options, &fresh);
    carried_rhs += a.rhs_evaluations;
    restarted_rhs += b.rhs_evaluations;
  }
  // Restarting ramps up over ~3 steps of each piece (x5 per step from 1e-2 of it); carried, one
  // step per piece suffices on this smooth rod.
  EXPECT_LT(2 * carried_rhs, restarted_rhs);
  EXPECT_LT((a.directions - b.directions).norm(), kSameFlowTolerance);
}

}  // namespace
}  // namespace kirchhoff

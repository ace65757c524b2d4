// The planar Elastica is the 3D core restricted to the plane: same flow, same solutions.
#include <Eigen/Geometry>

#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/equations/rod_equations.hpp"
#include "kirchhoff/shooting/shooting.hpp"
#include <gtest/gtest.h>

namespace kirchhoff {
namespace {

// Both integrate at 1e-12 per step with RK78; over a unit rod the two independent
// integrations differ by a few 1e-12. The 1e-10 bounds it with margin.
constexpr double kSameRodTolerance = 1e-10;

RodModel extensible_heavy_rod() {
  RodModel m;
  m.length = 1.3;
  m.B = {Profile(2.0), Profile([](double s) { return 1.0 + 0.5 * s; }), Profile(0.7)};
  m.extensible = true;
  m.A = {Profile(40.0), Profile(60.0), Profile(80.0)};
  m.u_hat = {Profile(0.0), Profile(0.8), Profile(0.0)};
  m.v_hat = {Profile(0.05), Profile(0.0), Profile(1.0)};  // natural shear in the plane (d1)
  m.field = std::make_shared<UniformGravity>(2.5, Vec3::UnitY());
  return m;
}

TEST(PlanarRestriction, FlowEqualsSpatialFlow) {
  const RodModel model = extensible_heavy_rod();
  const auto planar = make_planar_equations(model);
  const auto spatial = make_spatial_equations(model);
  RodPoint p;
  p.r = Vec3(0.1, -0.2, 0.0);
  p.R = Eigen::AngleAxisd(0.7, Vec3::UnitZ()).toRotationMatrix() * planar_reference_frame();
  p.n = Vec3(-3.0, 1.5, 0.0);
  p.m = Vec3(0.0, 0.0, 0.4);
  const IntegratorOptions options;
  const auto a = planar->flow(planar->state(p), 0.0, model.length, false, options);
  const auto b = spatial->flow(spatial->state(p), 0.0, model.length, false, options);
  const RodPoint pa = planar->point(a.y, model.length), pb = spatial->point(b.y, model.length);
  EXPECT_LE((pa.r - pb.r).norm(), kSameRodTolerance);
  EXPECT_LE((pa.R - pb.R).norm(), kSameRodTolerance);
  EXPECT_LE((pa.n - pb.n).norm(), kSameRodTolerance);
  EXPECT_LE((pa.m - pb.m).norm(), kSameRodTolerance);
  EXPECT_LE((pa.u - pb.u).norm(), kSameRodTolerance);
  // The 3D solution stays in the plane exactly.
  EXPECT_LE(std::abs(pb.r.z()) + std::abs(pb.R(2, 1) - 1.0), kSameRodTolerance);
}

// A clamped-roller Elastica (slope imposed at s = 0, end sliding along x under -P e_x), solved
// once with the planar equations and once with the 3D core.
ProblemDefinition clamped_roller(RodKind kind) {
  ProblemDefinition d;
  d.kind = kind;
  d.model = [](const Parameters&) {
    RodModel m;
    m.B = {Profile(1.0), Profile(1.0), Profile(1.0)};
    return m;
  };
  d.parameters.set("P", 25.0);
  const Mat3 R0 = Eigen::AngleAxisd(0.9, Vec3::UnitZ()).toRotationMatrix() * planar_reference_frame();
  const Eigen::AngleAxisd frame(R0);
  const OrientationTarget target = kind == RodKind::Planar ? OrientationTarget{Vec3::UnitZ(), 0.9}
                                                           : OrientationTarget{frame.axis(), frame.angle()};
  d.start = EndCondition::clamped(constant(Vec3::Zero()), constant_orientation(target));
  d.end = EndCondition::sliding(Vec3::UnitX(), constant(Vec3::Zero()),
                                [](const Parameters& p) { return Vec3(-p["P"], 0.0, 0.0); });
  // Converge far below the comparison tolerance so that the two solutions differ only by
  // their integration error, not by where each Newton happened to stop.
  d.options.newton.residual_tolerance = 1e-11;  // the 3D residual bottoms out near 1e-12
  return d;
}

TEST(PlanarRestriction, SolutionEqualsSpatialSolution) {
  std::vector<Solution> solutions;
  for (RodKind kind : {RodKind::Planar, RodKind::Spatial}) {
    const ShootingProblem problem(clamped_roller(kind));
    RodPoint guess;
    guess.R = Eigen::AngleAxisd(0.9, Vec3::UnitZ()).toRotationMatrix() * planar_reference_frame();
    guess.n = Vec3(-25.0, 0.0, 0.0);
    ShootingResult r = solve(problem, problem.initial_unknowns(guess));
    ASSERT_TRUE(r.summary.converged()) << r.summary.brief_report();
    solutions.push_back(make_solution(problem, std::move(r), 51, {}));
  }
  for (size_t i = 0; i < solutions[0].profile.size(); ++i) {
    const RodPoint& a = solutions[0].profile[i];
    const RodPoint& b = solutions[1].profile[i];
    ASSERT_LE((a.r - b.r).norm(), kSameRodTolerance) << "s = " << a.s;
    ASSERT_LE((a.R - b.R).norm(), kSameRodTolerance) << "s = " << a.s;
    ASSERT_LE((a.n - b.n).norm(), kSameRodTolerance) << "s = " << a.s;
    ASSERT_LE((a.m - b.m).norm(), kSameRodTolerance) << "s = " << a.s;
  }
}

}  // namespace
}  // namespace kirchhoff

// RodEquations::state_beside: a guess's node whose frame leaves its state's representation to
// round-off takes the one its neighbour continues. A spatial frame turned by pi about e3 (the
// plectoneme's clamp at -pi * turns, odd turns) has quaternion +-(0, 0, 0, 1): state() chooses
// by the sign of a q0 of round-off, and a first node of the other sign from its second put a hard
// ply's seed a segment's quaternion and a turn of chi from any solution.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "kirchhoff/equations/detail/spatial_state.hpp"
#include "kirchhoff/equations/rod_equations.hpp"

namespace kirchhoff {
namespace {

using detail::kChi;
using detail::kQ;

RodPoint frame_turned_about_e3(double angle) {
  RodPoint p;
  p.R = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  return p;
}

TEST(StateBeside, QuaternionAtRoundOffFollowsTheNeighbour) {
  const auto eq = make_spatial_equations(RodModel{});
  // Turned by pi +- 1e-13: q0 = -+5e-14, the two sides of the cut.
  for (const double angle : {M_PI - 1e-13, M_PI + 1e-13}) {
    const RodPoint p = frame_turned_about_e3(angle);
    // The neighbour, turned a little less (as the node after a clamp at -pi): q3 of one sign.
    for (const double side : {1.0, -1.0}) {
      Eigen::VectorXd neighbour = eq->state(frame_turned_about_e3(M_PI - 0.3));
      neighbour.segment<4>(kQ) *= side;
      const Eigen::VectorXd y = eq->state_beside(p, neighbour);
      EXPECT_GT(y.segment<4>(kQ).dot(neighbour.segment<4>(kQ)), 0.9) << angle << " " << side;
      // chi is the quaternion's angle: +-pi by the sign chosen, within round-off.
      EXPECT_NEAR(std::abs(y[kChi]), M_PI, 1e-12);
      EXPECT_NEAR(y[kChi], 2.0 * std::atan2(y[kQ + 3], y[kQ]), 1e-15);
      // The same frame either way.
      EXPECT_LE((eq->point(y, 0.0).R - p.R).cwiseAbs().maxCoeff(), 1e-12);
    }
  }
}

// Away from the cut the state keeps its own representation (q0 >= 0), whatever the neighbour.
TEST(StateBeside, QuaternionAwayFromTheCutIsStatesOwn) {
  const auto eq = make_spatial_equations(RodModel{});
  const RodPoint p = frame_turned_about_e3(2.0);
  Eigen::VectorXd neighbour = eq->state(frame_turned_about_e3(2.1));
  neighbour.segment<4>(kQ) *= -1.0;
  EXPECT_EQ(eq->state_beside(p, neighbour), eq->state(p));
}

}  // namespace
}  // namespace kirchhoff

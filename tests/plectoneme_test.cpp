// Self-contact by the half-turn symmetry (self_contact.hpp) and the symmetric plectoneme case
// (cases/plectoneme.toml, section 7.6, eqs. 58-61).
#include <gtest/gtest.h>

#include <cmath>

#include "kirchhoff/analytic.hpp"
#include "kirchhoff/integrator.hpp"
#include "kirchhoff/plectoneme.hpp"
#include "kirchhoff/self_contact.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

HalfTurnSelfContactOptions contact_options() {
  HalfTurnSelfContactOptions o;
  o.radius = 0.01;
  o.axis = Vec3(1.0, 0.0, 0.0);
  o.symmetry_s = 0.5;
  o.strength = 1e-6;
  o.range = 0.0025;
  o.adjacent = 0.02;
  return o;
}

// The force is minus the gradient of the potential and its gradient is the Jacobian the
// variational equations use: central differences (step 1e-7 on lengths ~1e-3, so truncation
// ~1e-14 and round-off ~1e-16 * |V| / 1e-7) agree to 1e-6 relative.
TEST(HalfTurnSelfContact, ForceIsMinusGradientOfPotential) {
  const HalfTurnSelfContact contact(contact_options());
  const double s = 0.3;
  for (const Vec3& r : {Vec3(0.1, 0.0105, 0.0), Vec3(0.2, 0.008, 0.0071), Vec3(-0.05, -0.0009, 0.0112)}) {
    const Vec3 f = contact.force(s, r);
    const Mat3 G = contact.force_gradient(s, r);
    const double h = 1e-7;
    for (int i = 0; i < 3; ++i) {
      Vec3 e = Vec3::Zero();
      e[i] = h;
      const double dV = (contact.potential(s, r + e) - contact.potential(s, r - e)) / (2 * h);
      EXPECT_NEAR(f[i], -dV, 1e-6 * f.norm()) << "component " << i;
      const Vec3 df = (contact.force(s, r + e) - contact.force(s, r - e)) / (2 * h);
      EXPECT_LT((G.col(i) - df).norm(), 1e-6 * G.norm()) << "column " << i;
    }
    // Repulsive, across the axis, away from it.
    EXPECT_NEAR(f.x(), 0.0, 1e-15 * f.norm());
    EXPECT_GT(f.dot(Vec3(0.0, r.y(), r.z())), 0.0);
  }
}

TEST(HalfTurnSelfContact, ImageDistanceAndSwitchOff) {
  const HalfTurnSelfContact contact(contact_options());
  const Vec3 r(0.3, 0.004, -0.012);
  EXPECT_NEAR((r - contact.image(r)).norm(), 2.0 * contact.distance_to_axis(r), 1e-16);
  EXPECT_EQ(contact.weight(0.0), 1.0);
  EXPECT_EQ(contact.weight(0.5 - 0.04), 1.0);
  EXPECT_EQ(contact.weight(0.5 - 0.02), 0.0);
  EXPECT_GT(contact.weight(0.47), 0.0);
  EXPECT_LT(contact.weight(0.47), 1.0);
  EXPECT_EQ(contact.potential(0.49, Vec3(0.3, 0.0, 0.0)), 0.0);  // the end loop crosses the axis freely
  EXPECT_TRUE(std::isnan(contact.gap(0.49, r)));
  EXPECT_THROW(contact.force(0.1, Vec3(0.3, 0.0, 0.005)), IntegrationError);  // inside the other strand
}

TEST(HalfTurnSelfContact, RefusesNonPhysicalOptions) {
  auto o = contact_options();
  o.radius = -1.0;
  EXPECT_THROW(HalfTurnSelfContact{o}, std::invalid_argument);
  o = contact_options();
  o.strength = 0.0;
  EXPECT_THROW(HalfTurnSelfContact{o}, std::invalid_argument);
  o = contact_options();
  o.adjacent = 0.3;  // longer than half the half rod
  EXPECT_THROW(HalfTurnSelfContact{o}, std::invalid_argument);
}

// Untwisted, the half rod with a half-turn end is the planar clamped-clamped Elastica with its
// ends end_distance*L apart: T_ext = -16 K(k)^2 EI/L^2 with 2E/K - 1 = D/L. The shooting solve
// converges to 1e-8 in |F| (the case's tolerance) at forces ~50, hence 1e-9 relative.
TEST(Plectoneme, UntwistedIsTheClampedClampedElastica) {
  for (double D : {0.5, 0.8}) {
    const double guess_P = analytic::clamped_clamped_elastica_load(1.0, 1.0, D);
    const auto solved = testing::solve_case(
        "plectoneme.toml", {{"end_distance", D}, {"guess_n", -guess_P}, {"guess_m", 2.0 * std::sqrt(guess_P) * 0.68}});
    const double T = solved.solution.derived.at("T_ext");
    EXPECT_NEAR(-T / guess_P, 1.0, 1e-9) << "D = " << D;
    EXPECT_NEAR(solved.solution.derived.at("m3"), 0.0, 1e-12);
    EXPECT_LT(solved.solution.invariants.H.spread, 1e-9 * std::abs(solved.solution.invariants.H.mean));
  }
}

}  // namespace
}  // namespace kirchhoff

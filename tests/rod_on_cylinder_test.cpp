// A spatial rod lying on a cylinder (rod_on_cylinder.hpp): the constraint's derivatives against
// finite differences along the unloaded rod, the exact helices on the cylinder (the ply of eqs.
// 58a-c among them), the Baumgarte pull back onto it, and the flow's variational equations.
#include <gtest/gtest.h>

#include <cmath>

#include "kirchhoff/equations/detail/rod_on_cylinder.hpp"

namespace kirchhoff {
namespace {

constexpr double kEI = 1.0, kGJ = 1.0 / 1.3;

RodModel isotropic_rod(double length) {
  RodModel model;
  model.length = length;
  model.B = {Profile(kEI), Profile(kEI), Profile(kGJ)};
  return model;
}

// The axis e1 through the origin, as in cases/plectoneme.toml.
CylinderSupport ply_cylinder(double radius) {
  CylinderSupport c;
  c.axis = Vec3::UnitX();
  c.radius = radius;
  return c;
}

// A helix of angle theta on the cylinder about e1 (radius R), at phase phi: the frame (e, g, t)
// with e radial, t = sin(theta) e_phi + cos(theta) e1, g = t x e; and the internal force and
// moment of an isotropic rod in equilibrium on it with tension N and twisting moment m3:
// m = -B kappa g + m3 t, n = N t + K g, K = kappa (B sin(theta) cos(theta) / R - m3), kappa =
// sin^2(theta) / R. The cylinder's pressure is then p = N kappa + K sin(theta) cos(theta) / R.
struct Helix {
  double R, theta, N, m3;
  double kappa() const { return std::sin(theta) * std::sin(theta) / R; }
  double K() const { return kappa() * (kEI * std::sin(theta) * std::cos(theta) / R - m3); }
  double pressure() const { return N * kappa() + K() * std::sin(theta) * std::cos(theta) / R; }
  RodPoint at(double s) const {
    const double phi = s * std::sin(theta) / R;
    const Vec3 e(0.0, std::cos(phi), std::sin(phi)), e_phi(0.0, -std::sin(phi), std::cos(phi));
    const Vec3 t = std::sin(theta) * e_phi + std::cos(theta) * Vec3::UnitX();
    const Vec3 g = t.cross(e);
    RodPoint p;
    p.s = s;
    p.r = R * e + s * std::cos(theta) * Vec3::UnitX();
    p.R.col(0) = e;
    p.R.col(1) = g;
    p.R.col(2) = t;
    p.m = -kEI * kappa() * g + m3 * t;
    p.n = N * t + K() * g;
    return p;
  }
};

// The ply of eqs. (58a-c): a helix whose internal force has no component along the axis.
Helix ply_helix(double R, double theta) {
  const double c2 = std::cos(2.0 * theta), s = std::sin(theta), c = std::cos(theta);
  return {R, theta, kEI / (R * R) * std::pow(s, 4) / c2, -kEI / R * 2.0 * s * s * s * c / c2};
}

double gap_along(const RodEquations& free, const Eigen::VectorXd& y0, double s, int k,
                 const CylinderSupport& c) {
  IntegratorOptions tight;
  tight.abs_tol = tight.rel_tol = 1e-14;
  const Eigen::VectorXd y = free.sample(y0, {0.0, s}, tight).back();
  return cylinder_gap_derivatives(free.model(), c, y)[k];
}

// Each of g', g'', g''' is the derivative of the one before along the unloaded rod: fourth-order
// central differences of the previous one with h = 5e-4 err by ~h^4 |g^(5)| / 30 ~ 1e-10 here (the
// state varies on the scale 0.05) plus the integrator's error over h, ~1e-14 / h = 2e-11.
TEST(RodOnCylinder, GapDerivativesAreTheDerivativesAlongTheRod) {
  const RodModel model = isotropic_rod(1.0);
  const auto free = make_spatial_equations(model);
  const CylinderSupport c = ply_cylinder(0.05);
  RodPoint p;
  p.r = Vec3(0.1, 0.04, 0.05);
  p.R = Eigen::AngleAxisd(0.7, Vec3(0.3, 1.0, 0.2).normalized()).toRotationMatrix();
  p.n = Vec3(1.5, -2.0, 0.7);
  p.m = Vec3(0.4, 1.1, -0.6);
  const Eigen::VectorXd y0 = free->state(p);
  const double h = 5e-4, s0 = 0.05;
  for (int k = 1; k < 4; ++k) {
    auto g = [&](double s) { return gap_along(*free, y0, s, k - 1, c); };
    const double fd = (8.0 * (g(s0 + h) - g(s0 - h)) - (g(s0 + 2 * h) - g(s0 - 2 * h))) / (12.0 * h);
    EXPECT_NEAR(gap_along(*free, y0, s0, k, c), fd, 1e-8 * std::max(1.0, std::abs(fd))) << "g^(" << k << ")";
  }
}

// On an exact helix of the cylinder, whatever its tension and twist, the constrained flow stays on
// it and the pressure is the helix's. Along the cylinder the equations are unstable (errors grow
// like exp(0.7 s / R) on these helices: a Hamiltonian system's hyperbolic directions), so the
// helix is followed over 10 R at the default tolerance (1e-12): positions to 1e-9 of R, forces to
// 1e-8. The gap itself is held by the Baumgarte pull however far the solution strays along the
// cylinder: below 1e-9 R after 100 R (measured 1.3e-10 - 3.4e-10 R).
TEST(RodOnCylinder, HelicesStayOnTheCylinderWithTheirPressure) {
  const double R = 0.01;
  for (const Helix& helix : {Helix{R, 0.3, 50.0, 3.0}, Helix{R, 0.5, -20.0, -8.0}, ply_helix(R, 0.25)}) {
    const auto on = make_spatial_equations_on_cylinder(isotropic_rod(1.0), ply_cylinder(R));
    const Eigen::VectorXd y0 = on->state(helix.at(0.0));
    EXPECT_NEAR(cylinder_pressure(on->model(), ply_cylinder(R), y0), helix.pressure(),
                1e-9 * std::abs(helix.pressure()));
    const double length = 10.0 * R;
    const Eigen::VectorXd y1 = on->flow(y0, 0.0, length, false, IntegratorOptions{}).y;
    const RodPoint end = on->point(y1, length), exact = helix.at(length);
    EXPECT_LE((end.r - exact.r).norm(), 1e-9 * R) << "theta " << helix.theta;
    EXPECT_LE((end.n - exact.n).norm(), 1e-8 * exact.n.norm());
    const Eigen::VectorXd far = on->flow(y0, 0.0, 100.0 * R, false, IntegratorOptions{}).y;
    EXPECT_LE(std::abs(cylinder_gap_derivatives(on->model(), ply_cylinder(R), far)[0]), 1e-9 * R);
  }
}

// The ply helix of eqs. (58a-c): pressure EI sin^4 / (R^3 cos 2 theta) = T_helix / R, and no
// force along the axis (the two strands' axial forces cancel in a ply).
TEST(RodOnCylinder, PlyHelixHasThePressureOfEquation58a) {
  const double R = 0.005, theta = 0.3;
  const Helix ply = ply_helix(R, theta);
  const double p58a = kEI / (R * R * R) * std::pow(std::sin(theta), 4) / std::cos(2.0 * theta);
  EXPECT_NEAR(ply.pressure(), p58a, 1e-12 * p58a);
  const auto on = make_spatial_equations_on_cylinder(isotropic_rod(1.0), ply_cylinder(R));
  EXPECT_NEAR(cylinder_pressure(on->model(), ply_cylinder(R), on->state(ply.at(0.3))), p58a, 1e-9 * p58a);
  EXPECT_NEAR(ply.at(0.1).n.x(), 0.0, 1e-12 * ply.N);
}

// A state that starts off the cylinder (by 1 % of the radius) is pulled back onto it at the
// Baumgarte rate w = 0.1 / R: after 300 R the gap has fallen below 1e-6 of its start (a quadruple
// root at -w decays like (w s)^3 exp(-w s) / 6: 2e-9 at w s = 30).
TEST(RodOnCylinder, StatesOffTheCylinderArePulledBack) {
  const double R = 0.01;
  const Helix helix = ply_helix(R, 0.3);
  RodPoint p = helix.at(0.0);
  p.r *= 1.01;
  const auto on = make_spatial_equations_on_cylinder(isotropic_rod(1.0), ply_cylinder(R));
  const Eigen::VectorXd y1 = on->flow(on->state(p), 0.0, 300.0 * R, false, IntegratorOptions{}).y;
  EXPECT_LE(std::abs(cylinder_gap_derivatives(on->model(), ply_cylinder(R), y1)[0]), 1e-6 * 0.01 * R);
}

// The variational equations of the constrained flow against central differences of the flow
// (h = 1e-6 relative; error ~ h^2 and 1e-12 / h): agreement to 1e-5 of the largest entry.
TEST(RodOnCylinder, VariationalEquationsMatchFiniteDifferences) {
  const double R = 0.02;
  const Helix helix{R, 0.35, 30.0, 2.0};
  const auto on = make_spatial_equations_on_cylinder(isotropic_rod(1.0), ply_cylinder(R));
  RodPoint p = helix.at(0.0);
  p.n += Vec3(0.5, -0.3, 0.2);  // off the exact helix: every term of the pressure moves
  const Eigen::VectorXd y0 = on->state(p);
  const double length = 0.2;
  const SegmentFlow flow = on->flow(y0, 0.0, length, true, IntegratorOptions{});
  Eigen::MatrixXd fd(y0.size(), y0.size());
  for (int j = 0; j < y0.size(); ++j) {
    const double h = 1e-6 * (1.0 + std::abs(y0[j]));
    Eigen::VectorXd plus = y0, minus = y0;
    plus[j] += h;
    minus[j] -= h;
    fd.col(j) = (on->flow(plus, 0.0, length, false, IntegratorOptions{}).y -
                 on->flow(minus, 0.0, length, false, IntegratorOptions{}).y) / (2.0 * h);
  }
  EXPECT_LE((flow.Phi - fd).cwiseAbs().maxCoeff(), 1e-5 * flow.Phi.cwiseAbs().maxCoeff());
}

TEST(RodOnCylinder, RefusesRodsItDoesNotModel) {
  RodModel anisotropic = isotropic_rod(1.0);
  anisotropic.B[1] = Profile(2.0);
  EXPECT_NE(rod_on_cylinder_unsupported(anisotropic).find("B1 != B2"), std::string::npos);
  RodModel curved = isotropic_rod(1.0);
  curved.u_hat[0] = Profile(1.0);
  EXPECT_NE(rod_on_cylinder_unsupported(curved).find("natural"), std::string::npos);
  RodModel extensible = isotropic_rod(1.0);
  extensible.extensible = true;
  EXPECT_THROW(make_spatial_equations_on_cylinder(extensible, ply_cylinder(0.1)), std::invalid_argument);
  EXPECT_THROW(make_spatial_equations_on_cylinder(isotropic_rod(1.0), ply_cylinder(0.0)), std::invalid_argument);
  EXPECT_EQ(rod_on_cylinder_unsupported(isotropic_rod(1.0)), "");
}

}  // namespace
}  // namespace kirchhoff

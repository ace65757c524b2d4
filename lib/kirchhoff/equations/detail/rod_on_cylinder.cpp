#include "kirchhoff/equations/detail/rod_on_cylinder.hpp"

#include <cmath>

#include "kirchhoff/equations/detail/rod_on_cylinder_impl.hpp"

namespace kirchhoff {
namespace {

constexpr int kN = detail::kSpatialStateSize;
using StateDual = Dual<kN>;

// The state on dual numbers seeded with the identity: one evaluation gives a function's gradient.
std::array<StateDual, kN> seeded(const Eigen::VectorXd& y) {
  std::array<StateDual, kN> out;
  for (int i = 0; i < kN; ++i) {
    out[i].v = y[i];
    out[i].d[i] = 1.0;
  }
  return out;
}

void check_state(const Eigen::VectorXd& y) {
  if (y.size() != kN) throw std::invalid_argument("a rod on a cylinder needs the spatial state (14 entries)");
}

CylinderSupport with_unit_axis(CylinderSupport support) {
  support.axis.normalize();
  return support;
}

}  // namespace

std::string rod_on_cylinder_unsupported(const RodModel& model) {
  const std::string what = "a spatial rod lying on a cylinder is modelled for ";
  const std::string kind = "isotropic (B1 = B2), uniform, naturally straight, inextensible and unshearable rods "
                           "without an external field";
  if (model.extensible || !model.is_uniform() || model.field || model.symmetry_unfolding != 0.0)
    return what + kind + " (rod_on_cylinder.hpp); not implemented for this rod";
  if (std::abs(model.B[0](0.0) - model.B[1](0.0)) > 1e-12 * std::abs(model.B[0](0.0)))
    return what + kind + ": this rod's bending stiffnesses differ (B1 != B2)";
  for (int i = 0; i < 3; ++i)
    if (model.u_hat[i](0.0) != 0.0 || model.v_hat[i](0.0) != (i == 2 ? 1.0 : 0.0))
      return what + kind + ": this rod has natural curvature, twist or strain";
  return "";
}

Eigen::Vector4d cylinder_gap_derivatives(const RodModel& model, const CylinderSupport& given, const Eigen::VectorXd& y,
                                         Eigen::MatrixXd* jacobian) {
  check_state(y);
  const CylinderSupport support = with_unit_axis(given);
  const double B = model.B[0](0.0);
  Eigen::Vector4d out;
  if (!jacobian) {
    detail::V3<double> r, t, m, n;
    detail::spatial_vectors(y.data(), &r, &t, &m, &n);
    const auto G = detail::cylinder_gaps(support, B, r, t, m, n);
    for (int i = 0; i < 4; ++i) out[i] = G.g[i];
    return out;
  }
  const auto yd = seeded(y);
  detail::V3<StateDual> r, t, m, n;
  detail::spatial_vectors(yd.data(), &r, &t, &m, &n);
  const auto G = detail::cylinder_gaps(support, B, r, t, m, n);
  jacobian->resize(4, kN);
  for (int i = 0; i < 4; ++i) {
    out[i] = G.g[i].v;
    for (int j = 0; j < kN; ++j) (*jacobian)(i, j) = G.g[i].d[j];
  }
  return out;
}

Vec3 cylinder_normal(const CylinderSupport& given, const Eigen::VectorXd& y, Eigen::MatrixXd* jacobian) {
  check_state(y);
  const CylinderSupport support = with_unit_axis(given);
  const Vec3 d = y.segment<3>(detail::kR) - support.point;
  const Vec3 w = d - support.axis * support.axis.dot(d);
  const double rho = w.norm();
  const Vec3 e = w / rho;
  if (jacobian) {
    jacobian->setZero(3, kN);
    // de/dr = (I - a a^T - e e^T) / rho.
    jacobian->block<3, 3>(0, detail::kR) =
        (Mat3::Identity() - support.axis * support.axis.transpose() - e * e.transpose()) / rho;
  }
  return e;
}

double cylinder_pressure(const RodModel& model, const CylinderSupport& support, const Eigen::VectorXd& y) {
  check_state(y);
  detail::V3<double> e;
  return detail::cylinder_pressure(with_unit_axis(support), model.B[0](0.0), y.data(), &e);
}

}  // namespace kirchhoff

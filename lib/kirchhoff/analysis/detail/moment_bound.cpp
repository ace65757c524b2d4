#include "kirchhoff/analysis/detail/moment_bound.hpp"

#include <algorithm>
#include <cmath>

namespace kirchhoff::detail {

std::optional<double> moment_bound(const RodEquations& equations, const RodPoint& start, bool has_contacts) {
  const RodModel& model = equations.model();
  if (model.field || model.extensible || !model.is_uniform() || has_contacts) return std::nullopt;
  // r' = d3 (no natural strain) and no natural curvature: H is as written.
  for (int k = 0; k < 3; ++k)
    if (model.u_hat[k](0.0) != 0.0 || model.v_hat[k](0.0) != (k == 2 ? 1.0 : 0.0)) return std::nullopt;
  const Vec3 m = start.R.transpose() * start.m;  // body components
  const double n_d3 = start.n.dot(start.R.col(2)), n_norm = start.n.norm();
  if (equations.is_planar()) {  // it bends about d2 only
    const double B = model.B[1](0.0), H = 0.5 * m[1] * m[1] / B + n_d3;
    return std::sqrt(2.0 * B * std::max(0.0, H + n_norm));
  }
  const double B1 = model.B[0](0.0), B2 = model.B[1](0.0), B3 = model.B[2](0.0);
  const double H = 0.5 * (m[0] * m[0] / B1 + m[1] * m[1] / B2 + m[2] * m[2] / B3) + n_d3;
  const double budget = 2.0 * std::max(0.0, H + n_norm);  // >= m.B^-1 m all along
  // Isotropic: m3 = m.d3 is conserved as well, and only the bending part varies.
  if (B1 == B2) return std::sqrt(B1 * std::max(0.0, budget - m[2] * m[2] / B3) + m[2] * m[2]);
  return std::sqrt(std::max({B1, B2, B3}) * budget);
}

}  // namespace kirchhoff::detail

#include "kirchhoff/analysis/detail/moment_bound.hpp"

#include <algorithm>
#include <cmath>

namespace kirchhoff::detail {

std::optional<double> moment_bound(const RodEquations& equations, const RodPoint& start, bool has_contacts) {
  const RodModel& model = equations.model();
  // Uniform but for the symmetry-unfolding couple, whose effect on H is bounded below.
  if (model.field || model.extensible || !model.has_constant_properties() || has_contacts) return std::nullopt;
  // r' = d3 (no natural strain) and no natural curvature: H is as written.
  for (int k = 0; k < 3; ++k)
    if (model.u_hat[k](0.0) != 0.0 || model.v_hat[k](0.0) != (k == 2 ? 1.0 : 0.0)) return std::nullopt;
  const double mu = std::abs(model.symmetry_unfolding), L = model.length;
  const Vec3 m = start.R.transpose() * start.m;  // body components
  const double n_d3 = start.n.dot(start.R.col(2)), n_norm = start.n.norm();
  // |m'| = |d3 x n + mu g| <= |n| + 2 mu (n constant, |g| <= 2): |m| <= |m(0)| + (|n| + 2 mu) L all
  // along. It is the tighter bound where the stiffnesses differ widely (H's bound grows with the
  // stiffest one's square root: a strip with B1 = 1e8 B2 under a tip load of 4 bounded |m| by
  // 2.8e4, where it is 4, and the fields' scale set from that hid the soft directions' momenta,
  // and a negative end eigenvalue, under the zero tolerance).
  const double crude = start.m.norm() + (n_norm + 2.0 * mu) * L;
  if (equations.is_planar()) {  // it bends about d2 only
    if (mu != 0.0) return std::nullopt;
    const double B = model.B[1](0.0), H = 0.5 * m[1] * m[1] / B + n_d3;
    return std::min(crude, std::sqrt(2.0 * B * std::max(0.0, H + n_norm)));
  }
  const double B1 = model.B[0](0.0), B2 = model.B[1](0.0), B3 = model.B[2](0.0);
  // The unfolding couple changes H at a rate |u.mu g| <= 2 mu |m| / B_min, and m3 at a rate <= 2 mu.
  const double B_min = std::min({B1, B2, B3});
  const double H = 0.5 * (m[0] * m[0] / B1 + m[1] * m[1] / B2 + m[2] * m[2] / B3) + n_d3 + 2.0 * mu * L * crude / B_min;
  const double budget = 2.0 * std::max(0.0, H + n_norm);  // >= m.B^-1 m all along
  // Isotropic: m3 = m.d3 is conserved as well (within 2 mu L), and only the bending part varies.
  if (B1 == B2) {
    const double m3_low = std::max(0.0, std::abs(m[2]) - 2.0 * mu * L), m3_high = std::abs(m[2]) + 2.0 * mu * L;
    return std::min(crude, std::sqrt(B1 * std::max(0.0, budget - m3_low * m3_low / B3) + m3_high * m3_high));
  }
  return std::min(crude, std::sqrt(std::max({B1, B2, B3}) * budget));
}

}  // namespace kirchhoff::detail

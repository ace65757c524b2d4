// Continuous families among found equilibria (see equilibrium_families.hpp).
#include "kirchhoff/jobs/detail/equilibrium_families.hpp"

#include <Eigen/SVD>
#include <array>
#include <cmath>

namespace kirchhoff {
namespace {

// The scaled lab vectors a rigid motion turns (positions about their centroid): r, d3, n, m.
std::vector<std::array<Vec3, 4>> rigid_parts(const std::vector<RodPoint>& points, double L, double force_scale) {
  Vec3 centroid = Vec3::Zero();
  for (const RodPoint& p : points) centroid += p.r;
  centroid /= static_cast<double>(points.size());
  std::vector<std::array<Vec3, 4>> parts;
  for (const RodPoint& p : points)
    parts.push_back({(p.r - centroid) / L, p.R.col(2), p.n / force_scale, p.m / (force_scale * L)});
  return parts;
}

// The proper rotation Q minimising sum |Q b - a|^2 over all parts (Kabsch): from the SVD of the
// cross-covariance, with the sign fixed so that det Q = +1. In the plane, the turn about e3 alone.
Mat3 best_rotation(const std::vector<std::array<Vec3, 4>>& a, const std::vector<std::array<Vec3, 4>>& b, bool planar) {
  Mat3 H = Mat3::Zero();  // sum a b^T
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 4; ++k) H += a[i][k] * b[i][k].transpose();
  if (planar) {
    const double dot = H(0, 0) + H(1, 1), cross = H(1, 0) - H(0, 1);
    return Eigen::AngleAxisd(std::atan2(cross, dot), Vec3::UnitZ()).toRotationMatrix();
  }
  const Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double sign = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * Vec3(1.0, 1.0, sign).asDiagonal() * svd.matrixV().transpose();
}

double energy_scale(const Equilibrium& e, double force_scale) {
  return std::abs(e.energy) + force_scale * e.problem->length(e.solution.result.parameters);
}

bool same_family(const Equilibrium& a, const Equilibrium& b, double force_scale, double distinct_tolerance,
                 double energy_tolerance, int samples) {
  if (!(std::abs(a.energy - b.energy) <= energy_tolerance * std::max(energy_scale(a, force_scale), energy_scale(b, force_scale))))
    return false;
  return rigid_motion_distance(*a.problem, a.solution.result.x, *b.problem, b.solution.result.x, force_scale, samples) <
         distinct_tolerance;
}

}  // namespace

double rigid_motion_distance(const ShootingProblem& a, const Eigen::VectorXd& xa, const ShootingProblem& b,
                             const Eigen::VectorXd& xb, double force_scale, int samples) {
  const double L = a.length(a.parameters_at(xa));
  if (std::abs(L - b.length(b.parameters_at(xb))) > 1e-12 * L) return INFINITY;
  if (a.definition().kind != b.definition().kind) return INFINITY;
  std::vector<double> s(samples);
  for (int i = 0; i < samples; ++i) s[i] = L * i / (samples - 1);
  s.back() = L;
  const auto pa = rigid_parts(a.sample(xa, s), L, force_scale), pb = rigid_parts(b.sample(xb, s), L, force_scale);
  const Mat3 Q = best_rotation(pa, pb, a.definition().kind == RodKind::Planar);
  double worst = 0.0;
  for (int i = 0; i < samples; ++i)
    for (int k = 0; k < 4; ++k) worst = std::max(worst, (Q * pb[i][k] - pa[i][k]).norm());
  return worst;
}

int group_continuous_families(std::vector<Equilibrium>* equilibria, double force_scale, double distinct_tolerance,
                              double energy_tolerance, int samples) {
  int families = 0;
  std::vector<Equilibrium>& list = *equilibria;
  for (size_t i = 0; i < list.size(); ++i) {
    Equilibrium& e = list[i];
    e.family = 0;
    if (!e.stability.defined() || e.stability.zero_modes == 0) continue;  // (a NaN energy matches none)
    for (size_t j = 0; j < i && e.family == 0; ++j)
      if (list[j].family > 0 && same_family(list[j], e, force_scale, distinct_tolerance, energy_tolerance, samples))
        e.family = list[j].family;
    if (e.family == 0) e.family = ++families;
  }
  return families;
}

}  // namespace kirchhoff

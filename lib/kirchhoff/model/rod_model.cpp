#include "kirchhoff/model/rod_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kirchhoff {

double Profile::derivative(double s) const {
  if (!function_) return 0.0;
  if (derivative_) return derivative_(s);
  const double h = 1e-5 * (1.0 + std::abs(s));  // balances truncation h^2 against round-off/h
  return (function_(s + h) - function_(s - h)) / (2.0 * h);
}

UniformGravity::UniformGravity(double weight_per_length, Vec3 up)
    : weight_(weight_per_length), up_(up.normalized()) {}

BarrierWall::BarrierWall(double range_b, double height_a, Vec3 normal)
    : b_(range_b), a_(height_a), normal_(normal.normalized()) {
  if (!(b_ > 0.0)) throw std::invalid_argument("barrier range b must be > 0");
}

double BarrierWall::potential(double, const Vec3& r) const { return b_ / (a_ - r.dot(normal_)); }

Vec3 BarrierWall::force(double, const Vec3& r) const {
  const double gap = a_ - r.dot(normal_);
  return -b_ / (gap * gap) * normal_;
}

Mat3 BarrierWall::force_gradient(double, const Vec3& r) const {
  const double gap = a_ - r.dot(normal_);
  return -2.0 * b_ / (gap * gap * gap) * normal_ * normal_.transpose();
}

double FieldSum::potential(double s, const Vec3& r) const {
  double w = 0.0;
  for (const auto& f : fields_) w += f->potential(s, r);
  return w;
}
Vec3 FieldSum::force(double s, const Vec3& r) const {
  Vec3 total = Vec3::Zero();
  for (const auto& f : fields_) total += f->force(s, r);
  return total;
}
Mat3 FieldSum::force_gradient(double s, const Vec3& r) const {
  Mat3 total = Mat3::Zero();
  for (const auto& f : fields_) total += f->force_gradient(s, r);
  return total;
}

bool FieldSum::stiffens_perturbations() const {
  for (const auto& f : fields_)
    if (f->stiffens_perturbations()) return true;
  return false;
}

bool FieldSum::has_tangent_stiffness() const {
  for (const auto& f : fields_)
    if (f->has_tangent_stiffness()) return true;
  return false;
}
void FieldSum::add_tangent_stiffness(double s, const Vec3& r, const Vec3& d3, const Vec3& d3_prime,
                                     Eigen::Matrix<double, 6, 6>* S) const {
  for (const auto& f : fields_) f->add_tangent_stiffness(s, r, d3, d3_prime, S);
}

double FieldSum::gap(double s, const Vec3& r) const {
  double smallest = std::numeric_limits<double>::quiet_NaN();
  for (const auto& f : fields_) {
    const double g = f->gap(s, r);
    if (std::isfinite(g) && !(g >= smallest)) smallest = g;
  }
  return smallest;
}

namespace {
// Stiffness profiles are checked at this many equally spaced points (tapered rods are smooth;
// a profile that dips below zero between samples would still fail in the equations).
constexpr int kValidationSamples = 101;

void require_positive_at(const Profile& p, double s, const std::string& name) {
  const double value = p(s);
  if (!(value > 0.0))
    throw std::invalid_argument(name + " must be > 0 along the rod, got " + std::to_string(value) +
                                " at s = " + std::to_string(s));
}

// (Both sides of each jump too: a stretch between two jumps may be shorter than the samples' spacing.)
void require_positive(const Profile& p, double length, const std::string& name) {
  for (int i = 0; i < kValidationSamples; ++i) require_positive_at(p, length * i / (kValidationSamples - 1), name);
  for (const ProfileJump& j : p.jumps()) {
    require_positive_at(p, j.before, name);
    require_positive_at(p, j.after, name);
  }
}
}  // namespace

void RodModel::validate() const {
  if (!(length > 0.0)) throw std::invalid_argument("length must be > 0, got " + std::to_string(length));
  const char* bend_names[3] = {"B1", "B2", "B3"};
  const char* shear_names[3] = {"A1", "A2", "A3"};
  for (int i = 0; i < 3; ++i) require_positive(B[i], length, bend_names[i]);
  if (extensible)
    for (int i = 0; i < 3; ++i) require_positive(A[i], length, shear_names[i]);
}

bool RodModel::is_uniform() const { return symmetry_unfolding == 0.0 && has_constant_properties(); }

bool RodModel::has_constant_properties() const {
  for (int i = 0; i < 3; ++i) {
    if (!B[i].is_constant() || !u_hat[i].is_constant() || !v_hat[i].is_constant()) return false;
    if (extensible && !A[i].is_constant()) return false;
  }
  return true;
}

std::vector<ProfileJump> RodModel::jumps() const {
  std::vector<ProfileJump> all;
  const auto add = [&](const std::array<Profile, 3>& profiles) {
    for (const Profile& p : profiles) all.insert(all.end(), p.jumps().begin(), p.jumps().end());
  };
  add(B);
  if (extensible) add(A);
  add(u_hat);
  add(v_hat);
  std::sort(all.begin(), all.end(), [](const ProfileJump& a, const ProfileJump& b) { return a.before < b.before; });
  // Properties read from one expression (B for B1 and B2) jump at the same place.
  all.erase(std::unique(all.begin(), all.end(),
                        [](const ProfileJump& a, const ProfileJump& b) { return b.before <= a.after; }),
            all.end());
  return all;
}

}  // namespace kirchhoff

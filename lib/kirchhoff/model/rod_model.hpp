// The description of an elastic rod: stiffnesses, natural strains and external conservative
// fields. Immutable once built; the equations and solvers read it, never write it.
//
// Notation follows the reference paper (Noether invariants for elastic rods), section 3:
// bending/twist stiffnesses B1, B2, B3 (eq. 12), shear/stretch stiffnesses A1, A2, A3 (eq. 13),
// natural curvatures/twist u_hat and natural shear/stretch v_hat, external potential W_ext (eq. 14).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace kirchhoff {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Where a material property given piecewise jumps: its left-hand value holds up to `before`, its
// right-hand one from `after`, the next double (model/detail/profile_jumps.hpp locates them).
struct ProfileJump {
  double before = 0.0, after = 0.0;
};

// A scalar material property as a function of the arclength s. Constant profiles skip the
// function call, which matters because the right-hand side evaluates six of them per call.
class Profile {
 public:
  Profile(double constant = 0.0) : constant_(constant) {}  // NOLINT: a number is a constant profile
  Profile(std::function<double(double)> f, std::function<double(double)> derivative = {})
      : function_(std::move(f)), derivative_(std::move(derivative)) {}

  double operator()(double s) const { return function_ ? function_(s) : constant_; }
  bool is_constant() const { return !function_; }
  // The same profile, known to jump at these places (sorted by s, inside the rod).
  Profile with_jumps(std::vector<ProfileJump> jumps) && {
    jumps_ = std::move(jumps);
    return std::move(*this);
  }
  const std::vector<ProfileJump>& jumps() const { return jumps_; }
  // d/ds of the profile; central differences when no derivative was supplied (used only for
  // reporting identities such as eq. 57, never inside the equations).
  double derivative(double s) const;

 private:
  double constant_ = 0.0;
  std::function<double(double)> function_;
  std::function<double(double)> derivative_;
  std::vector<ProfileJump> jumps_;
};

// A conservative external field per unit length: potential W_ext(s, r), force f = -dW/dr and the
// force's gradient df/dr, which the variational equations need. Most fields depend on r only;
// the arclength is there for fields that act on part of the rod (self-contact, which must not
// act between neighbouring cross-sections). H is conserved where W_ext does not depend on s.
class ExternalField {
 public:
  virtual ~ExternalField() = default;
  virtual double potential(double s, const Vec3& r) const = 0;
  virtual Vec3 force(double s, const Vec3& r) const = 0;
  virtual Mat3 force_gradient(double s, const Vec3& r) const = 0;
  // Distance to the obstacle the field models (soft walls); NaN when it models none.
  virtual double gap(double, const Vec3&) const { return std::numeric_limits<double>::quiet_NaN(); }
  // A term of the second variation that depends on the tangent d3 = r' as well as on r, for fields
  // that exist only in a stability analysis (the sliding contact partners of a half-turn
  // self-contact, analysis/detail/stability_symmetric.hpp): adds to S (6 x 6, symmetric, on
  // z = (dr, dd3)) the field's part of d2E/de2 = z.S z beyond dr.Hess W dr. It has no first
  // variation, so the equilibrium equations do not change; their linearisation gains
  // dn' += S_rr dr + S_rt dd3 and dm' += d3 x (S_tr dr + S_tt dd3) (the spatial equations only).
  virtual bool has_tangent_stiffness() const { return false; }
  virtual void add_tangent_stiffness(double /*s*/, const Vec3& /*r*/, const Vec3& /*d3*/, const Vec3& /*d3_prime*/,
                                     Eigen::Matrix<double, 6, 6>* /*S*/) const {}
  // Whether the field adds to the second variation directly (a force gradient or a tangent
  // stiffness somewhere): false for a field linear in r, which acts on perturbations only through
  // the equilibrium's internal force. The stability index confirms its count by denser
  // observations only in a field that does (analysis/stability.hpp).
  virtual bool stiffens_perturbations() const { return true; }
};

// Weight per unit length w acting along -up: W_ext = w r.up (section 3.1, rho S g r.e_z).
class UniformGravity final : public ExternalField {
 public:
  UniformGravity(double weight_per_length, Vec3 up);
  double potential(double, const Vec3& r) const override { return weight_ * r.dot(up_); }
  Vec3 force(double, const Vec3&) const override { return -weight_ * up_; }
  Mat3 force_gradient(double, const Vec3&) const override { return Mat3::Zero(); }
  bool stiffens_perturbations() const override { return false; }

 private:
  double weight_;
  Vec3 up_;
};

// Soft-wall barrier of eq. (64): W_ext = b / (a - r.normal), repelling the rod from the plane
// r.normal = a it must stay below.
class BarrierWall final : public ExternalField {
 public:
  BarrierWall(double range_b, double height_a, Vec3 normal);
  double potential(double s, const Vec3& r) const override;
  Vec3 force(double s, const Vec3& r) const override;
  Mat3 force_gradient(double s, const Vec3& r) const override;
  double gap(double, const Vec3& r) const override { return a_ - r.dot(normal_); }

 private:
  double b_, a_;
  Vec3 normal_;
};

// Several fields acting together.
class FieldSum final : public ExternalField {
 public:
  void add(std::shared_ptr<const ExternalField> f) { fields_.push_back(std::move(f)); }
  bool empty() const { return fields_.empty(); }
  double potential(double s, const Vec3& r) const override;
  Vec3 force(double s, const Vec3& r) const override;
  Mat3 force_gradient(double s, const Vec3& r) const override;
  double gap(double s, const Vec3& r) const override;  // the smallest of the fields' gaps
  bool has_tangent_stiffness() const override;
  void add_tangent_stiffness(double s, const Vec3& r, const Vec3& d3, const Vec3& d3_prime,
                             Eigen::Matrix<double, 6, 6>* S) const override;
  bool stiffens_perturbations() const override;
  const std::vector<std::shared_ptr<const ExternalField>>& fields() const { return fields_; }

 private:
  std::vector<std::shared_ptr<const ExternalField>> fields_;
};

struct RodModel {
  double length = 1.0;
  std::array<Profile, 3> B{Profile(1.0), Profile(1.0), Profile(1.0)};  // bend 1, bend 2, twist
  // Kirchhoff limit: inextensible and unshearable, v = v_hat exactly (no large stiffness).
  bool extensible = false;
  std::array<Profile, 3> A{Profile(1.0), Profile(1.0), Profile(1.0)};  // shear 1, shear 2, stretch
  std::array<Profile, 3> u_hat{Profile(0.0), Profile(0.0), Profile(0.0)};
  std::array<Profile, 3> v_hat{Profile(0.0), Profile(0.0), Profile(1.0)};
  std::shared_ptr<const ExternalField> field;  // null: no external field
  // Unfolding parameter mu of the axial phase condition (see add_axial_phase_condition): a
  // fictitious distributed couple l = mu (e3 - d3), m' = n x r' - l. Every solution of a
  // well-posed problem drives it to zero; while it is non-zero H is not reported invariant.
  double symmetry_unfolding = 0.0;
  // Set where mu is an unknown (add_axial_phase_condition): flows with sensitivities then also
  // carry the end state's derivative with respect to mu where the equations can
  // (SegmentFlow::dy_dunfolding), so that its Jacobian column needs no differencing.
  bool unfolding_sensitivity = false;

  // Throws std::invalid_argument naming the offending property (non-positive length or
  // stiffness at any sampled s).
  void validate() const;
  // True when no property depends on s, so the Lagrangian has no explicit s and H is conserved.
  bool is_uniform() const;
  // True when no stiffness or natural strain depends on s: is_uniform() but for the
  // symmetry-unfolding couple, whose effect on H a caller may bound itself.
  bool has_constant_properties() const;
  // Every place where a property that enters the equations jumps (the shear and stretch
  // stiffnesses only where extensible), sorted by s, one entry per place.
  std::vector<ProfileJump> jumps() const;
};

}  // namespace kirchhoff

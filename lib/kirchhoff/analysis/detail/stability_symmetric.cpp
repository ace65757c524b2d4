// The antisymmetric half of a half-turn symmetric rod's index (see stability_symmetric.hpp).
#include "kirchhoff/analysis/detail/stability_symmetric.hpp"

#include "kirchhoff/contact/self_contact.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace kirchhoff {

double shift_curvature(const Vec3& axis, const Vec3& radial, const Vec3& d3, const Vec3& d3_prime) {
  const double alpha = axis.dot(d3);
  return alpha * alpha + radial.dot(d3_prime);
}

namespace {

// The half-turn self-contact as the antisymmetric perturbations see it (stability_symmetric.hpp):
// the same force on the equilibrium; the pair energy's second variation with the partners held,
// as a force gradient (f.d) / rho^2 a a^T, and the partners' sliding as a tangent stiffness
// k v v^T on (dr, dd3), v = (alpha a, d), k = (f.d) / (rho^2 kappa).
class AntisymmetricPairBarrier final : public ExternalField {
 public:
  explicit AntisymmetricPairBarrier(std::shared_ptr<const HalfTurnSelfContact> barrier)
      : barrier_(std::move(barrier)) {}
  double potential(double s, const Vec3& r) const override { return barrier_->potential(s, r); }
  Vec3 force(double s, const Vec3& r) const override { return barrier_->force(s, r); }
  Mat3 force_gradient(double s, const Vec3& r) const override {
    const Vec3 f = barrier_->force(s, r);
    if (f.isZero(0.0)) return Mat3::Zero();  // off near the end loop, or out of range
    const HalfTurnGeometry& g = barrier_->geometry();
    const Vec3 d = g.radial(r);
    return (f.dot(d) / d.squaredNorm()) * g.axis * g.axis.transpose();
  }
  double gap(double s, const Vec3& r) const override { return barrier_->gap(s, r); }
  bool has_tangent_stiffness() const override { return true; }
  void add_tangent_stiffness(double s, const Vec3& r, const Vec3& d3, const Vec3& d3_prime,
                             Eigen::Matrix<double, 6, 6>* S) const override {
    const Vec3 f = barrier_->force(s, r);
    if (f.isZero(0.0)) return;
    const HalfTurnGeometry& g = barrier_->geometry();
    const Vec3 d = g.radial(r);
    const double kappa = shift_curvature(g.axis, d, d3, d3_prime);
    if (!(kappa > 0)) return;  // not a minimum along the shift: stability.cpp reports it (sliding_reason)
    Eigen::Matrix<double, 6, 1> v;
    v << g.axis.dot(d3) * g.axis, d;
    *S += (f.dot(d) / (d.squaredNorm() * kappa)) * v * v.transpose();
  }

 private:
  std::shared_ptr<const HalfTurnSelfContact> barrier_;
};

// The field with every half-turn self-contact in it replaced by its antisymmetric form.
std::shared_ptr<const ExternalField> antisymmetric_field(const std::shared_ptr<const ExternalField>& field) {
  if (auto barrier = std::dynamic_pointer_cast<const HalfTurnSelfContact>(field))
    return std::make_shared<AntisymmetricPairBarrier>(barrier);
  if (auto sum = std::dynamic_pointer_cast<const FieldSum>(field)) {
    auto out = std::make_shared<FieldSum>();
    for (const auto& f : sum->fields()) out->add(antisymmetric_field(f));
    return out;
  }
  return field;
}

}  // namespace

EndCondition antisymmetric_half_turn_end(const Vec3& axis) {
  const Vec3 a = axis.normalized();
  EndCondition c;
  c.add({Slot::Position, Directions::AlongAxis, a, constant(Vec3::Zero()), {}, false, false});
  c.add({Slot::Force, Directions::LateralToAxis, a, constant(Vec3::Zero()), {}, false, false});
  c.add({Slot::Orientation, Directions::AlongAxis, a, {}, constant_orientation({a, 0.0}), false, false});
  c.add({Slot::Moment, Directions::LateralToAxis, a, constant(Vec3::Zero()), {}, false, false});
  return c;
}

std::shared_ptr<const RodEquations> antisymmetric_equations(const RodEquations& eq) {
  RodModel model = eq.model();
  if (!find_half_turn_self_contact(model)) return nullptr;
  model.field = antisymmetric_field(model.field);
  return eq.is_planar() ? make_planar_equations(model) : make_spatial_equations(model);
}

double antisymmetric_barrier_stiffness(const RodEquations& eq, const std::vector<RodPoint>& samples) {
  const RodModel& model = eq.model();
  const HalfTurnSelfContact* barrier = find_half_turn_self_contact(model);
  if (!barrier) return 0.0;
  double largest = 0.0;
  for (const RodPoint& q : samples) {
    const Vec3 d = barrier->geometry().radial(q.r);
    largest = std::max(largest, std::abs(barrier->force(q.s, q.r).dot(d)) / d.squaredNorm());
  }
  return largest * std::pow(model.length, 4) / model.B[0](0.0);
}

std::string sliding_reason(const RodEquations& eq, const RodPoint& q, double zero_tolerance) {
  const HalfTurnSelfContact* barrier = find_half_turn_self_contact(eq.model());
  if (!barrier || !(antisymmetric_barrier_stiffness(eq, {q}) > zero_tolerance)) return "";
  if (eq.is_planar())
    return "the self-contact acts on a planar rod: the sliding contact partners of its antisymmetric perturbations "
           "are implemented in the spatial equations only";
  const Vec3 d3 = q.R.col(2), d3_prime = q.R * q.u.cross(Vec3::UnitZ());
  const double kappa = shift_curvature(barrier->geometry().axis, barrier->geometry().radial(q.r), d3, d3_prime);
  if (kappa > 0) return "";
  std::ostringstream out;
  out << "the self-contact acts where the strands' distance is not a minimum along their relative shift "
         "(alpha^2 + d.r'' = "
      << kappa << " at s = " << q.s << "): the sliding partners are not defined there";
  return out.str();
}

}  // namespace kirchhoff

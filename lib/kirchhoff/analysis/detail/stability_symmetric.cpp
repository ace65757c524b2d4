// The antisymmetric half of a half-turn symmetric rod's index (see stability_symmetric.hpp).
#include "kirchhoff/analysis/detail/stability_symmetric.hpp"

#include "kirchhoff/contact/self_contact.hpp"

#include <algorithm>
#include <cmath>

namespace kirchhoff {
namespace {

// The half-turn self-contact as the antisymmetric perturbations see it: the same force on the
// equilibrium, the force gradient of the pair energy on dr(L - s) = -Q dr(s), which is
// (f.d) / rho^2 a a^T (stability_symmetric.hpp).
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

}  // namespace kirchhoff

#include "kirchhoff/shooting/boundary_conditions.hpp"

#include "kirchhoff/equations/invariants.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

namespace kirchhoff {
namespace {

// Directions whose component in a basis is smaller than this are taken as absent: the bases
// are built from exact unit vectors, so anything above round-off is a genuine component.
constexpr double kDirectionTolerance = 1e-9;

// Directions: LabDirections (fixed largest size, as the residual takes it at every evaluation) or
// Eigen::MatrixXd (the completeness check stacks two slots' bases: up to 6 columns).
template <class Directions>
Directions orthonormal_columns(const Directions& A) {
  if (A.cols() == 0) return A;
  Eigen::ColPivHouseholderQR<Directions> qr(A);
  qr.setThreshold(kDirectionTolerance);
  const int rank = static_cast<int>(qr.rank());
  return qr.householderQ() * Directions::Identity(A.rows(), rank);
}

std::string describe(const Vec3& v) {
  std::ostringstream os;
  os << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return os.str();
}

Slot conjugate(Slot s) {
  switch (s) {
    case Slot::Position: return Slot::Force;
    case Slot::Force: return Slot::Position;
    case Slot::Orientation: return Slot::Moment;
    case Slot::Moment: return Slot::Orientation;
  }
  return s;
}

}  // namespace

VectorTarget constant(const Vec3& v) {
  return [v](const Parameters&) { return v; };
}
OrientationFunction constant_orientation(const OrientationTarget& t) {
  return [t](const Parameters&) { return t; };
}

LabDirections SlotCondition::basis(const RodEquations& eq) const {
  const LabDirections E = eq.admissible_directions(slot);
  const Vec3 a = axis.normalized();
  switch (directions) {
    case Directions::All: return E;
    case Directions::AlongAxis: return a;
    case Directions::LateralToAxis: {
      const LabDirections lateral = E - a * (a.transpose() * E);
      return orthonormal_columns(lateral);
    }
  }
  return E;
}

EndCondition EndCondition::clamped(VectorTarget position, OrientationFunction orientation, bool track_turns) {
  EndCondition c;
  c.add({Slot::Position, Directions::All, Vec3::UnitZ(), std::move(position), {}, false, false});
  c.add({Slot::Orientation, Directions::All, Vec3::UnitZ(), {}, std::move(orientation), track_turns, false});
  return c;
}

EndCondition EndCondition::pinned(VectorTarget position) {
  EndCondition c;
  c.add({Slot::Position, Directions::All, Vec3::UnitZ(), std::move(position), {}, false, false});
  c.add({Slot::Moment, Directions::All, Vec3::UnitZ(), constant(Vec3::Zero()), {}, false, false});
  return c;
}

EndCondition EndCondition::free() { return loaded(constant(Vec3::Zero()), constant(Vec3::Zero())); }

EndCondition EndCondition::loaded(VectorTarget force, VectorTarget moment) {
  EndCondition c;
  c.add({Slot::Force, Directions::All, Vec3::UnitZ(), std::move(force), {}, false, false});
  c.add({Slot::Moment, Directions::All, Vec3::UnitZ(), std::move(moment), {}, false, false});
  return c;
}

EndCondition EndCondition::sliding(Vec3 axis, VectorTarget position, VectorTarget force,
                                   OrientationFunction orientation, bool track_turns) {
  EndCondition c;
  c.add({Slot::Position, Directions::LateralToAxis, axis, std::move(position), {}, false, false});
  c.add({Slot::Force, Directions::AlongAxis, axis, std::move(force), {}, false, false});
  if (orientation)
    c.add({Slot::Orientation, Directions::All, axis, {}, std::move(orientation), track_turns, false});
  else
    c.add({Slot::Moment, Directions::All, axis, constant(Vec3::Zero()), {}, false, false});
  return c;
}

EndCondition EndCondition::half_turn_symmetry(Vec3 axis, int director,
                                              std::function<double(const Parameters&)> rotation) {
  if (director != 1 && director != 2) throw std::invalid_argument("half-turn symmetry: director must be 1 or 2");
  const Vec3 a = axis.normalized();
  const Vec3 d = director == 1 ? Vec3::UnitX() : Vec3::UnitY();
  // The rotation taking d to a: the frame in which d_director lies along the axis.
  Vec3 rotation_axis = d.cross(a);
  const double angle = std::atan2(rotation_axis.norm(), d.dot(a));
  if (rotation_axis.norm() < 1e-14) rotation_axis = Vec3::UnitZ();  // parallel or opposite: turn about e3
  const Eigen::AngleAxisd base(angle, rotation_axis.normalized());
  EndCondition c;
  c.half_turn_ = true;
  c.add({Slot::Position, Directions::LateralToAxis, a, constant(Vec3::Zero()), {}, false, false});
  c.add({Slot::Force, Directions::AlongAxis, a, constant(Vec3::Zero()), {}, false, false});
  if (!rotation) {
    c.add({Slot::Orientation, Directions::LateralToAxis, a, {},
           constant_orientation({base.axis(), base.angle()}), false, false});
    c.add({Slot::Moment, Directions::AlongAxis, a, constant(Vec3::Zero()), {}, false, false});
    c.half_turn_axis_ = a;
    c.half_turn_director_ = director;
    return c;
  }
  OrientationFunction turned = [a, base, rotation](const Parameters& p) {
    const Eigen::AngleAxisd frame(Eigen::AngleAxisd(rotation(p), a) * base);
    return OrientationTarget{frame.axis(), frame.angle()};
  };
  c.add({Slot::Orientation, Directions::All, a, {}, std::move(turned), false, false});
  c.add({Slot::Moment, Directions::AlongAxis, a, constant(Vec3::Zero()), {}, false, true});
  return c;
}

EndCondition& EndCondition::add(SlotCondition condition) {
  conditions_.push_back(std::move(condition));
  return *this;
}

EndCondition& EndCondition::impose_orientation_angle(Vec3 axis, std::function<double(const Parameters&)> angle) {
  SlotCondition c;
  c.slot = Slot::Orientation;
  c.directions = Directions::AlongAxis;
  c.axis = axis;
  c.orientation = [axis, angle](const Parameters& p) { return OrientationTarget{axis, angle(p)}; };
  c.track_turns = true;
  c.extra = true;
  return add(std::move(c));
}

EndCondition& EndCondition::impose_hamiltonian(std::function<double(const Parameters&)> value) {
  hamiltonian_ = std::move(value);
  return *this;
}

int EndCondition::extra_count() const {
  int n = hamiltonian_ ? 1 : 0;
  for (const auto& c : conditions_) n += c.extra ? static_cast<int>(1) : 0;
  return n;
}

std::string EndCondition::check(const RodEquations& eq) const {
  for (Slot kinematic : {Slot::Position, Slot::Orientation}) {
    const Slot statics = conjugate(kinematic);
    const Eigen::MatrixXd E = eq.admissible_directions(kinematic);
    Eigen::MatrixXd kin(3, 0), stat(3, 0);
    for (const auto& c : conditions_) {
      if (c.extra) continue;
      if (c.slot != kinematic && c.slot != statics) continue;
      const Eigen::MatrixXd B = c.basis(eq);
      for (int j = 0; j < B.cols(); ++j) {
        const Vec3 d = B.col(j);
        if ((d - E * (E.transpose() * d)).norm() > kDirectionTolerance)
          return std::string(to_string(c.slot)) + " imposed along " + describe(d) +
                 ", a direction this rod cannot move in" + (eq.is_planar() ? " (the rod is planar)" : "");
      }
      Eigen::MatrixXd& target = (c.slot == kinematic) ? kin : stat;
      target.conservativeResize(3, target.cols() + B.cols());
      target.rightCols(B.cols()) = B;
    }
    Eigen::MatrixXd both(3, kin.cols() + stat.cols());
    both << kin, stat;
    const int rank = static_cast<int>(orthonormal_columns(both).cols());
    if (rank < both.cols()) {
      // Find a direction imposed twice to name it.
      for (int i = 0; i < kin.cols(); ++i)
        for (int j = 0; j < stat.cols(); ++j)
          if (std::abs(kin.col(i).dot(stat.col(j))) > kDirectionTolerance)
            return std::string(to_string(kinematic)) + " and " + to_string(statics) + " both imposed along " +
                   describe(kin.col(i));
      return std::string(to_string(kinematic)) + "/" + to_string(statics) + " imposed twice along some direction";
    }
    if (rank < E.cols()) {
      const Eigen::MatrixXd Q = orthonormal_columns(both);
      const Eigen::MatrixXd rest = E - Q * (Q.transpose() * E);
      Vec3 missing = Vec3::Zero();
      for (int j = 0; j < rest.cols(); ++j)
        if (rest.col(j).norm() > missing.norm()) missing = rest.col(j);
      return std::string("neither ") + to_string(kinematic) + " nor " + to_string(statics) + " imposed along " +
             describe(missing.normalized());
    }
  }
  return {};
}

void EndCondition::append_residuals(const RodEquations& eq, bool at_start, const Eigen::VectorXd& y,
                                    const Parameters& p, std::vector<double>* residual,
                                    std::vector<StateRow>* jacobian) const {
  // Applied loads relate to the internal force/moment with a sign that depends on the end.
  const double load_sign = at_start ? -1.0 : 1.0;
  for (const auto& c : conditions_) {
    const LabDirections B = c.basis(eq);
    Vec3 error;
    SlotMap J;
    if (c.slot == Slot::Orientation) {
      error = eq.orientation_error(y, c.orientation(p), c.track_turns, jacobian ? &J : nullptr);
    } else {
      const SlotMap M = eq.slot_map(c.slot);
      const double sign = (c.slot == Slot::Position) ? 1.0 : load_sign;
      error.noalias() = M * y;
      error -= sign * c.value(p);
      if (jacobian) J = M;
    }
    for (int j = 0; j < B.cols(); ++j) {
      residual->push_back(B.col(j).dot(error));
      if (jacobian) jacobian->push_back(B.col(j).transpose() * J);
    }
  }
  if (hamiltonian_) {
    const double s = at_start ? 0.0 : eq.model().length;
    auto H = [&](const Eigen::VectorXd& state) { return hamiltonian(eq.model(), eq.point(state, s)); };
    residual->push_back(H(y) - hamiltonian_(p));
    if (jacobian) {
      // Central differences of a closed-form function of the state (no integration).
      StateRow row(y.size());
      for (int i = 0; i < y.size(); ++i) {
        const double h = 1e-7 * (1.0 + std::abs(y[i]));
        Eigen::VectorXd plus = y, minus = y;
        plus[i] += h;
        minus[i] -= h;
        row[i] = (H(plus) - H(minus)) / (2.0 * h);
      }
      jacobian->push_back(row);
    }
  }
}

void EndCondition::impose_on(const RodEquations& eq, bool at_start, const Parameters& p, RodPoint* point) const {
  const double load_sign = at_start ? -1.0 : 1.0;
  for (const auto& c : conditions_) {
    const Eigen::MatrixXd B = c.basis(eq);
    const Eigen::MatrixXd P = B * B.transpose();
    switch (c.slot) {
      case Slot::Position: point->r += P * (c.value(p) - point->r); break;
      case Slot::Force: point->n += P * (load_sign * c.value(p) - point->n); break;
      case Slot::Moment: point->m += P * (load_sign * c.value(p) - point->m); break;
      case Slot::Orientation: {
        const OrientationTarget t = c.orientation(p);
        const Mat3 reference = eq.is_planar() ? planar_reference_frame() : Mat3::Identity();
        if (c.directions == Directions::All || eq.is_planar())
          point->R = Eigen::AngleAxisd(t.angle, t.axis.normalized()).toRotationMatrix() * reference;
        point->turn_angle = t.angle;
        break;
      }
    }
  }
}

}  // namespace kirchhoff

#include "kirchhoff/model/obstacle.hpp"

#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace kirchhoff {
namespace {

// Fourth-order central difference of f along e with step h. The result type is f's (a double or
// a Vec3), not `auto`: for a vector f, auto was an Eigen expression holding references to the
// four f(...) temporaries, read after they died (AddressSanitizer: stack-use-after-scope in the
// level set's hessian).
template <class F>
auto central_difference(const F& f, const Vec3& r, const Vec3& e, double h) -> std::decay_t<decltype(f(r))> {
  return (-f(r + 2 * h * e) + 8.0 * f(r + h * e) - 8.0 * f(r - h * e) + f(r - 2 * h * e)) / (12.0 * h);
}

std::string quoted_name(const std::string& name) { return name.empty() ? "" : " '" + name + "'"; }

}  // namespace

Obstacle Obstacle::plane(const Vec3& point, const Vec3& normal, std::string name) {
  if (!(normal.norm() > 0)) throw std::invalid_argument("obstacle" + quoted_name(name) + ": the normal must be non-zero");
  Obstacle o;
  o.shape_ = Shape::Plane;
  o.point_ = point;
  o.direction_ = normal.normalized();
  o.name = std::move(name);
  return o;
}

Obstacle Obstacle::cylinder(const Vec3& centre, const Vec3& axis, double radius, std::string name) {
  if (!(axis.norm() > 0)) throw std::invalid_argument("obstacle" + quoted_name(name) + ": the axis must be non-zero");
  if (!(radius > 0))
    throw std::invalid_argument("obstacle" + quoted_name(name) +
                                ": the radius must be > 0 (a sharp point is the limit of small radii)");
  Obstacle o;
  o.shape_ = Shape::Cylinder;
  o.point_ = centre;
  o.direction_ = axis.normalized();
  o.radius_ = radius;
  o.name = std::move(name);
  return o;
}

Obstacle Obstacle::level_set(std::function<double(const Vec3&)> g, std::string formula, std::string name,
                             double step) {
  if (!(step > 0)) throw std::invalid_argument("obstacle" + quoted_name(name) + ": the difference step must be > 0");
  Obstacle o;
  o.shape_ = Shape::LevelSet;
  o.level_set_ = std::move(g);
  o.formula_ = std::move(formula);
  o.step_ = step;
  o.name = std::move(name);
  return o;
}

double Obstacle::gap(const Vec3& r) const {
  switch (shape_) {
    case Shape::Plane:
      return (r - point_).dot(direction_);
    case Shape::Cylinder:
      return (r - point_).cross(direction_).norm() - radius_;
    case Shape::LevelSet:
      return level_set_(r);
  }
  return NAN;
}

Vec3 Obstacle::gradient(const Vec3& r) const {
  switch (shape_) {
    case Shape::Plane:
      return direction_;
    case Shape::Cylinder: {
      const Vec3 d = r - point_;
      const Vec3 radial = d - d.dot(direction_) * direction_;
      return radial / radial.norm();
    }
    case Shape::LevelSet: {
      Vec3 out;
      for (int i = 0; i < 3; ++i) out[i] = central_difference(level_set_, r, Vec3::Unit(i), step_);
      return out;
    }
  }
  return Vec3::Constant(NAN);
}

Mat3 Obstacle::hessian(const Vec3& r) const {
  switch (shape_) {
    case Shape::Plane:
      return Mat3::Zero();
    case Shape::Cylinder: {
      // (P - e e^T) / rho with P the projection across the axis and e the unit radial direction.
      const Vec3 d = r - point_;
      const Vec3 radial = d - d.dot(direction_) * direction_;
      const double rho = radial.norm();
      const Vec3 e = radial / rho;
      return (Mat3::Identity() - direction_ * direction_.transpose() - e * e.transpose()) / rho;
    }
    case Shape::LevelSet: {
      Mat3 out;
      const auto grad = [this](const Vec3& at) { return gradient(at); };
      for (int j = 0; j < 3; ++j) out.col(j) = central_difference(grad, r, Vec3::Unit(j), step_);
      return 0.5 * (out + out.transpose());
    }
  }
  return Mat3::Constant(NAN);
}

Mat3 Obstacle::normal_derivative(const Vec3& r) const {
  if (shape_ == Shape::Plane) return Mat3::Zero();
  const Vec3 g = gradient(r);
  const double size = g.norm();
  const Vec3 nu = g / size;
  return (Mat3::Identity() - nu * nu.transpose()) * hessian(r) / size;
}

Obstacle::ContactConditions Obstacle::contact_conditions(const Vec3& r, const Vec3& tangent) const {
  ContactConditions out;
  if (shape_ != Shape::Cylinder) {
    const Vec3 g = gradient(r);
    out.gap = gap(r);
    out.tangency = g.dot(tangent);
    out.normal = g.normalized();
    return out;
  }
  const Vec3 d = (r - point_) - (r - point_).dot(direction_) * direction_;
  const Vec3 across = direction_.cross(tangent);
  out.normal = (d.dot(across) >= 0 ? 1.0 : -1.0) * across.normalized();
  out.gap = d.dot(out.normal) - radius_;
  out.tangency = d.dot(tangent);
  return out;
}

std::string Obstacle::describe() const {
  std::ostringstream out;
  out << "obstacle" << quoted_name(name) << " (";
  switch (shape_) {
    case Shape::Plane:
      out << "plane through (" << point_.transpose() << ") with normal (" << direction_.transpose() << ")";
      break;
    case Shape::Cylinder:
      out << "cylinder of radius " << radius_ << " around (" << point_.transpose() << ") along ("
          << direction_.transpose() << ")";
      break;
    case Shape::LevelSet:
      out << "level set " << formula_ << " >= 0";
      break;
  }
  out << ")";
  return out.str();
}

}  // namespace kirchhoff

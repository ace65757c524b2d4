// Rigid frictionless obstacles as gap functions: the rod's centreline must stay where g(r) >= 0.
//
// A contact at r pushes the rod along the unit normal nu = grad g / |grad g| (into the admissible
// side) with a force >= 0. The shooting core imposes g = 0 and tangency (grad g . r' = 0) at a
// point contact; the event that a point contact spreads into an interval of contact watches
// d^2 g(r(s)) / ds^2 = grad g . r'' + r'^T (Hessian g) r', which is why an obstacle gives its
// Hessian too.
//
// Shapes:
//   - plane: g = (r - point) . normal; a wall, two of them a cavity. A planar rod may lie flat on
//     it over an interval (an extended contact, see PointContact).
//   - cylinder: g = |(r - centre) x axis| - radius, radius > 0; for a planar rod with the axis
//     normal to its plane, a disc: a pin, an indenter, the rounded edge of a table or a corner. A
//     uniform planar rod may wrap around a disc (the extended contact's curved form); see
//     extended_contact_unsupported for what is not modelled.
//     A sharp point is the limit radius -> 0 (the contact conditions are singular at radius 0, so
//     it is refused: take a radius small against the rod's length).
//   - level set: any smooth g(x, y, z) (a case-file expression), its gradient and Hessian by
//     fourth-order central differences with step h (error ~ h^4 g''''' + 1e-16 |g| / h).
#pragma once

#include <functional>
#include <string>

#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff {

class Obstacle {
 public:
  enum class Shape { Plane, Cylinder, LevelSet };

  // Throw std::invalid_argument for a zero normal or axis, a radius <= 0 or a step <= 0.
  static Obstacle plane(const Vec3& point, const Vec3& normal, std::string name = "");
  static Obstacle cylinder(const Vec3& centre, const Vec3& axis, double radius, std::string name = "");
  static Obstacle level_set(std::function<double(const Vec3&)> g, std::string formula, std::string name = "",
                            double step = 1e-3);

  double gap(const Vec3& r) const;
  Vec3 gradient(const Vec3& r) const;
  Mat3 hessian(const Vec3& r) const;
  // Direction of the reaction at r: grad g / |grad g|.
  Vec3 normal(const Vec3& r) const { return gradient(r).normalized(); }
  // d normal / d r: (I - nu nu^T) Hessian / |grad g|; zero for a plane.
  Mat3 normal_derivative(const Vec3& r) const;

  // What a point contact at r with tangent t imposes, gap = 0 and tangency = 0, and the direction
  // of its reaction. Planes and level sets: g, grad g . t and grad g / |grad g|. Cylinders use the
  // rod's side instead of the centre's direction: nu = +-(axis x t) / |axis x t| (the side the rod
  // is on), gap = d . nu - radius and tangency = d . t with d the radial offset of r from the
  // axis. At the solution d = radius nu, the same point as before, but no row or jump divides by
  // |d| ~ radius: small pins are as well conditioned as large ones (with grad g the residual's
  // round-off floor grows like force / radius).
  struct ContactConditions {
    double gap = 0.0;
    double tangency = 0.0;
    Vec3 normal = Vec3::Zero();
  };
  ContactConditions contact_conditions(const Vec3& r, const Vec3& tangent) const;

  Shape shape() const { return shape_; }
  bool is_flat() const { return shape_ == Shape::Plane; }
  // "plane", "cylinder" or "level set", with its data, for messages and output.
  std::string describe() const;

  std::string name;

  // The plane's point and unit normal, the cylinder's centre and unit axis.
  const Vec3& point() const { return point_; }
  const Vec3& direction() const { return direction_; }
  double radius() const { return radius_; }

 private:
  Shape shape_ = Shape::Plane;
  Vec3 point_ = Vec3::Zero();
  Vec3 direction_ = Vec3::UnitY();
  double radius_ = 0.0;
  std::function<double(const Vec3&)> level_set_;
  std::string formula_;
  double step_ = 1e-3;
};

}  // namespace kirchhoff

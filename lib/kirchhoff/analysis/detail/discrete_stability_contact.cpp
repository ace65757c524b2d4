// The closest approach of the quadratic through three gaps (see discrete_stability_contact.hpp).
#include "kirchhoff/analysis/detail/discrete_stability_contact.hpp"

namespace kirchhoff {

ClosestApproach closest_approach(double before, double middle, double after, double h) {
  ClosestApproach c;
  const double a = (after - before) / (2 * h);
  c.curvature = (after - 2 * middle + before) / (h * h);
  c.offset = -a / c.curvature;
  c.value = middle - a * a / (2 * c.curvature);
  const Eigen::Vector3d da(-1 / (2 * h), 0.0, 1 / (2 * h)), db = Eigen::Vector3d(1.0, -2.0, 1.0) / (h * h);
  // Envelope theorem: dq* = dq(t*) = dg_0 + t* da + t*^2 / 2 db.
  c.weights = Eigen::Vector3d(0.0, 1.0, 0.0) + c.offset * da + 0.5 * c.offset * c.offset * db;
  c.direction = da + c.offset * db;
  return c;
}

}  // namespace kirchhoff

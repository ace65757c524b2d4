// Internal: the state layout of the spatial rod equations (spatial_equations.cpp), shared with the
// code that reads the state directly (the rod held on a cylinder, rod_on_cylinder.cpp).
//
// State (14): r[0..2], q[3..6] = (w, x, y, z), n[7..9], m[10..12], turn angle chi[13]. The frame
// is R(q / |q|), orthonormal to round-off for any q.
#pragma once

#include "kirchhoff/equations/detail/dual.hpp"

namespace kirchhoff::detail {

constexpr int kSpatialStateSize = 14;
enum SpatialIndex { kR = 0, kQ = 3, kN = 7, kM = 10, kChi = 13 };

// The turn angle chi = 2 atan2(qz, w) is undefined where the tangent points along -e3: there
// w = qz = 0 whatever the twist, and chi' = 2 (w qz' - qz w') / (w^2 + qz^2) is 0 / 0. A rod
// hanging along -e3 could not be integrated at all ("more than max_steps"), and one passing
// through -e3 (a ring closed on itself) only by a stepper that happened to step over it. The
// denominator is held at this share of |q|^2 at least: within 2e-4 rad of -e3 (w^2 + qz^2 =
// cos^2 of half the tangent's angle from e3), where the turn about e3 means nothing, chi turns at
// most about 1e4 times the curvature's rate, smoothly; farther away chi is exact.
constexpr double kTurnAngleFloor = 1e-8;
inline double turn_angle_floor(double w, double qx, double qy, double qz) {
  return kTurnAngleFloor * (w * w + qx * qx + qy * qy + qz * qz);
}

// w^2 + qz^2 held at kTurnAngleFloor |q|^2 at least. The floor is a constant to the derivatives
// (on dual numbers and in the written-out variations alike): chi's row of the Jacobian is
// meaningless where it applies, and the state's other rows do not read chi.
template <class T>
T turn_angle_denominator(const T& w, const T& qx, const T& qy, const T& qz) {
  const T d = w * w + qz * qz;
  const double floor = turn_angle_floor(value(w), value(qx), value(qy), value(qz));
  return value(d) >= floor ? d : T(floor);
}

// Rotation matrix of a (not necessarily unit) quaternion, row-major in R[3][3].
template <class T>
void rotation_from_quaternion(const T* q, T R[3][3]) {
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  // Each product once (on dual numbers a product is the costly operation): the same values, in
  // the same order of operations, as writing them out in every entry.
  const T ww = w * w, xx = x * x, yy = y * y, zz = z * z;
  const T xy = x * y, xz = x * z, yz = y * z, wx = w * x, wy = w * y, wz = w * z;
  const T inv = 1.0 / (ww + xx + yy + zz);
  R[0][0] = (ww + xx - yy - zz) * inv;
  R[0][1] = 2.0 * (xy - wz) * inv;
  R[0][2] = 2.0 * (xz + wy) * inv;
  R[1][0] = 2.0 * (xy + wz) * inv;
  R[1][1] = (ww - xx + yy - zz) * inv;
  R[1][2] = 2.0 * (yz - wx) * inv;
  R[2][0] = 2.0 * (xz - wy) * inv;
  R[2][1] = 2.0 * (yz + wx) * inv;
  R[2][2] = (ww - xx - yy + zz) * inv;
}

}  // namespace kirchhoff::detail

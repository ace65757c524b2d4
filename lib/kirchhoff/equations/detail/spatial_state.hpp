// Internal: the state layout of the spatial rod equations (spatial_equations.cpp), shared with the
// code that reads the state directly (the rod held on a cylinder, rod_on_cylinder.cpp).
//
// State (14): r[0..2], q[3..6] = (w, x, y, z), n[7..9], m[10..12], turn angle chi[13]. The frame
// is R(q / |q|), orthonormal to round-off for any q.
#pragma once

namespace kirchhoff::detail {

constexpr int kSpatialStateSize = 14;
enum SpatialIndex { kR = 0, kQ = 3, kN = 7, kM = 10, kChi = 13 };

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

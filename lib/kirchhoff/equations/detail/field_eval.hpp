// Internal: evaluating an external field on the scalar types of the right-hand sides.
#pragma once

#include "kirchhoff/equations/detail/dual.hpp"
#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff::detail {

// External force on a state of scalar type T: values for double, value plus gradient-times-
// direction for Dual numbers.
inline void field_force(const ExternalField& f, double s, const double* r, double* out) {
  const Vec3 v = f.force(s, Vec3(r[0], r[1], r[2]));
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}
template <int N>
void field_force(const ExternalField& f, double s, const Dual<N>* r, Dual<N>* out) {
  const Vec3 r0(r[0].v, r[1].v, r[2].v);
  const Vec3 v = f.force(s, r0);
  const Mat3 G = f.force_gradient(s, r0);
  for (int i = 0; i < 3; ++i) {
    out[i] = Dual<N>(v[i]);
    for (int k = 0; k < N; ++k) out[i].d[k] = G(i, 0) * r[0].d[k] + G(i, 1) * r[1].d[k] + G(i, 2) * r[2].d[k];
  }
}

}  // namespace kirchhoff::detail

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

// The field's tangent stiffness (ExternalField::add_tangent_stiffness): nothing on the
// equilibrium (double); on the variational equations (Dual), dn' += S_rr dr + S_rt dd3 and
// dm' += d3 x (S_tr dr + S_tt dd3) at the state's values r, d3 and d3' (dr and dd3 are the dual
// parts of r and d3).
inline void add_tangent_stiffness(const ExternalField&, double, const double*, const double* const*, const double*,
                                  double*, double*) {}
template <int N>
void add_tangent_stiffness(const ExternalField& f, double s, const Dual<N>* r, const Dual<N>* const* d3,
                           const double* d3_prime, Dual<N>* dn, Dual<N>* dm) {
  const Vec3 r0(r[0].v, r[1].v, r[2].v), t0(d3[0]->v, d3[1]->v, d3[2]->v);
  Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();
  f.add_tangent_stiffness(s, r0, t0, Vec3(d3_prime[0], d3_prime[1], d3_prime[2]), &S);
  if (S.isZero(0.0)) return;
  for (int k = 0; k < N; ++k) {
    Eigen::Matrix<double, 6, 1> z;
    z << r[0].d[k], r[1].d[k], r[2].d[k], d3[0]->d[k], d3[1]->d[k], d3[2]->d[k];
    const Eigen::Matrix<double, 6, 1> g = S * z;
    const Vec3 couple = t0.cross(Vec3(g[3], g[4], g[5]));
    for (int i = 0; i < 3; ++i) {
      dn[i].d[k] += g[i];
      dm[i].d[k] += couple[i];
    }
  }
}

}  // namespace kirchhoff::detail

// Internal: the variational equations of the spatial rod (spatial_equations.cpp) written out: its
// matrices (exact, and looser with IntegratorOptions::sensitivity_tol, the state then in a pass of
// its own: detail::flow_with_loose_pass_into), the directions of RodEquations::flow_directions (the
// stability index's Jacobi fields) and, where the unfolding couple mu is an unknown
// (RodModel::unfolding_sensitivity), the state's sensitivity to it (SegmentFlow::dy_dunfolding).
//
// Why: on Dual<10> every product of the right-hand side carries ten derivatives, the quaternion's
// rotation matrix included, and the dual pass was about half of a 3D continuation point's time.
// Written out, the rotation and the body-frame quantities are formed once per evaluation on
// doubles and each column costs its own linearisation only. The same components are under error
// control as with the dual numbers, so the steps are theirs.
//
// Scope: a rod with neither an external field nor a supporting cylinder (then n is constant, so
// the rows n of Phi are those of the identity, and nothing depends on r(s0) or chi(s0), so those
// columns are unit vectors). Every other rod keeps the dual numbers.
//
// With y = (r, q, n, m, chi) and R = R(q / |q|) (spatial_state.hpp), a perturbation dq turns the
// frame by the body-frame angle omega = 2 vec(conj(q) dq) / |q|^2 (q + dq = q (1 + conj(q) dq / |q|^2),
// and a quaternion's scalar part does not rotate to first order): dR = R [omega]x. Then
//   du = B^-1 (m_body x omega + R^T dm),  dv = A^-1 (n_body x omega + R^T dn) (extensible rods, else 0),
//   dr' = R (omega x v + dv),  dq' = (dq (0, u) + q (0, du)) / 2,
//   dm' = dn x r' + n x dr' (+ the unfolding's mu dR e3 = mu R (omega_2, -omega_1, 0)),
//   dchi' from chi' = 2 (w z' - z w') / (w^2 + z^2) by the quotient rule,
// each a loop over the columns (contiguous in the row-major block, so they vectorise); the
// sensitivity to mu is one more column, zero at s0, whose rows m gain df/dmu = d3 - e3.
#pragma once

#include <array>

#include "kirchhoff/equations/detail/compliances.hpp"
#include "kirchhoff/equations/detail/integrator_impl.hpp"
#include "kirchhoff/equations/detail/spatial_state.hpp"
#include "kirchhoff/equations/integrator.hpp"
#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff::detail {

// The carried block of a set of C perturbation columns: rows r, q, m, chi (the rows n are
// constant without a field, so they are kept beside the integration, not in it).
constexpr int kVariationRows = 11;
constexpr std::array<int, kVariationRows> kVariationRowOf{kR,     kR + 1, kR + 2, kQ,     kQ + 1, kQ + 2,
                                                          kQ + 3, kM,     kM + 1, kM + 2, kChi};
// Where the block's rows start (row-major, C per row).
enum VariationRow { kRowR = 0, kRowQ = 3, kRowM = 7, kRowChi = 10 };
template <int C>
constexpr int kVariedStateSize = kSpatialStateSize + kVariationRows * C;

// The columns of Phi that are not unit vectors (nothing depends on r(s0) or chi(s0)).
constexpr int kVariationColumns = 10;
constexpr std::array<int, kVariationColumns> kVariationColumnOf{kQ,     kQ + 1, kQ + 2, kQ + 3, kN,
                                                                kN + 1, kN + 2, kM,     kM + 1, kM + 2};
constexpr int kColumnN = 4;  // the columns of n(s0) are kColumnN + 0, 1, 2
static_assert(kVariationColumnOf[kColumnN] == kN);

// Whether the written-out equations hold for this rod (the scope above).
inline bool has_written_out_variations(const RodModel& model, bool on_cylinder) {
  return !model.field && !on_cylinder;
}

// What one evaluation shares between the columns: the frame, the strains, the body-frame loads.
struct FrameAtPoint {
  double R[3][3];
  double inv_S;                   // 1 / |q|^2
  double u[3], v[3];              // strains
  double m_body[3], n_body[3];    // R^T m, R^T n
  double flex[3], compliance[3];  // 1/B, 1/A (0 for an inextensible rod)
};

inline FrameAtPoint frame_at_point(const RodModel& model, const Compliances& compliances, const double* y, double s) {
  FrameAtPoint f;
  rotation_from_quaternion(y + kQ, f.R);
  const double* q = y + kQ;
  f.inv_S = 1.0 / (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int i = 0; i < 3; ++i) {
    f.m_body[i] = f.R[0][i] * y[kM] + f.R[1][i] * y[kM + 1] + f.R[2][i] * y[kM + 2];
    f.n_body[i] = f.R[0][i] * y[kN] + f.R[1][i] * y[kN + 1] + f.R[2][i] * y[kN + 2];
    f.flex[i] = compliances.bending(model, i, s);
    f.u[i] = model.u_hat[i](s) + f.m_body[i] * f.flex[i];
    f.compliance[i] = model.extensible ? compliances.stretching(model, i, s) : 0.0;
    f.v[i] = model.v_hat[i](s) + (model.extensible ? f.n_body[i] * f.compliance[i] : 0.0);
  }
  return f;
}

// d/ds of the state (by `state_rhs`, the equations' own right-hand side on doubles) and of the
// carried block of C perturbation columns, whose force perturbations are the constants dn, for a
// rod in scope (has_written_out_variations). Column `forced` (if >= 0) is the state's derivative
// with respect to the unfolding couple mu: its equations gain the forcing df/dmu = (0, 0, 0,
// d3 - e3 in the rows m).
template <int C, class StateRhs>
void rhs_with_written_out_variations(const RodModel& model, const Compliances& compliances, const StateRhs& state_rhs,
                                     const double (&dn)[3][C], int forced, const double* y, double* dy, double s) {
  state_rhs(y, dy, s);
  const FrameAtPoint f = frame_at_point(model, compliances, y, s);
  const double(&R)[3][3] = f.R;
  const double *q = y + kQ, *n = y + kN, *dr = dy + kR;  // dr: r' = R v
  const double *P = y + kSpatialStateSize, *dq[4], *dm[3];
  double* dP = dy + kSpatialStateSize;
  for (int a = 0; a < 4; ++a) dq[a] = P + (kRowQ + a) * C;
  for (int a = 0; a < 3; ++a) dm[a] = P + (kRowM + a) * C;
  double omega[3][C], du[3][C], e[3][C];  // e = omega x v + dv, so that dr' = R e
  const double k = 2.0 * f.inv_S;
  for (int j = 0; j < C; ++j) {  // omega = 2 (w dv - dw v - v x dv) / |q|^2, with q = (w, v)
    omega[0][j] = k * (q[0] * dq[1][j] - dq[0][j] * q[1] - (q[2] * dq[3][j] - q[3] * dq[2][j]));
    omega[1][j] = k * (q[0] * dq[2][j] - dq[0][j] * q[2] - (q[3] * dq[1][j] - q[1] * dq[3][j]));
    omega[2][j] = k * (q[0] * dq[3][j] - dq[0][j] * q[3] - (q[1] * dq[2][j] - q[2] * dq[1][j]));
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < C; ++j) {
      const double rotated = f.m_body[i1] * omega[i2][j] - f.m_body[i2] * omega[i1][j];
      du[i][j] = f.flex[i] * (rotated + R[0][i] * dm[0][j] + R[1][i] * dm[1][j] + R[2][i] * dm[2][j]);
      e[i][j] = omega[i1][j] * f.v[i2] - omega[i2][j] * f.v[i1];
      if (model.extensible)
        e[i][j] += f.compliance[i] * (f.n_body[i1] * omega[i2][j] - f.n_body[i2] * omega[i1][j] +
                                      R[0][i] * dn[0][j] + R[1][i] * dn[1][j] + R[2][i] * dn[2][j]);
    }
  }
  double d_dr[3][C];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < C; ++j) {
      d_dr[i][j] = R[i][0] * e[0][j] + R[i][1] * e[1][j] + R[i][2] * e[2][j];
      dP[(kRowR + i) * C + j] = d_dr[i][j];
    }
  // dq' = (dq (0, u) + q (0, du)) / 2 (q' = q (0, u) / 2 in spatial_equations.cpp).
  const double* u = f.u;
  double* dw = dP + kRowQ * C;
  double *dx = dw + C, *d_y = dw + 2 * C, *dz = dw + 3 * C;
  for (int j = 0; j < C; ++j) {
    dw[j] = -0.5 * (dq[1][j] * u[0] + q[1] * du[0][j] + dq[2][j] * u[1] + q[2] * du[1][j] + dq[3][j] * u[2] +
                    q[3] * du[2][j]);
    dx[j] = 0.5 * (dq[0][j] * u[0] + q[0] * du[0][j] + dq[2][j] * u[2] + q[2] * du[2][j] - dq[3][j] * u[1] -
                   q[3] * du[1][j]);
    d_y[j] = 0.5 * (dq[0][j] * u[1] + q[0] * du[1][j] + dq[3][j] * u[0] + q[3] * du[0][j] - dq[1][j] * u[2] -
                    q[1] * du[2][j]);
    dz[j] = 0.5 * (dq[0][j] * u[2] + q[0] * du[2][j] + dq[1][j] * u[1] + q[1] * du[1][j] - dq[2][j] * u[0] -
                   q[2] * du[0][j]);
  }
  // dm' = dn x r' + n x dr' + mu R (omega_2, -omega_1, 0) (the unfolding's couple mu (d3 - e3)).
  const double mu = model.symmetry_unfolding;
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < C; ++j)
      dP[(kRowM + i) * C + j] = dn[i1][j] * dr[i2] - dn[i2][j] * dr[i1] + n[i1] * d_dr[i2][j] -
                                n[i2] * d_dr[i1][j] + mu * (R[i][0] * omega[1][j] - R[i][1] * omega[0][j]);
    if (forced >= 0) dP[(kRowM + i) * C + forced] += R[i][2] - (i == 2 ? 1.0 : 0.0);
  }
  // chi' = 2 N / D with N = w z' - z w', D = w^2 + z^2, or where the tangent points along -e3 the
  // constant floor (turn_angle_denominator, the same branch as the state's).
  const double w = q[0], z = q[3], w_prime = dy[kQ], z_prime = dy[kQ + 3];
  const double raw = w * w + z * z, floor = turn_angle_floor(w, q[1], q[2], z);
  const bool floored = !(raw >= floor);
  const double D = floored ? floor : raw, N = w * z_prime - z * w_prime;
  for (int j = 0; j < C; ++j) {
    const double dN = dq[0][j] * z_prime + w * dz[j] - dq[3][j] * w_prime - z * dw[j];
    const double dD = floored ? 0.0 : 2.0 * (w * dq[0][j] + z * dq[3][j]);
    dP[kRowChi * C + j] = 2.0 * (dN * D - N * dD) / (D * D);
  }
}

// Marches the state and the carried block x (kVariedStateSize<C>: the state, then the block
// row-major) from s0 to s1 by rhs_with_written_out_variations, every carried component under
// error control (as the dual numbers have it), continuing from the step size *ds and leaving there
// the one proposed next. Returns the steps taken; adds the right-hand sides to *evaluations.
template <int C, class StateRhs>
long march_written_out(const RodModel& model, const Compliances& compliances, const StateRhs& state_rhs,
                       const double (&dn)[3][C], int forced, std::array<double, kVariedStateSize<C>>& x, double s0,
                       double s1, const IntegratorOptions& options, double* ds, long* evaluations) {
  using State = std::array<double, kVariedStateSize<C>>;
  auto system = [&](const State& y, State& dy, double s) {
    ++*evaluations;
    rhs_with_written_out_variations<C>(model, compliances, state_rhs, dn, forced, y.data(), dy.data(), s);
  };
  return march_carrying(x, s0, s1, system, options, ds);
}

// The state and the columns of `directions` (at most C, rows as the state's; fewer are padded with
// zero columns, which stay zero) carried from s0 to s1 by march_written_out.
template <int C, class StateRhs>
DirectionalFlow written_out_directions(const RodModel& model, const Compliances& compliances,
                                       const StateRhs& state_rhs, const Eigen::VectorXd& y0,
                                       const Eigen::MatrixXd& directions, double s0, double s1,
                                       const IntegratorOptions& options, double* ds) {
  const int k = static_cast<int>(directions.cols());
  std::array<double, kVariedStateSize<C>> x{};
  double dn[3][C] = {};
  for (int i = 0; i < kSpatialStateSize; ++i) x[i] = y0[i];
  for (int j = 0; j < k; ++j) {
    for (int r = 0; r < kVariationRows; ++r) x[kSpatialStateSize + r * C + j] = directions(kVariationRowOf[r], j);
    for (int a = 0; a < 3; ++a) dn[a][j] = directions(kN + a, j);
  }
  DirectionalFlow out;
  out.steps =
      march_written_out<C>(model, compliances, state_rhs, dn, -1, x, s0, s1, options, ds, &out.rhs_evaluations);
  out.y = Eigen::Map<const Eigen::Matrix<double, kSpatialStateSize, 1>>(x.data());
  out.directions.resize(kSpatialStateSize, k);
  for (int j = 0; j < k; ++j) {
    for (int r = 0; r < kVariationRows; ++r) out.directions(kVariationRowOf[r], j) = x[kSpatialStateSize + r * C + j];
    for (int a = 0; a < 3; ++a) out.directions(kN + a, j) = dn[a][j];
  }
  return out;
}

// The columns of Phi that are not unit vectors (kVariationColumnOf) by march_written_out, the
// others unit vectors: the whole of Phi over [s0, s1], into *out (its storage reused); C =
// kVariationColumns + 1 adds the forced column of the unfolding couple's sensitivity
// (SegmentFlow::dy_dunfolding). Continues from the step size *ds and leaves there the one
// proposed next.
template <int C, class StateRhs>
void written_out_phi_into(const RodModel& model, const Compliances& compliances, const StateRhs& state_rhs,
                          const Eigen::VectorXd& y0, double s0, double s1, const IntegratorOptions& options,
                          double* ds, SegmentFlow* out) {
  static_assert(C == kVariationColumns || C == kVariationColumns + 1);
  constexpr bool with_unfolding = C > kVariationColumns;
  std::array<double, kVariedStateSize<C>> x{};
  double dn[3][C] = {};
  for (int i = 0; i < kSpatialStateSize; ++i) x[i] = y0[i];
  for (int r = 0; r < kVariationRows; ++r)
    for (int j = 0; j < kVariationColumns; ++j)
      x[kSpatialStateSize + r * C + j] = kVariationRowOf[r] == kVariationColumnOf[j];
  for (int a = 0; a < 3; ++a) dn[a][kColumnN + a] = 1.0;
  const int forced = with_unfolding ? kVariationColumns : -1;
  out->rhs_evaluations = 0;
  out->steps =
      march_written_out<C>(model, compliances, state_rhs, dn, forced, x, s0, s1, options, ds, &out->rhs_evaluations);
  out->y = Eigen::Map<const Eigen::Matrix<double, kSpatialStateSize, 1>>(x.data());
  out->Phi.setIdentity(kSpatialStateSize, kSpatialStateSize);
  for (int r = 0; r < kVariationRows; ++r)
    for (int j = 0; j < kVariationColumns; ++j)
      out->Phi(kVariationRowOf[r], kVariationColumnOf[j]) = x[kSpatialStateSize + r * C + j];
  if (with_unfolding) {  // (zero at s0 and in the rows n, which mu does not move)
    out->dy_dunfolding.setZero(kSpatialStateSize);
    for (int r = 0; r < kVariationRows; ++r)
      out->dy_dunfolding[kVariationRowOf[r]] = x[kSpatialStateSize + r * C + forced];
  } else {
    out->dy_dunfolding.resize(0);
  }
}

// Phi (and dy/dmu where the model carries it) over [s0, s1] into *out, from the options' initial step.
template <class StateRhs>
void written_out_variations_pass_into(const RodModel& model, const Compliances& compliances,
                                      const StateRhs& state_rhs, const Eigen::VectorXd& y0, double s0, double s1,
                                      const IntegratorOptions& options, SegmentFlow* out) {
  double ds = options.initial_step * (s1 - s0);
  if (model.unfolding_sensitivity)
    return written_out_phi_into<kVariationColumns + 1>(model, compliances, state_rhs, y0, s0, s1, options, &ds, out);
  written_out_phi_into<kVariationColumns>(model, compliances, state_rhs, y0, s0, s1, options, &ds, out);
}

// written_out_directions with C the first of Cs (ascending) that holds the columns; false when none does.
template <int C, int... More, class StateRhs>
bool written_out_directions_fitting(const RodModel& model, const Compliances& compliances, const StateRhs& state_rhs,
                                    const Eigen::VectorXd& y0, const Eigen::MatrixXd& directions, double s0,
                                    double s1, const IntegratorOptions& options, double* ds, DirectionalFlow* out) {
  if (directions.cols() <= C) {
    *out = written_out_directions<C>(model, compliances, state_rhs, y0, directions, s0, s1, options, ds);
    return true;
  }
  if constexpr (sizeof...(More) > 0)
    return written_out_directions_fitting<More...>(model, compliances, state_rhs, y0, directions, s0, s1, options, ds,
                                                   out);
  else
    return false;
}

// RodEquations::flow_directions by written_out_directions: the columns themselves when Cs (the
// column counts compiled) hold them, else through the non-unit columns of Phi; the state at the
// options' own tolerance in a pass of its own where sensitivity_tol is looser (the contract of
// detail::flow_directions on dual numbers).
template <int... Cs, class StateRhs>
DirectionalFlow written_out_directional_flow(const RodModel& model, const Compliances& compliances,
                                             const StateRhs& state_rhs, const Eigen::VectorXd& y0,
                                             const Eigen::MatrixXd& directions, double s0, double s1,
                                             const IntegratorOptions& options, CarriedSteps* carried) {
  const bool loose = options.sensitivity_tol > options.abs_tol;
  IntegratorOptions carried_options = options;
  if (loose) carried_options.abs_tol = carried_options.rel_tol = options.sensitivity_tol;
  DirectionalFlow out;
  if (!written_out_directions_fitting<Cs...>(model, compliances, state_rhs, y0, directions, s0, s1, carried_options,
                                             &carried->directions, &out)) {
    SegmentFlow phi;
    written_out_phi_into<kVariationColumns>(model, compliances, state_rhs, y0, s0, s1, carried_options,
                                            &carried->directions, &phi);
    out.y = std::move(phi.y);
    out.directions = phi.Phi * directions;
    out.steps = phi.steps;
    out.rhs_evaluations = phi.rhs_evaluations;
  }
  if (loose) carry_state_alone<kSpatialStateSize>(state_rhs, y0, s0, s1, options, carried, &out);
  return out;
}

}  // namespace kirchhoff::detail

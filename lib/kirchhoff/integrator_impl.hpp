// Internal: the odeint plumbing shared by the spatial and planar equations. A right-hand side
// is any object with `template <class T> void operator()(const T* y, T* dyds, double s) const`,
// evaluated on double for the state and on Dual<N> for the variational equations.
#pragma once

#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>

#include "kirchhoff/dual.hpp"
#include "kirchhoff/integrator.hpp"

namespace kirchhoff::detail {

namespace odeint = boost::numeric::odeint;

// Arclength marching with an odeint controlled stepper. We drive try_step ourselves (rather
// than integrate_adaptive) to cap the number of steps and to land exactly on s1.
template <class State, class System>
long march(State& x, double s0, double s1, const System& system, const IntegratorOptions& opt) {
  const double span = s1 - s0;
  if (span == 0.0) return 0;
  double s = s0;
  double ds = opt.initial_step * span;
  long steps = 0;
  auto advance = [&](auto stepper) {
    while ((span > 0) ? (s < s1) : (s > s1)) {
      if ((span > 0) ? (s + ds > s1) : (s + ds < s1)) ds = s1 - s;
      if (stepper.try_step(system, x, s, ds) == odeint::success) ++steps;
      // A step meant to land on s1 can stop an ulp short of it (s + (s1 - s) rounds): the sliver
      // left is below round-off, not a step to take (taking it read as a step-size underflow).
      if (std::abs(s1 - s) <= 1e-14 * std::abs(span)) break;
      if (steps + 1 > opt.max_steps) throw IntegrationError("more than max_steps integration steps");
      if (!std::isfinite(ds) || std::abs(ds) < 1e-14 * std::abs(span))
        throw IntegrationError("step size underflow near s = " + std::to_string(s));
    }
  };
  if (opt.stepper == IntegratorOptions::Stepper::Dopri5)
    advance(odeint::make_controlled(opt.abs_tol, opt.rel_tol, odeint::runge_kutta_dopri5<State>()));
  else
    advance(odeint::make_controlled(opt.abs_tol, opt.rel_tol, odeint::runge_kutta_fehlberg78<State>()));
  for (double v : x)
    if (!std::isfinite(v)) throw IntegrationError("non-finite state");
  return steps;
}

// Integrates the state alone.
template <int N, class Rhs>
SegmentFlow flow_state(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1,
                       const IntegratorOptions& opt) {
  using State = std::array<double, N>;
  State x;
  for (int i = 0; i < N; ++i) x[i] = y0[i];
  long evaluations = 0;
  auto system = [&](const State& y, State& dy, double s) {
    ++evaluations;
    rhs(y.data(), dy.data(), s);
  };
  SegmentFlow out;
  out.steps = march(x, s0, s1, system, opt);
  out.y = Eigen::Map<const Eigen::Matrix<double, N, 1>>(x.data());
  out.rhs_evaluations = evaluations;
  return out;
}

// Integrates the state together with the variational equations Phi' = (df/dy) Phi, Phi(s0) = I,
// by evaluating the right-hand side on Dual<K> seeded with K of the N columns of Phi (the others
// may be known in closed form by the caller): cheaper by about (N/K)^2 in the derivative
// arithmetic. Returns Phi restricted to those columns (N x K) in out.Phi.
template <int N, int K, class Rhs>
SegmentFlow flow_with_partial_sensitivities(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1,
                                            const IntegratorOptions& opt, const std::array<int, K>& seeds);

// Phi at opt.sensitivity_tol, the state at the state's own tolerance (IntegratorOptions).
template <int N, int K, class Rhs>
SegmentFlow flow_with_loose_sensitivities(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1,
                                          const IntegratorOptions& opt, const std::array<int, K>& seeds) {
  IntegratorOptions loose = opt;
  loose.abs_tol = loose.rel_tol = opt.sensitivity_tol;
  loose.sensitivity_tol = 0.0;
  SegmentFlow out = flow_with_partial_sensitivities<N, K>(rhs, y0, s0, s1, loose, seeds);
  const SegmentFlow state = flow_state<N>(rhs, y0, s0, s1, opt);
  out.y = state.y;
  out.steps += state.steps;
  out.rhs_evaluations += state.rhs_evaluations;
  return out;
}

template <int N, int K, class Rhs>
SegmentFlow flow_with_partial_sensitivities(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1,
                                            const IntegratorOptions& opt, const std::array<int, K>& seeds) {
  if (opt.sensitivity_tol > opt.abs_tol)  // (abs_tol > 0, so 0 keeps the one pass)
    return flow_with_loose_sensitivities<N, K>(rhs, y0, s0, s1, opt, seeds);
  using State = std::array<double, N + N * K>;  // y, then the N x K block row-major
  State x{};
  for (int i = 0; i < N; ++i) x[i] = y0[i];
  for (int j = 0; j < K; ++j) x[N + seeds[j] * K + j] = 1.0;
  long evaluations = 0;
  auto system = [&](const State& y, State& dy, double s) {
    ++evaluations;
    std::array<Dual<K>, N> yd, dyd;
    for (int i = 0; i < N; ++i) {
      yd[i].v = y[i];
      for (int j = 0; j < K; ++j) yd[i].d[j] = y[N + i * K + j];
    }
    rhs(yd.data(), dyd.data(), s);
    for (int i = 0; i < N; ++i) {
      dy[i] = dyd[i].v;
      for (int j = 0; j < K; ++j) dy[N + i * K + j] = dyd[i].d[j];
    }
  };
  SegmentFlow out;
  out.steps = march(x, s0, s1, system, opt);
  out.y = Eigen::Map<const Eigen::Matrix<double, N, 1>>(x.data());
  out.Phi = Eigen::Map<const Eigen::Matrix<double, N, K, Eigen::RowMajor>>(x.data() + N);
  out.rhs_evaluations = evaluations;
  return out;
}

// All N directions seeded: the full state-transition matrix.
template <int N, class Rhs>
SegmentFlow flow_with_sensitivities(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1,
                                    const IntegratorOptions& opt) {
  std::array<int, N> all;
  for (int i = 0; i < N; ++i) all[i] = i;
  return flow_with_partial_sensitivities<N, N>(rhs, y0, s0, s1, opt, all);
}

// States at the requested arclengths (sorted; repeated values allowed). Both steppers step onto
// each sample point, so profiles keep the integration's accuracy. (Dopri5's dense output is not
// used: odeint's integrate_times interpolates a sample equal to the start before the first step,
// from the stepper's uninitialised previous state, and gave NaN there.)
template <int N, class Rhs>
std::vector<Eigen::VectorXd> sample_states(const Rhs& rhs, const Eigen::VectorXd& y0,
                                           const std::vector<double>& s_values,
                                           const IntegratorOptions& opt) {
  using State = std::array<double, N>;
  State x;
  for (int i = 0; i < N; ++i) x[i] = y0[i];
  std::vector<Eigen::VectorXd> out;
  if (s_values.empty()) return out;
  auto system = [&](const State& y, State& dy, double s) { rhs(y.data(), dy.data(), s); };
  auto observer = [&](const State& y, double) {
    out.push_back(Eigen::Map<const Eigen::Matrix<double, N, 1>>(y.data()));
  };
  const double span = s_values.back() - s_values.front();
  const double ds = opt.initial_step * (span > 0 ? span : 1.0);
  if (opt.stepper == IntegratorOptions::Stepper::Dopri5) {
    auto stepper = odeint::make_controlled(opt.abs_tol, opt.rel_tol, odeint::runge_kutta_dopri5<State>());
    odeint::integrate_times(stepper, system, x, s_values.begin(), s_values.end(), ds, observer);
  } else {
    auto stepper = odeint::make_controlled(opt.abs_tol, opt.rel_tol, odeint::runge_kutta_fehlberg78<State>());
    odeint::integrate_times(stepper, system, x, s_values.begin(), s_values.end(), ds, observer);
  }
  return out;
}

}  // namespace kirchhoff::detail

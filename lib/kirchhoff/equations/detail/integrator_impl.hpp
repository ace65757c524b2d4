// Internal: the odeint plumbing shared by the spatial and planar equations. A right-hand side
// is any object with `template <class T> void operator()(const T* y, T* dyds, double s) const`,
// evaluated on double for the state and on Dual<N> for the variational equations.
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "kirchhoff/equations/detail/dual.hpp"
#include "kirchhoff/equations/integrator.hpp"

namespace kirchhoff::detail {

namespace odeint = boost::numeric::odeint;

// Arclength marching with an odeint controlled stepper. We drive try_step ourselves (rather
// than integrate_adaptive) to cap the number of steps and to land exactly on s1. The first trial
// step is *ds (when it is finite and points from s0 to s1, else opt.initial_step of the span); on
// return *ds is the step the controller proposes next, a step cut short to land on s1 not
// shrinking it: handed to the next adjacent interval, it continues the same integration.
template <class State, class System>
long march_stretch(State& x, double s0, double s1, const System& system, const IntegratorOptions& opt, double* ds_io) {
  const double span = s1 - s0;
  if (span == 0.0) return 0;
  double s = s0;
  double ds = std::isfinite(*ds_io) && *ds_io * span > 0 ? *ds_io : opt.initial_step * span;
  const double max_step = opt.max_step;  // 0: none
  long steps = 0;
  auto advance = [&](auto stepper) {
    while ((span > 0) ? (s < s1) : (s > s1)) {
      // (The longest step is held here, not by odeint's max_dt: its controller replaces a step
      // longer than max_dt by +max_dt, which on a march towards smaller s steps away from s1.)
      if (max_step > 0 && std::abs(ds) > max_step) ds = std::copysign(max_step, span);
      const double planned = ds;
      const bool cut = (span > 0) ? (s + ds > s1) : (s + ds < s1);
      if (cut) ds = s1 - s;
      const bool accepted = stepper.try_step(system, x, s, ds) == odeint::success;
      if (accepted) ++steps;
      *ds_io = accepted && cut && std::abs(planned) > std::abs(ds) ? planned : ds;
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

// The caller's options with a rod's jumps (IntegratorOptions::jumps), which the equations hold.
inline IntegratorOptions with_jumps(const IntegratorOptions& given,
                                    const std::shared_ptr<const std::vector<ProfileJump>>& jumps) {
  IntegratorOptions options = given;
  if (!jumps->empty()) options.jumps = jumps;
  return options;
}

// march_stretch over [s0, s1] (either way round), the stretch between two jumps of the right-hand
// side (IntegratorOptions::jumps) at a time: each ends on the side it came from and the next
// starts on the other, so a step's stages never mix the two sides, and a short stretch is
// always stepped into. The state is continuous across a jump.
template <class State, class System>
long march_carrying(State& x, double s0, double s1, const System& system, const IntegratorOptions& opt, double* ds_io) {
  if (!opt.jumps || opt.jumps->empty()) return march_stretch(x, s0, s1, system, opt, ds_io);
  const bool forward = s1 > s0;
  const double lo = std::min(s0, s1), hi = std::max(s0, s1);
  long steps = 0;
  double from = s0;
  const auto cross = [&](double to, double resume) {
    steps += march_stretch(x, from, to, system, opt, ds_io);
    from = resume;
  };
  // A jump counts where both its sides lie in [lo, hi]: an interval that starts on a jump's left
  // side goes on from its right side, and one that ends on its right side ends a stretch on its
  // left one first (profile samples at s = 0.3 on "s > 0.3": the stretch from 0.3 took its first
  // stage's stiffness from the left, which RKF78's error estimate, k1 against k12 at the same s,
  // cannot see: m(L) = 7.7e-4 reported at a moment-free end). One that ends on its left side, or
  // starts on its right, has nothing to cross.
  const auto inside = [&](const ProfileJump& j) { return j.before >= lo && j.after <= hi; };
  if (forward) {
    for (const ProfileJump& j : *opt.jumps)
      if (inside(j)) cross(j.before, j.after);
  } else {
    for (auto j = opt.jumps->rbegin(); j != opt.jumps->rend(); ++j)
      if (inside(*j)) cross(j->after, j->before);
  }
  return steps + march_stretch(x, from, s1, system, opt, ds_io);
}

// One interval on its own: the first trial step is opt.initial_step of it.
template <class State, class System>
long march(State& x, double s0, double s1, const System& system, const IntegratorOptions& opt) {
  double ds = opt.initial_step * (s1 - s0);
  return march_carrying(x, s0, s1, system, opt, &ds);
}

// The right-hand side on the state followed by K directions (an N x K block, row-major): one
// evaluation on Dual<K> seeded with the directions gives their derivatives (df/dy) directions.
template <int N, int K, class Rhs>
struct DualSystem {
  using State = std::array<double, N + N * K>;
  const Rhs& rhs;
  long* evaluations;
  void operator()(const State& y, State& dy, double s) const {
    ++*evaluations;
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
  }
};

// Integrates the state alone from y0 into *y (its storage kept once it has the state's size),
// continuing from the step size *ds and leaving there the one proposed next (march_carrying);
// returns the steps taken and adds the right-hand sides evaluated to *evaluations.
template <int N, class Rhs>
long march_state_into(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1, const IntegratorOptions& opt,
                      double* ds, Eigen::VectorXd* y, long* evaluations) {
  using State = std::array<double, N>;
  State x;
  for (int i = 0; i < N; ++i) x[i] = y0[i];
  auto system = [&](const State& state, State& dy, double s) {
    ++*evaluations;
    rhs(state.data(), dy.data(), s);
  };
  const long steps = march_carrying(x, s0, s1, system, opt, ds);
  *y = Eigen::Map<const Eigen::Matrix<double, N, 1>>(x.data());
  return steps;
}

// The same over one interval on its own: the first trial step is opt.initial_step of it (march).
template <int N, class Rhs>
long march_state_into(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1, const IntegratorOptions& opt,
                      Eigen::VectorXd* y, long* evaluations) {
  double ds = opt.initial_step * (s1 - s0);
  return march_state_into<N>(rhs, y0, s0, s1, opt, &ds, y, evaluations);
}

// Integrates the state alone, into *out (whose y keeps its storage: nothing is allocated once it
// has the state's size; Phi and dy_dunfolding are left empty).
template <int N, class Rhs>
void flow_state_into(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1, const IntegratorOptions& opt,
                     SegmentFlow* out) {
  out->rhs_evaluations = 0;
  out->steps = march_state_into<N>(rhs, y0, s0, s1, opt, &out->y, &out->rhs_evaluations);
  out->Phi.resize(0, 0);
  out->dy_dunfolding.resize(0);  // (no sensitivities: none left from a previous flow into *out)
}

// Phi at opt.sensitivity_tol by phi_pass(the looser options, out), which fills out's Phi (and
// dy_dunfolding), steps and right-hand sides; then the state at the state's own tolerance
// (IntegratorOptions) in a pass of its own into out->y, so F is bit for bit a residual's alone
// (unless opt.sensitivities_only: out->y is then the looser pass's).
template <int N, class Rhs, class PhiPass>
void flow_with_loose_pass_into(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1,
                               const IntegratorOptions& opt, const PhiPass& phi_pass, SegmentFlow* out) {
  IntegratorOptions loose = opt;
  loose.abs_tol = loose.rel_tol = opt.sensitivity_tol;
  loose.sensitivity_tol = 0.0;
  phi_pass(loose, out);
  if (opt.sensitivities_only) return;
  out->steps += march_state_into<N>(rhs, y0, s0, s1, opt, &out->y, &out->rhs_evaluations);
}

// Integrates the state together with the variational equations Phi' = (df/dy) Phi, Phi(s0) = I,
// into *out (its storage reused), by evaluating the right-hand side on Dual<K> seeded with K of
// the N columns of Phi: cheaper by about (N/K)^2 in the derivative arithmetic. The other columns
// are unit vectors (the caller seeds every component the flow depends on at s0), so out->Phi is
// the whole N x N matrix. With opt.sensitivity_tol looser than abs_tol: the seeded columns at
// that tolerance, the state at its own (flow_with_loose_pass_into).
template <int N, int K, class Rhs>
void flow_with_seeded_sensitivities_into(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1,
                                         const IntegratorOptions& opt, const std::array<int, K>& seeds,
                                         SegmentFlow* out) {
  if (opt.sensitivity_tol > opt.abs_tol) {  // (abs_tol > 0, so 0 keeps the one pass)
    flow_with_loose_pass_into<N>(
        rhs, y0, s0, s1, opt,
        [&](const IntegratorOptions& loose, SegmentFlow* o) {
          flow_with_seeded_sensitivities_into<N, K>(rhs, y0, s0, s1, loose, seeds, o);
        },
        out);
    return;
  }
  using State = typename DualSystem<N, K, Rhs>::State;  // y, then the N x K block row-major
  State x{};
  for (int i = 0; i < N; ++i) x[i] = y0[i];
  for (int j = 0; j < K; ++j) x[N + seeds[j] * K + j] = 1.0;
  long evaluations = 0;
  const DualSystem<N, K, Rhs> system{rhs, &evaluations};
  out->steps = march(x, s0, s1, system, opt);
  out->y = Eigen::Map<const Eigen::Matrix<double, N, 1>>(x.data());
  const Eigen::Map<const Eigen::Matrix<double, N, K, Eigen::RowMajor>> seeded(x.data() + N);
  out->Phi.setIdentity(N, N);
  for (int j = 0; j < K; ++j) out->Phi.col(seeds[j]) = seeded.col(j);
  out->dy_dunfolding.resize(0);  // (not carried on dual numbers: the caller differences)
  out->rhs_evaluations = evaluations;
}

// The state alone carried from s0 to s1 at opt's own tolerance, continuing the step sizes in
// carried->state: the directional flows' state where their directions took a looser tolerance
// (IntegratorOptions::sensitivity_tol). Replaces out->y; adds its steps and right-hand sides.
template <int N, class Rhs>
void carry_state_alone(const Rhs& rhs, const Eigen::VectorXd& y0, double s0, double s1, const IntegratorOptions& opt,
                       CarriedSteps* carried, DirectionalFlow* out) {
  out->steps += march_state_into<N>(rhs, y0, s0, s1, opt, &carried->state, &out->y, &out->rhs_evaluations);
}

// The state and the columns of `directions` (at most K; fewer are padded with zero columns, which
// stay zero) carried from s0 to s1, continuing from the step sizes in *carried and leaving there
// those proposed next. With opt.sensitivity_tol looser than abs_tol, as flow_with_loose_pass_into:
// the directions at sensitivity_tol, the state at its own tolerance in a pass of its own.
template <int N, int K, class Rhs>
DirectionalFlow flow_directions(const Rhs& rhs, const Eigen::VectorXd& y0, const Eigen::MatrixXd& directions,
                                double s0, double s1, const IntegratorOptions& opt, CarriedSteps* carried) {
  const bool loose = opt.sensitivity_tol > opt.abs_tol;
  IntegratorOptions dual_opt = opt;
  if (loose) dual_opt.abs_tol = dual_opt.rel_tol = opt.sensitivity_tol;
  using State = typename DualSystem<N, K, Rhs>::State;
  const int k = static_cast<int>(directions.cols());
  State x{};
  for (int i = 0; i < N; ++i) {
    x[i] = y0[i];
    for (int j = 0; j < k; ++j) x[N + i * K + j] = directions(i, j);
  }
  DirectionalFlow out;
  const DualSystem<N, K, Rhs> system{rhs, &out.rhs_evaluations};
  out.steps = march_carrying(x, s0, s1, system, dual_opt, &carried->directions);
  out.y = Eigen::Map<const Eigen::Matrix<double, N, 1>>(x.data());
  // (A single column is stored alike either way; Eigen refuses a row-major column vector.)
  constexpr int kLayout = K == 1 ? Eigen::ColMajor : Eigen::RowMajor;
  out.directions = Eigen::Map<const Eigen::Matrix<double, N, K, kLayout>>(x.data() + N).leftCols(k);
  if (loose) carry_state_alone<N>(rhs, y0, s0, s1, opt, carried, &out);
  return out;
}

// flow_directions with K the first of Ks (ascending) that holds `count` columns; false when none does.
template <int N, int K, int... More, class Rhs>
bool flow_directions_fitting(const Rhs& rhs, const Eigen::VectorXd& y0, const Eigen::MatrixXd& directions,
                             double s0, double s1, const IntegratorOptions& opt, CarriedSteps* carried,
                             DirectionalFlow* out) {
  if (directions.cols() <= K) {
    *out = flow_directions<N, K>(rhs, y0, directions, s0, s1, opt, carried);
    return true;
  }
  if constexpr (sizeof...(More) > 0)
    return flow_directions_fitting<N, More...>(rhs, y0, directions, s0, s1, opt, carried, out);
  else
    return false;
}

// The directions' flow for RodEquations::flow_directions. The state-transition matrix has unit
// columns off `seeds` (the state entries nothing depends on), so fewer directions than seeds are
// carried themselves, and more through Phi's seeded columns: Phi directions. Ks (ascending, the
// last at least seeds.size()) are the numbers of dual directions compiled.
template <int N, int... Ks, class Rhs>
DirectionalFlow flow_directions_through_seeds(const Rhs& rhs, const Eigen::VectorXd& y0,
                                              const Eigen::MatrixXd& directions, const std::vector<int>& seeds,
                                              double s0, double s1, const IntegratorOptions& opt,
                                              CarriedSteps* carried) {
  DirectionalFlow out;
  if (directions.cols() < static_cast<Eigen::Index>(seeds.size()) &&
      flow_directions_fitting<N, Ks...>(rhs, y0, directions, s0, s1, opt, carried, &out))
    return out;
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(N, static_cast<Eigen::Index>(seeds.size()));
  for (size_t j = 0; j < seeds.size(); ++j) unit(seeds[j], static_cast<Eigen::Index>(j)) = 1.0;
  if (!flow_directions_fitting<N, Ks...>(rhs, y0, unit, s0, s1, opt, carried, &out))
    throw std::logic_error("flow_directions_through_seeds: no dual size holds the seeds");
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(N, N);
  for (size_t j = 0; j < seeds.size(); ++j) Phi.col(seeds[j]) = out.directions.col(static_cast<Eigen::Index>(j));
  out.directions = Phi * directions;
  return out;
}

// States at the requested arclengths (sorted; repeated values allowed). The integration lands on
// each sample point, so profiles keep its accuracy. (Dopri5's dense output is not used: odeint's
// integrate_times interpolated a sample equal to the start before the first step, from the
// stepper's uninitialised previous state, and gave NaN there.)
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
  // One integration observed at each s (march_carrying continues the step sizes from one to the
  // next, and lands on the right-hand side's jumps between them).
  const double span = s_values.back() - s_values.front();
  double ds = opt.initial_step * (span > 0 ? span : 1.0);
  out.reserve(s_values.size());
  out.push_back(Eigen::Map<const Eigen::Matrix<double, N, 1>>(x.data()));
  for (size_t i = 1; i < s_values.size(); ++i) {
    march_carrying(x, s_values[i - 1], s_values[i], system, opt, &ds);
    out.push_back(Eigen::Map<const Eigen::Matrix<double, N, 1>>(x.data()));
  }
  return out;
}

}  // namespace kirchhoff::detail

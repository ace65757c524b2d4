#include "kirchhoff/analysis/discrete_elastica.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "kirchhoff/contact/detail/ipopt_application.hpp"

namespace kirchhoff {
namespace {

// The half cell at an end: a clamp at the angle `clamp` holds its end segment's angle through half
// a cell (stiffness 2 EI / h); a pinned end (`clamp` NaN: free to turn, no moment) has none.
double clamp_energy(double EI, double h, double theta, double clamp) {
  return std::isfinite(clamp) ? EI / h * (theta - clamp) * (theta - clamp) : 0.0;
}
double clamp_moment(double EI, double h, double theta, double clamp) {  // d clamp_energy / d theta
  return std::isfinite(clamp) ? 2.0 * EI / h * (theta - clamp) : 0.0;
}
double clamp_stiffness(double EI, double clamp) { return std::isfinite(clamp) ? 2.0 * EI : 0.0; }  // times 1 / h

using Ipopt::Index;
using Ipopt::Number;

// The same minimisation with the nodes as unknowns beside the angles: variables theta_0..N-1,
// then (x_k, y_k) of the interior nodes k = 1..N-1; equality constraints per segment i,
// r_i+1 - r_i - h (cos, sin) theta_i = 0 (r_0 and r_N the clamps); a gap row per interior node and
// obstacle, g(x_k, y_k) >= 0. Every row involves at most one angle and two nodes, so the KKT
// matrix is banded and a solve costs O(N) per iteration (with the angles alone every gap row
// depends on all the angles before its node: a dense Jacobian, O(N^3) per factorisation, 5.6 s
// at N = 1000). The multipliers are translated back to the angle formulation's (the end
// reaction, the gap multipliers), which the KKT check verifies in that formulation: the check is
// not made in the solver's own variables.
class ClampedElasticaNLP : public Ipopt::TNLP {
 public:
  ClampedElasticaNLP(DiscreteClampedElastica rod, int N, const DiscreteSolveOptions& options, DiscreteElasticaResult* out)
      : rod_(std::move(rod)), N_(N), h_(rod_.L / N), amplitude_(options.amplitude), lobes_(options.lobes),
        initial_theta_(options.initial_theta), symmetric_pairs_(options.mirror_symmetric ? N / 2 : 0), out_(out) {
    for (const auto& o : rod_.obstacles) curved_ = curved_ || !o.is_flat();
    for (int k = 0; k <= N_; ++k) EI_.push_back(rod_.EI(k * h_));
  }

  int obstacles() const { return static_cast<int>(rod_.obstacles.size()); }

  // With the mirror symmetry held, the segments' vertical rows are implied by it and the symmetry
  // rows (the heights of the two halves cancel): a uniform vertical force delta added to every
  // segment's multiplier, with mu_i + delta h cos theta_i on the symmetry rows, satisfies the
  // same stationarity, so Ipopt's split between them is arbitrary. The whole problem's is the one
  // with mu = 0: delta = -mu_i / (h cos theta_i), by least squares over the pairs (exact at a
  // symmetric equilibrium of a symmetric problem; elsewhere the KKT check, made without the
  // symmetry, fails).
  double vertical_force_from_symmetry(const Number* v, const Number* lambda) const {
    double num = 0.0, den = 0.0;
    for (int i = 0; i < symmetric_pairs_; ++i) {
      const double a = h_ * std::cos(v[i]);
      num += lambda[symmetry_row(i)] * a;
      den += a * a;
    }
    return den > 0.0 ? -num / den : 0.0;
  }
  // Variable indices: angle i, node k's x and y (k = 1..N-1).
  Index X(int k) const { return N_ + 2 * (k - 1); }
  Index Y(int k) const { return N_ + 2 * (k - 1) + 1; }
  Index gap_row(int o, int k) const { return 2 * N_ + o * (N_ - 1) + (k - 1); }
  // With mirror_symmetric: theta_i + theta_N-1-i = 2 alpha, i < N / 2, after the gap rows.
  Index symmetry_row(int i) const { return 2 * N_ + obstacles() * (N_ - 1) + i; }
  double chord_angle() const {
    const Vec3 chord = rod_.end - rod_.start;
    return std::atan2(chord.y(), chord.x());
  }
  Vec3 node(const Number* v, int k) const {
    if (k == 0) return rod_.start;
    if (k == N_) return rod_.end;
    return Vec3(v[X(k)], v[Y(k)], 0.0);
  }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_hess, IndexStyleEnum& style) override {
    n = N_ + 2 * (N_ - 1);
    m = 2 * N_ + obstacles() * (N_ - 1) + symmetric_pairs_;
    // Segment rows: the angle and the interior nodes among its two ends (N - 2 segments have
    // two, the first and last one), per coordinate.
    nnz_jac = 2 * (N_ + 2 * (N_ - 1)) + 2 * obstacles() * (N_ - 1) + 2 * symmetric_pairs_;
    // Lower triangle: the angles' tridiagonal; with curved obstacles each node's 2 x 2 block.
    nnz_hess = 2 * N_ - 1 + (curved_ ? 3 * (N_ - 1) : 0);
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l, Number* g_u) override {
    for (Index i = 0; i < n; ++i) {
      x_l[i] = -2e19;  // Ipopt's infinity: free
      x_u[i] = 2e19;
    }
    for (Index r = 0; r < 2 * N_; ++r) g_l[r] = g_u[r] = 0.0;
    for (Index r = 2 * N_; r < symmetry_row(0); ++r) {
      g_l[r] = 0.0;
      g_u[r] = 2e19;
    }
    for (Index r = symmetry_row(0); r < m; ++r) g_l[r] = g_u[r] = 0.0;
    return true;
  }

  bool get_starting_point(Index, bool, Number* v, bool, Number*, Number*, Index, bool, Number*) override {
    if (!initial_theta_.empty()) {
      std::copy(initial_theta_.begin(), initial_theta_.end(), v);
    } else {
      // The chord's angle, the clamps' angles blended in linearly, and the slope of
      // y = (A/2)(1 - cos 2 pi n s / L) across the chord (n = 1: the first clamped-clamped mode).
      const Vec3 chord = rod_.end - rod_.start;
      const double along = std::atan2(chord.y(), chord.x());
      for (int i = 0; i < N_; ++i) {
        const double s = (i + 0.5) * h_, t = s / rod_.L;
        const double start_turn = std::isfinite(rod_.start_angle) ? rod_.start_angle - along : 0.0;
        const double end_turn = std::isfinite(rod_.end_angle) ? rod_.end_angle - along : 0.0;
        v[i] = along + (1 - t) * start_turn + t * end_turn +
               amplitude_ * M_PI * lobes_ / rod_.L * std::sin(2 * M_PI * lobes_ * t);
      }
    }
    // The nodes from the angles (the segment rows hold but for the last one's, the end).
    Vec3 r = rod_.start;
    for (int k = 1; k < N_; ++k) {
      r += h_ * Vec3(std::cos(v[k - 1]), std::sin(v[k - 1]), 0.0);
      v[X(k)] = r.x();
      v[Y(k)] = r.y();
    }
    return true;
  }

  bool eval_f(Index, const Number* t, bool, Number& f) override {
    f = clamp_energy(EI_[0], h_, t[0], rod_.start_angle) + clamp_energy(EI_[N_], h_, t[N_ - 1], rod_.end_angle);
    for (int k = 1; k < N_; ++k) f += 0.5 * EI_[k] / h_ * (t[k] - t[k - 1]) * (t[k] - t[k - 1]);
    return true;
  }

  bool eval_grad_f(Index n, const Number* t, bool, Number* g) override {
    for (Index i = 0; i < n; ++i) g[i] = 0.0;
    g[0] += clamp_moment(EI_[0], h_, t[0], rod_.start_angle);
    g[N_ - 1] += clamp_moment(EI_[N_], h_, t[N_ - 1], rod_.end_angle);
    for (int k = 1; k < N_; ++k) {
      const double d = EI_[k] / h_ * (t[k] - t[k - 1]);
      g[k] += d;
      g[k - 1] -= d;
    }
    return true;
  }

  bool eval_g(Index, const Number* v, bool, Index, Number* g) override {
    for (int i = 0; i < N_; ++i) {
      const Vec3 d = node(v, i + 1) - node(v, i);
      g[2 * i] = d.x() - h_ * std::cos(v[i]);
      g[2 * i + 1] = d.y() - h_ * std::sin(v[i]);
    }
    for (int o = 0; o < obstacles(); ++o)
      for (int k = 1; k < N_; ++k) g[gap_row(o, k)] = rod_.obstacles[o].gap(node(v, k));
    for (int i = 0; i < symmetric_pairs_; ++i) g[symmetry_row(i)] = v[i] + v[N_ - 1 - i] - 2.0 * chord_angle();
    return true;
  }

  bool eval_jac_g(Index, const Number* v, bool, Index, Index, Index* rows, Index* cols, Number* values) override {
    Index e = 0;
    auto entry = [&](Index row, Index col, double value) {
      if (values)
        values[e] = value;
      else {
        rows[e] = row;
        cols[e] = col;
      }
      ++e;
    };
    for (int i = 0; i < N_; ++i) {
      const double c = values ? std::cos(v[i]) : 0.0, s = values ? std::sin(v[i]) : 0.0;
      entry(2 * i, i, h_ * s);
      entry(2 * i + 1, i, -h_ * c);
      if (i + 1 < N_) {
        entry(2 * i, X(i + 1), 1.0);
        entry(2 * i + 1, Y(i + 1), 1.0);
      }
      if (i > 0) {
        entry(2 * i, X(i), -1.0);
        entry(2 * i + 1, Y(i), -1.0);
      }
    }
    for (int o = 0; o < obstacles(); ++o)
      for (int k = 1; k < N_; ++k) {
        const Vec3 grad = values ? rod_.obstacles[o].gradient(node(v, k)) : Vec3::Zero();
        entry(gap_row(o, k), X(k), grad.x());
        entry(gap_row(o, k), Y(k), grad.y());
      }
    for (int i = 0; i < symmetric_pairs_; ++i) {
      entry(symmetry_row(i), i, 1.0);
      entry(symmetry_row(i), N_ - 1 - i, 1.0);
    }
    return true;
  }

  bool eval_h(Index, const Number* v, bool, Number obj_factor, Index, const Number* lambda, bool, Index,
              Index* rows, Index* cols, Number* values) override {
    Index e = 0;
    auto entry = [&](Index row, Index col, double value) {
      if (values)
        values[e] = value;
      else {
        rows[e] = row;
        cols[e] = col;
      }
      ++e;
    };
    for (int i = 0; i < N_; ++i) {
      if (i > 0) entry(i, i - 1, values ? -obj_factor * EI_[i] / h_ : 0.0);
      double diagonal = 0.0;
      if (values) {
        diagonal = obj_factor / h_ * (i > 0 ? EI_[i] : clamp_stiffness(EI_[0], rod_.start_angle)) +
                   obj_factor / h_ * (i + 1 < N_ ? EI_[i + 1] : clamp_stiffness(EI_[N_], rod_.end_angle));
        // d2/dtheta2 of -h cos theta and -h sin theta.
        diagonal += lambda[2 * i] * h_ * std::cos(v[i]) + lambda[2 * i + 1] * h_ * std::sin(v[i]);
      }
      entry(i, i, diagonal);
    }
    if (curved_)
      for (int k = 1; k < N_; ++k) {
        Mat3 H = Mat3::Zero();
        if (values)
          for (int o = 0; o < obstacles(); ++o)
            if (!rod_.obstacles[o].is_flat()) H += lambda[gap_row(o, k)] * rod_.obstacles[o].hessian(node(v, k));
        entry(X(k), X(k), H(0, 0));
        entry(Y(k), X(k), H(1, 0));
        entry(Y(k), Y(k), H(1, 1));
      }
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn status, Index, const Number* v, const Number*, const Number*,
                         Index m, const Number* g, const Number* lambda, Number f, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    // Provisional: solve_discrete_elastica adds the KKT check's verdict.
    out_->converged = status == Ipopt::SUCCESS;
    out_->ipopt_status = status == Ipopt::SUCCESS ? "success" : "ipopt status " + std::to_string(static_cast<int>(status));
    out_->status = out_->ipopt_status;
    out_->energy = f;
    const int n = N_;
    out_->theta.assign(v, v + n);
    // The nodes from the angles, as the angle formulation has them (the solver's own nodes agree
    // to its constraint tolerance).
    out_->x.assign(1, rod_.start.x());
    out_->y.assign(1, rod_.start.y());
    for (int i = 0; i < n; ++i) {
      out_->x.push_back(out_->x.back() + h_ * std::cos(v[i]));
      out_->y.push_back(out_->y.back() + h_ * std::sin(v[i]));
    }
    // The multipliers in the angle formulation (Lagrangian f + lambda^T g there, with the end
    // position's two rows first): the last segment's row pair carries n(L) = mu_N-1, and the end
    // rows' multipliers there are -mu_N-1; the gap rows' multipliers are the same.
    out_->multipliers.assign(2 + obstacles() * (n - 1), 0.0);
    out_->multipliers[0] = -lambda[2 * (n - 1)];
    out_->multipliers[1] = -(lambda[2 * (n - 1) + 1] + vertical_force_from_symmetry(v, lambda));
    // (The symmetry rows' multipliers are left out, moved into the vertical force above: the check
    // is made without the symmetry.)
    for (Index r = 2 * n; r < m - symmetric_pairs_; ++r) out_->multipliers[2 + (r - 2 * n)] = lambda[r];
    // Ipopt's Lagrangian is f + lambda^T g: n(L) = -lambda_end (the force the end constraint
    // applies to the rod). The gap multipliers give the contact forces -lambda grad g, so that
    // across the contacts n(0) = n(L) + sum (-lambda_k) grad g_k (n' = -f; eq. 63 for a wall).
    const std::vector<double>& lam = out_->multipliers;
    out_->P = lam[0];
    out_->contact_force = 0.0;
    out_->node_forces.assign(rod_.obstacles.size(), std::vector<double>(n - 1, 0.0));
    out_->node_gaps = out_->node_forces;
    out_->min_gap = INFINITY;
    Vec3 n_start(-lam[0], -lam[1], 0.0);
    for (int o = 0; o < obstacles(); ++o)
      for (int k = 1; k < n; ++k) {
        const Index r = 2 + o * (n - 1) + (k - 1);
        const Vec3 at(out_->x[k], out_->y[k], 0.0);
        const Vec3 grad = rod_.obstacles[o].gradient(at);
        const double gap = g[gap_row(o, k)];
        out_->contact_force += -lam[r] * grad.norm();
        n_start += -lam[r] * grad;
        out_->min_gap = std::min(out_->min_gap, gap);
        out_->node_forces[o][k - 1] = -lam[r] * grad.norm();
        out_->node_gaps[o][k - 1] = gap;
      }
    out_->n_y = n_start.y();
    out_->n_start = n_start;
    out_->m_start = clamp_moment(EI_[0], h_, v[0], rod_.start_angle);  // 0 at a pinned start
  }

 private:
  DiscreteClampedElastica rod_;
  std::vector<double> EI_;
  int N_;
  double h_, amplitude_;
  int lobes_;
  std::vector<double> initial_theta_;
  int symmetric_pairs_;  // rows holding the mirror symmetry (0: none)
  bool curved_ = false;
  DiscreteElasticaResult* out_;
};

}  // namespace

DiscreteElasticaResult solve_discrete_clamped_elastica(double L, double EI, double Delta,
                                                       const std::vector<Obstacle>& obstacles, int segments,
                                                       double amplitude) {
  if (!(EI > 0)) throw std::invalid_argument("discrete Elastica: EI must be > 0");
  if (!(Delta > 0 && Delta < L)) throw std::invalid_argument("discrete Elastica: Delta must lie in (0, L)");
  DiscreteClampedElastica rod;
  rod.L = L;
  rod.EI = [EI](double) { return EI; };
  rod.end = Vec3(L - Delta, 0.0, 0.0);
  rod.obstacles = obstacles;
  return solve_discrete_elastica(rod, segments, amplitude);
}

DiscreteElasticaResult solve_discrete_elastica(const DiscreteClampedElastica& rod, int segments, double amplitude) {
  DiscreteSolveOptions options;
  options.amplitude = amplitude;
  return solve_discrete_elastica(rod, segments, options);
}

DiscreteElasticaResult solve_discrete_elastica(const DiscreteClampedElastica& rod, int segments,
                                               const DiscreteSolveOptions& options) {
  if (!(rod.L > 0)) throw std::invalid_argument("discrete Elastica: L must be > 0");
  if (options.mirror_symmetric && segments % 2 != 0)
    throw std::invalid_argument("discrete Elastica: a mirror-symmetric rod needs an even number of segments");
  if (options.lobes < 1) throw std::invalid_argument("discrete Elastica: lobes must be >= 1");
  double EI_max = 0.0;
  for (int k = 0; k <= 20; ++k) {
    const double EI = rod.EI(rod.L * k / 20);
    if (!(EI > 0)) throw std::invalid_argument("discrete Elastica: EI must be > 0 along the rod");
    EI_max = std::max(EI_max, EI);
  }
  if (!((rod.end - rod.start).norm() < rod.L))
    throw std::invalid_argument("discrete Elastica: the clamps are further apart than the rod is long");
  if (segments < 4) throw std::invalid_argument("discrete Elastica: at least 4 segments");
  if (!options.initial_theta.empty() && static_cast<int>(options.initial_theta.size()) != segments)
    throw std::invalid_argument("discrete Elastica: initial_theta must hold one angle per segment");
  if (!(options.initial_multiplier >= 0))
    throw std::invalid_argument("discrete Elastica: initial_multiplier must be >= 0");
  DiscreteElasticaResult out;
  Ipopt::SmartPtr<Ipopt::TNLP> nlp = new ClampedElasticaNLP(rod, segments, options, &out);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = detail::make_ipopt_application();
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", 1e-12);
  app->Options()->SetIntegerValue("max_iter", 3000);
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  // Exact complementarity: by default Ipopt relaxes bounds by 1e-8, which would let the rod sit
  // 1e-8 inside the wall.
  app->Options()->SetNumericValue("bound_relax_factor", 0.0);
  // The gap multipliers start as a total force EI / L^2 spread over the nodes, not Ipopt's 1 per
  // node (N EI / L^2 in all, which pushed the rod off the wall at large N; see the header).
  const double initial_multiplier =
      options.initial_multiplier > 0 ? options.initial_multiplier : EI_max / (rod.L * rod.L * segments);
  app->Options()->SetNumericValue("bound_mult_init_val", initial_multiplier);
  if (app->Initialize() != Ipopt::Solve_Succeeded) throw std::runtime_error("Ipopt failed to initialise");
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(nlp);
  if (Ipopt::IsValid(app->Statistics())) out.iterations = app->Statistics()->IterationCount();
  if (out.theta.size() != static_cast<size_t>(segments)) {  // finalize_solution was not called
    out.converged = false;
    out.ipopt_status = out.status = "ipopt status " + std::to_string(static_cast<int>(status)) + " (no solution)";
    return out;
  }
  // Ipopt's word is not taken: the KKT conditions are recomputed from its angles and multipliers.
  out.kkt = check_discrete_elastica(rod, out);
  if (status != Ipopt::Solve_Succeeded) {
    out.converged = false;
  } else if (!out.kkt.passed) {
    out.converged = false;
    out.status = "KKT check failed: " + out.kkt.failure;
  } else {
    out.converged = true;
    out.status = "converged";
  }
  return out;
}

DiscreteKktCheck check_discrete_elastica(const DiscreteClampedElastica& rod, const DiscreteElasticaResult& r) {
  const int N = static_cast<int>(r.theta.size());
  const size_t obstacles = rod.obstacles.size();
  if (N < 4 || r.multipliers.size() != 2 + obstacles * (N - 1))
    throw std::invalid_argument("discrete Elastica check: " + std::to_string(N) + " angles and " +
                                std::to_string(r.multipliers.size()) + " multipliers do not match the rod");
  const double h = rod.L / N;
  const std::vector<double>& t = r.theta;
  const std::vector<double>& lambda = r.multipliers;
  std::vector<double> EI(N + 1);
  double EI_max = 0.0;
  for (int k = 0; k <= N; ++k) EI_max = std::max(EI_max, EI[k] = rod.EI(k * h));
  std::vector<Vec3> nodes(N + 1, rod.start);
  for (int k = 1; k <= N; ++k) nodes[k] = nodes[k - 1] + h * Vec3(std::cos(t[k - 1]), std::sin(t[k - 1]), 0.0);

  DiscreteKktCheck c;
  // Forces: the end reaction and each node's contact force -lambda |grad g| (Ipopt's multiplier
  // of an active lower bound is <= 0).
  Vec3 n_start(-lambda[0], -lambda[1], 0.0);
  double total_force = 0.0, most_negative = 0.0, worst_product = 0.0, min_gap = INFINITY;
  // dL/dtheta_i: the energy's gradient, plus the multipliers times the constraints' gradients
  // (every constraint of node k >= i + 1 depends on theta_i through r_k, d r_k / d theta_i = a_i).
  std::vector<double> dL(N, 0.0);
  dL[0] += clamp_moment(EI[0], h, t[0], rod.start_angle);
  dL[N - 1] += clamp_moment(EI[N], h, t[N - 1], rod.end_angle);
  for (int k = 1; k < N; ++k) {
    const double d = EI[k] / h * (t[k] - t[k - 1]);
    dL[k] += d;
    dL[k - 1] -= d;
  }
  Vec3 pull = Vec3(lambda[0], lambda[1], 0.0);  // sum over the constraints of nodes > i of lambda grad
  std::vector<Vec3> gradient_tail(N);
  std::vector<std::vector<Vec3>> gradients(obstacles, std::vector<Vec3>(N + 1, Vec3::Zero()));
  for (size_t o = 0; o < obstacles; ++o)
    for (int k = 1; k < N; ++k) gradients[o][k] = rod.obstacles[o].gradient(nodes[k]);
  for (int i = N - 1; i >= 0; --i) {
    if (i + 1 <= N - 1)
      for (size_t o = 0; o < obstacles; ++o) pull += lambda[2 + o * (N - 1) + i] * gradients[o][i + 1];
    gradient_tail[i] = pull;
  }
  for (int i = 0; i < N; ++i) dL[i] += gradient_tail[i].dot(Vec3(-h * std::sin(t[i]), h * std::cos(t[i]), 0.0));
  std::vector<double> force(obstacles * (N - 1)), gap(obstacles * (N - 1));
  for (size_t o = 0; o < obstacles; ++o)
    for (int k = 1; k < N; ++k) {
      const size_t row = o * (N - 1) + (k - 1);
      force[row] = -lambda[2 + row] * gradients[o][k].norm();
      gap[row] = rod.obstacles[o].gap(nodes[k]);
      n_start += -lambda[2 + row] * gradients[o][k];
      total_force += std::abs(force[row]);
      min_gap = std::min(min_gap, gap[row]);
    }
  c.force_scale = n_start.norm() + total_force + EI_max / (rod.L * rod.L);
  const double F = c.force_scale;
  double stationarity = 0.0;
  for (int i = 0; i < N; ++i) stationarity = std::max(stationarity, std::abs(dL[i]));
  c.stationarity = stationarity / (h * F);
  c.end_error = (nodes[N] - rod.end).norm() / rod.L;
  c.penetration = obstacles ? std::max(0.0, -min_gap) / rod.L : 0.0;
  for (size_t row = 0; row < force.size(); ++row) {
    most_negative = std::min(most_negative, force[row]);
    worst_product = std::max(worst_product, std::abs(force[row] * gap[row]));
  }
  c.negative_force = -most_negative / F;
  c.complementarity = worst_product / (F * rod.L);
  auto fail = [&](const char* what, double value) {
    if (c.failure.empty() && !(value <= kDiscreteKktTolerance)) {
      char text[160];
      std::snprintf(text, sizeof text, "%s %.2e > %.0e", what, value, kDiscreteKktTolerance);
      c.failure = text;
    }
  };
  fail("stationarity (moment balance, relative)", c.stationarity);
  fail("end position error (relative)", c.end_error);
  fail("penetration (relative)", c.penetration);
  fail("pulling contact force (relative)", c.negative_force);
  fail("complementarity force x gap (relative)", c.complementarity);
  c.passed = c.failure.empty();
  return c;
}

DiscreteRefinementCheck check_refinement(int segments, double P, double P_half, double P_quarter) {
  DiscreteRefinementCheck c;
  c.segments = segments;
  c.P = P;
  c.P_half = P_half;
  c.P_quarter = P_quarter;
  const double fine = P_half - P, coarse = P_quarter - P_half;
  c.error_estimate = std::abs(fine) / 3.0;
  c.P_extrapolated = (4.0 * P - P_half) / 3.0;
  c.ratio = coarse / fine;
  // Differences at round-off: P is converged in N to the digits Ipopt gives (the Lagrangian's
  // stationarity to 1e-12 moves P by ~1e-12 of itself; 1e-10 leaves a factor 100).
  const double roundoff = 1e-10 * std::max({std::abs(P), std::abs(P_half), std::abs(P_quarter)});
  if (!std::isfinite(P) || !std::isfinite(P_half) || !std::isfinite(P_quarter)) {
    c.failure = "P is not finite";
  } else if (std::abs(fine) <= roundoff && std::abs(coarse) <= roundoff) {
    c.error_estimate = std::max(c.error_estimate, roundoff);
  } else if (!(c.ratio >= kRefinementRatioMin && c.ratio <= kRefinementRatioMax)) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "P at N/4, N/2, N = %.10g, %.10g, %.10g: the differences' ratio %.3g is outside [%g, %g] "
                  "(4 at second order): not one equilibrium refined, or not yet asymptotic",
                  P_quarter, P_half, P, c.ratio, kRefinementRatioMin, kRefinementRatioMax);
    c.failure = text;
  }
  c.passed = c.failure.empty();
  return c;
}

DiscreteElasticaResult solve_discrete_elastica_refined(const DiscreteClampedElastica& rod, int segments,
                                                       const DiscreteSolveOptions& options) {
  if (segments % 4 != 0 || segments / 4 < 4)
    throw std::invalid_argument("discrete Elastica, refined: N must be a multiple of 4 and N/4 >= 4");
  DiscreteSolveOptions level = options;
  if (!level.initial_theta.empty() && static_cast<int>(level.initial_theta.size()) != segments / 4)
    throw std::invalid_argument("discrete Elastica, refined: initial_theta must hold N/4 angles");
  std::vector<DiscreteElasticaResult> solved;
  for (int n : {segments / 4, segments / 2, segments}) {
    if (!solved.empty()) {
      // Each coarse segment split in two at the same angle: the same nodes (the end constraints
      // hold exactly), on the branch the coarse solve found.
      level.initial_theta.clear();
      for (double angle : solved.back().theta) level.initial_theta.insert(level.initial_theta.end(), 2, angle);
    }
    solved.push_back(solve_discrete_elastica(rod, n, level));
    if (!solved.back().converged) {
      DiscreteElasticaResult out = std::move(solved.back());
      if (n != segments) {
        out.converged = false;
        out.status = "the solve at N = " + std::to_string(n) + " for the refinement check failed: " + out.status;
      }
      return out;
    }
  }
  DiscreteElasticaResult out = std::move(solved[2]);
  out.refinement = check_refinement(segments, out.P, solved[1].P, solved[0].P);
  if (!out.refinement.passed) {
    out.converged = false;
    out.status = "refinement check failed: " + out.refinement.failure;
  }
  return out;
}

}  // namespace kirchhoff

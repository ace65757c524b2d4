#include "kirchhoff/discrete_elastica.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <cmath>
#include <stdexcept>

namespace kirchhoff {
namespace {

using Ipopt::Index;
using Ipopt::Number;

class ClampedElasticaNLP : public Ipopt::TNLP {
 public:
  ClampedElasticaNLP(DiscreteClampedElastica rod, int N, double amplitude, DiscreteElasticaResult* out)
      : rod_(std::move(rod)), N_(N), h_(rod_.L / N), amplitude_(amplitude), out_(out) {
    for (const auto& o : rod_.obstacles) curved_ = curved_ || !o.is_flat();
    // EI at the nodes 0..N: the interior nodes weight the angle differences, the ends the clamps.
    for (int k = 0; k <= N_; ++k) EI_.push_back(rod_.EI(k * h_));
  }

  // Constraints: 0, 1: the end's x and y, then for each obstacle o and interior node
  // k = 1..N-1: gap_o(x_k, y_k) >= 0.
  int gap_rows() const { return static_cast<int>(rod_.obstacles.size()) * (N_ - 1); }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_hess, IndexStyleEnum& style) override {
    n = N_;
    m = 2 + gap_rows();
    // Node k depends on the angles of segments 0..k-1.
    nnz_jac = 2 * N_ + static_cast<int>(rod_.obstacles.size()) * (N_ - 1) * N_ / 2;
    // Lower triangle: tridiagonal with planes; curved obstacles couple every pair of angles.
    nnz_hess = curved_ ? N_ * (N_ + 1) / 2 : 2 * N_ - 1;
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l, Number* g_u) override {
    for (Index i = 0; i < n; ++i) {
      x_l[i] = -2e19;  // Ipopt's infinity: the angles are free
      x_u[i] = 2e19;
    }
    g_l[0] = g_u[0] = rod_.end.x();
    g_l[1] = g_u[1] = rod_.end.y();
    for (Index r = 2; r < m; ++r) {
      g_l[r] = 0.0;
      g_u[r] = 2e19;  // Ipopt's +infinity
    }
    return true;
  }

  bool get_starting_point(Index n, bool, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    // The chord's angle, the clamps' angles blended in linearly, and the slope of the first
    // clamped-clamped mode y = (A/2)(1 - cos 2 pi s / L) across the chord.
    const Vec3 chord = rod_.end - rod_.start;
    const double along = std::atan2(chord.y(), chord.x());
    for (Index i = 0; i < n; ++i) {
      const double s = (i + 0.5) * h_, t = s / rod_.L;
      x[i] = along + (1 - t) * (rod_.start_angle - along) + t * (rod_.end_angle - along) +
             amplitude_ * M_PI / rod_.L * std::sin(2 * M_PI * t);
    }
    return true;
  }

  bool eval_f(Index n, const Number* t, bool, Number& f) override {
    f = EI_[0] / h_ * std::pow(t[0] - rod_.start_angle, 2) + EI_[N_] / h_ * std::pow(t[n - 1] - rod_.end_angle, 2);
    for (Index k = 1; k < n; ++k) f += 0.5 * EI_[k] / h_ * (t[k] - t[k - 1]) * (t[k] - t[k - 1]);
    return true;
  }

  bool eval_grad_f(Index n, const Number* t, bool, Number* g) override {
    for (Index i = 0; i < n; ++i) g[i] = 0.0;
    g[0] += 2 * EI_[0] / h_ * (t[0] - rod_.start_angle);
    g[n - 1] += 2 * EI_[N_] / h_ * (t[n - 1] - rod_.end_angle);
    for (Index k = 1; k < n; ++k) {
      const double d = EI_[k] / h_ * (t[k] - t[k - 1]);
      g[k] += d;
      g[k - 1] -= d;
    }
    return true;
  }

  bool eval_g(Index n, const Number* t, bool, Index, Number* g) override {
    double x = rod_.start.x(), y = rod_.start.y();
    Index row = 2;
    for (Index k = 1; k <= n; ++k) {
      x += h_ * std::cos(t[k - 1]);
      y += h_ * std::sin(t[k - 1]);
      if (k < n)
        for (size_t o = 0; o < rod_.obstacles.size(); ++o) g[row + o * (n - 1) + (k - 1)] = rod_.obstacles[o].gap(Vec3(x, y, 0));
    }
    g[0] = x;
    g[1] = y;
    (void)row;
    return true;
  }

  bool eval_jac_g(Index n, const Number* t, bool, Index, Index, Index* rows, Index* cols, Number* values) override {
    Index e = 0;
    for (Index i = 0; i < n; ++i) {
      if (values) {
        values[e] = -h_ * std::sin(t[i]);
        values[e + 1] = h_ * std::cos(t[i]);
      } else {
        rows[e] = 0;
        cols[e] = i;
        rows[e + 1] = 1;
        cols[e + 1] = i;
      }
      e += 2;
    }
    const auto nodes = values ? node_positions(t) : std::vector<Vec3>();
    for (size_t o = 0; o < rod_.obstacles.size(); ++o) {
      for (Index k = 1; k < n; ++k) {
        const Vec3 normal = values ? rod_.obstacles[o].gradient(nodes[k]) : Vec3::Zero();
        for (Index i = 0; i < k; ++i, ++e) {
          if (values)
            values[e] = normal.x() * (-h_ * std::sin(t[i])) + normal.y() * (h_ * std::cos(t[i]));
          else {
            rows[e] = 2 + static_cast<Index>(o) * (n - 1) + (k - 1);
            cols[e] = i;
          }
        }
      }
    }
    return true;
  }

  bool eval_h(Index n, const Number* t, bool, Number obj_factor, Index, const Number* lambda, bool, Index,
              Index* rows, Index* cols, Number* values) override {
    if (!values) {
      Index e = 0;
      for (Index i = 0; i < n; ++i)
        for (Index j = curved_ ? 0 : std::max<Index>(0, i - 1); j <= i; ++j, ++e) {
          rows[e] = i;
          cols[e] = j;
        }
      return true;
    }
    // A gap row of node k involves the angles of segments 0..k-1 through r_k = sum h (cos, sin):
    // d2 g_k / dtheta_i dtheta_j = a_i^T Hess g a_j + delta_ij grad g . b_i, with
    // a_i = h (-sin, cos) theta_i and b_i = -h (cos, sin) theta_i. Summed with the multipliers over
    // the nodes k > max(i, j), as suffix sums of lambda_k grad g_k and lambda_k Hess g_k.
    const auto nodes = node_positions(t);
    std::vector<Vec3> gradient_tail(n, Vec3::Zero());
    std::vector<Mat3> hessian_tail(n, Mat3::Zero());
    for (size_t o = 0; o < rod_.obstacles.size(); ++o) {
      Vec3 g_sum = Vec3::Zero();
      Mat3 h_sum = Mat3::Zero();
      for (Index i = n - 1; i >= 0; --i) {
        if (i + 1 <= n - 1) {
          const double multiplier = lambda[2 + o * (n - 1) + i];  // node k = i + 1
          g_sum += multiplier * rod_.obstacles[o].gradient(nodes[i + 1]);
          if (!rod_.obstacles[o].is_flat()) h_sum += multiplier * rod_.obstacles[o].hessian(nodes[i + 1]);
        }
        gradient_tail[i] += g_sum;
        hessian_tail[i] += h_sum;
      }
    }
    auto a = [&](Index i) { return Vec3(-h_ * std::sin(t[i]), h_ * std::cos(t[i]), 0.0); };
    Index e = 0;
    for (Index i = 0; i < n; ++i) {
      for (Index j = curved_ ? 0 : std::max<Index>(0, i - 1); j <= i; ++j, ++e) {
        double value = curved_ ? a(i).dot(hessian_tail[i] * a(j)) : 0.0;
        if (j + 1 == i) value += -obj_factor * EI_[i] / h_;
        if (j == i) {
          // Energy: tridiagonal; end constraints and gaps: b_i = -h (cos, sin) theta_i.
          const Vec3 b(-h_ * std::cos(t[i]), -h_ * std::sin(t[i]), 0.0);
          value += obj_factor / h_ * (i > 0 ? EI_[i] : 2.0 * EI_[0]) + obj_factor / h_ * (i + 1 < n ? EI_[i + 1] : 2.0 * EI_[N_]);
          value += lambda[0] * b.x() + lambda[1] * b.y() + gradient_tail[i].dot(b);
        }
        values[e] = value;
      }
    }
    return true;
  }

  // Nodes 0..N from the segment angles.
  std::vector<Vec3> node_positions(const Number* t) const {
    std::vector<Vec3> out(N_ + 1, rod_.start);
    for (int k = 1; k <= N_; ++k) out[k] = out[k - 1] + h_ * Vec3(std::cos(t[k - 1]), std::sin(t[k - 1]), 0.0);
    return out;
  }

  void finalize_solution(Ipopt::SolverReturn status, Index n, const Number* t, const Number*, const Number*,
                         Index m, const Number* g, const Number* lambda, Number f, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    out_->converged = status == Ipopt::SUCCESS;
    out_->status = status == Ipopt::SUCCESS ? "converged" : "ipopt status " + std::to_string(static_cast<int>(status));
    out_->energy = f;
    out_->theta.assign(t, t + n);
    out_->x.assign(1, rod_.start.x());
    out_->y.assign(1, rod_.start.y());
    for (Index i = 0; i < n; ++i) {
      out_->x.push_back(out_->x.back() + h_ * std::cos(t[i]));
      out_->y.push_back(out_->y.back() + h_ * std::sin(t[i]));
    }
    // Ipopt's Lagrangian is f + lambda^T g: the end constraints' multipliers are the end
    // reaction, n(L) = -lambda (the force the constraint applies to the rod's end).
    // The gap rows' multipliers give the contact forces -lambda grad g, so that across the
    // contacts n(0) = n(L) + sum (-lambda_k) grad g_k (n' = -f; eq. 63 for a wall).
    out_->P = lambda[0];
    out_->contact_force = 0.0;
    out_->node_forces.assign(rod_.obstacles.size(), std::vector<double>(n - 1, 0.0));
    out_->node_gaps = out_->node_forces;
    out_->min_gap = INFINITY;
    Vec3 n_start(-lambda[0], -lambda[1], 0.0);
    std::vector<Vec3> nodes(n + 1);
    for (Index k = 0; k <= n; ++k) nodes[k] = Vec3(out_->x[k], out_->y[k], 0.0);
    for (Index r = 2; r < m; ++r) {
      const Index o = (r - 2) / (n - 1), k = (r - 2) % (n - 1) + 1;
      const Vec3 grad = rod_.obstacles[o].gradient(nodes[k]);
      out_->contact_force += -lambda[r] * grad.norm();
      n_start += -lambda[r] * grad;
      out_->min_gap = std::min(out_->min_gap, g[r]);
      out_->node_forces[o][k - 1] = -lambda[r] * grad.norm();
      out_->node_gaps[o][k - 1] = g[r];
    }
    out_->n_y = n_start.y();
    out_->n_start = n_start;
    out_->m_start = EI_[0] * (t[0] - rod_.start_angle) / (0.5 * h_);
  }

 private:
  DiscreteClampedElastica rod_;
  std::vector<double> EI_;
  int N_;
  double h_, amplitude_;
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
  if (!(rod.L > 0)) throw std::invalid_argument("discrete Elastica: L must be > 0");
  for (int k = 0; k <= 20; ++k)
    if (!(rod.EI(rod.L * k / 20) > 0)) throw std::invalid_argument("discrete Elastica: EI must be > 0 along the rod");
  if (!((rod.end - rod.start).norm() < rod.L))
    throw std::invalid_argument("discrete Elastica: the clamps are further apart than the rod is long");
  if (segments < 4) throw std::invalid_argument("discrete Elastica: at least 4 segments");
  DiscreteElasticaResult out;
  Ipopt::SmartPtr<Ipopt::TNLP> nlp = new ClampedElasticaNLP(rod, segments, amplitude, &out);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", 1e-12);
  app->Options()->SetIntegerValue("max_iter", 3000);
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  // Exact complementarity: by default Ipopt relaxes bounds by 1e-8, which would let the rod sit
  // 1e-8 inside the wall.
  app->Options()->SetNumericValue("bound_relax_factor", 0.0);
  if (app->Initialize() != Ipopt::Solve_Succeeded) throw std::runtime_error("Ipopt failed to initialise");
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(nlp);
  if (Ipopt::IsValid(app->Statistics())) out.iterations = app->Statistics()->IterationCount();
  if (status != Ipopt::Solve_Succeeded && status != Ipopt::Solved_To_Acceptable_Level) out.converged = false;
  return out;
}

}  // namespace kirchhoff

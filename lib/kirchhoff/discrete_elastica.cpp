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
  ClampedElasticaNLP(double L, double EI, double Delta, std::vector<PlaneObstacle> obstacles, int N, double amplitude,
                     DiscreteElasticaResult* out)
      : L_(L), EI_(EI), Delta_(Delta), obstacles_(std::move(obstacles)), N_(N), h_(L / N), amplitude_(amplitude),
        out_(out) {}

  // Constraints: 0: x(L) = L - Delta, 1: y(L) = 0, then for each obstacle o and interior node
  // k = 1..N-1: gap_o(x_k, y_k) >= 0.
  int gap_rows() const { return static_cast<int>(obstacles_.size()) * (N_ - 1); }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_hess, IndexStyleEnum& style) override {
    n = N_;
    m = 2 + gap_rows();
    // Node k depends on the angles of segments 0..k-1.
    nnz_jac = 2 * N_ + static_cast<int>(obstacles_.size()) * (N_ - 1) * N_ / 2;
    nnz_hess = 2 * N_ - 1;  // tridiagonal, lower triangle
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l, Number* g_u) override {
    for (Index i = 0; i < n; ++i) {
      x_l[i] = -M_PI;
      x_u[i] = M_PI;
    }
    g_l[0] = g_u[0] = L_ - Delta_;
    g_l[1] = g_u[1] = 0.0;
    for (Index r = 2; r < m; ++r) {
      g_l[r] = 0.0;
      g_u[r] = 2e19;  // Ipopt's +infinity
    }
    return true;
  }

  bool get_starting_point(Index n, bool, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    // theta of the first clamped-clamped mode y = (A/2)(1 - cos 2 pi s / L).
    for (Index i = 0; i < n; ++i) {
      const double s = (i + 0.5) * h_;
      x[i] = amplitude_ * M_PI / L_ * std::sin(2 * M_PI * s / L_);
    }
    return true;
  }

  bool eval_f(Index n, const Number* t, bool, Number& f) override {
    f = EI_ / h_ * (t[0] * t[0] + t[n - 1] * t[n - 1]);
    for (Index i = 0; i + 1 < n; ++i) f += 0.5 * EI_ / h_ * (t[i + 1] - t[i]) * (t[i + 1] - t[i]);
    return true;
  }

  bool eval_grad_f(Index n, const Number* t, bool, Number* g) override {
    for (Index i = 0; i < n; ++i) g[i] = 0.0;
    g[0] += 2 * EI_ / h_ * t[0];
    g[n - 1] += 2 * EI_ / h_ * t[n - 1];
    for (Index i = 0; i + 1 < n; ++i) {
      const double d = EI_ / h_ * (t[i + 1] - t[i]);
      g[i + 1] += d;
      g[i] -= d;
    }
    return true;
  }

  bool eval_g(Index n, const Number* t, bool, Index, Number* g) override {
    double x = 0.0, y = 0.0;
    Index row = 2;
    for (Index k = 1; k <= n; ++k) {
      x += h_ * std::cos(t[k - 1]);
      y += h_ * std::sin(t[k - 1]);
      if (k < n)
        for (size_t o = 0; o < obstacles_.size(); ++o) g[row + o * (n - 1) + (k - 1)] = obstacles_[o].gap(Vec3(x, y, 0));
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
    for (size_t o = 0; o < obstacles_.size(); ++o) {
      const Vec3 normal = obstacles_[o].normal;
      for (Index k = 1; k < n; ++k)
        for (Index i = 0; i < k; ++i, ++e) {
          if (values)
            values[e] = normal.x() * (-h_ * std::sin(t[i])) + normal.y() * (h_ * std::cos(t[i]));
          else {
            rows[e] = 2 + static_cast<Index>(o) * (n - 1) + (k - 1);
            cols[e] = i;
          }
        }
    }
    return true;
  }

  bool eval_h(Index n, const Number* t, bool, Number obj_factor, Index, const Number* lambda, bool, Index,
              Index* rows, Index* cols, Number* values) override {
    if (!values) {
      Index e = 0;
      for (Index i = 0; i < n; ++i, ++e) rows[e] = cols[e] = i;
      for (Index i = 1; i < n; ++i, ++e) {
        rows[e] = i;
        cols[e] = i - 1;
      }
      return true;
    }
    // Energy: tridiagonal. Constraints: each is a sum of functions of single angles, so their
    // Hessians are diagonal; a gap row of node k involves the angles of segments 0..k-1.
    std::vector<double> diag(n, 0.0);
    for (Index i = 0; i < n; ++i) {
      diag[i] = obj_factor * EI_ / h_ * ((i > 0 ? 1.0 : 2.0) + (i + 1 < n ? 1.0 : 2.0));
      diag[i] += lambda[0] * (-h_ * std::cos(t[i])) + lambda[1] * (-h_ * std::sin(t[i]));
    }
    for (size_t o = 0; o < obstacles_.size(); ++o) {
      const Vec3 normal = obstacles_[o].normal;
      // Suffix sums of the multipliers: angle i appears in the gaps of nodes k = i+1..n-1.
      double tail = 0.0;
      for (Index i = n - 1; i >= 0; --i) {
        if (i + 1 <= n - 1) tail += lambda[2 + o * (n - 1) + i];
        diag[i] += tail * (normal.x() * (-h_ * std::cos(t[i])) + normal.y() * (-h_ * std::sin(t[i])));
      }
    }
    Index e = 0;
    for (Index i = 0; i < n; ++i, ++e) values[e] = diag[i];
    for (Index i = 1; i < n; ++i, ++e) values[e] = -obj_factor * EI_ / h_;
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn status, Index n, const Number* t, const Number*, const Number*,
                         Index m, const Number* g, const Number* lambda, Number f, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    out_->converged = status == Ipopt::SUCCESS;
    out_->status = status == Ipopt::SUCCESS ? "converged" : "ipopt status " + std::to_string(static_cast<int>(status));
    out_->energy = f;
    out_->theta.assign(t, t + n);
    out_->x.assign(1, 0.0);
    out_->y.assign(1, 0.0);
    for (Index i = 0; i < n; ++i) {
      out_->x.push_back(out_->x.back() + h_ * std::cos(t[i]));
      out_->y.push_back(out_->y.back() + h_ * std::sin(t[i]));
    }
    // Ipopt's Lagrangian is f + lambda^T g: the end constraints' multipliers are the end
    // reaction, n(L) = -lambda (the force the constraint applies to the rod's end).
    out_->P = lambda[0];
    out_->contact_force = 0.0;
    out_->node_forces.assign(n - 1, 0.0);
    out_->min_gap = INFINITY;
    for (Index r = 2; r < m; ++r) {
      out_->contact_force += -lambda[r];
      out_->min_gap = std::min(out_->min_gap, g[r]);
      if (r - 2 < n - 1) out_->node_forces[r - 2] = -lambda[r];
    }
    // n_y(L) = -lambda[1]; across the contacts n_y jumps up by the contact forces (eq. 63).
    out_->n_y = -lambda[1] - out_->contact_force;
  }

 private:
  double L_, EI_, Delta_;
  std::vector<PlaneObstacle> obstacles_;
  int N_;
  double h_, amplitude_;
  DiscreteElasticaResult* out_;
};

}  // namespace

DiscreteElasticaResult solve_discrete_clamped_elastica(double L, double EI, double Delta,
                                                       const std::vector<PlaneObstacle>& obstacles, int segments,
                                                       double amplitude) {
  if (!(L > 0) || !(EI > 0)) throw std::invalid_argument("discrete Elastica: L and EI must be > 0");
  if (!(Delta > 0 && Delta < L)) throw std::invalid_argument("discrete Elastica: Delta must lie in (0, L)");
  if (segments < 4) throw std::invalid_argument("discrete Elastica: at least 4 segments");
  std::vector<PlaneObstacle> planes = obstacles;
  for (auto& o : planes) o.normal.normalize();
  DiscreteElasticaResult out;
  Ipopt::SmartPtr<Ipopt::TNLP> nlp = new ClampedElasticaNLP(L, EI, Delta, planes, segments, amplitude, &out);
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

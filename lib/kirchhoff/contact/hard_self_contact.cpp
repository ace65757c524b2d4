#include "kirchhoff/contact/hard_self_contact.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <unordered_map>

#include "kirchhoff/contact/detail/ipopt_application.hpp"
#include "kirchhoff/contact/plectoneme.hpp"
#include "kirchhoff/contact/self_contact.hpp"

namespace kirchhoff {
namespace {

using Ipopt::Index;
using Ipopt::Number;
using Quat = Eigen::Vector4d;  // (w, x, y, z)
using Mat4 = Eigen::Matrix4d;

constexpr double kIpoptInfinity = 2e19;

Quat multiply(const Quat& a, const Quat& b) {
  Quat c;
  c[0] = a[0] * b[0] - a.tail<3>().dot(b.tail<3>());
  c.tail<3>() = a[0] * b.tail<3>() + b[0] * a.tail<3>() + a.tail<3>().cross(b.tail<3>());
  return c;
}

Quat conjugate(const Quat& a) { return Quat(a[0], -a[1], -a[2], -a[3]); }

// d3 of the frame of q, without normalising: quadratic in q, |d3| = |q|^2.
Vec3 director3(const Quat& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return Vec3(2.0 * (x * z + w * y), 2.0 * (y * z - w * x), w * w - x * x - y * y + z * z);
}

// The constant matrices of the bilinear and quadratic forms the energy and constraints are made
// of: vec_k(conj(a) b) = a^T C_k b, d3_j(q) = q^T D_j q (D_j symmetric).
struct QuaternionForms {
  std::array<Mat4, 3> C, D;
  QuaternionForms() {
    const Mat4 I = Mat4::Identity();
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
          C[k](i, j) = multiply(conjugate(I.col(i)), I.col(j))[k + 1];
          D[k](i, j) = 0.5 * (director3(I.col(i) + I.col(j)) - director3(I.col(i)) - director3(I.col(j)))[k];
        }
  }
};

// The seed and everything fixed: the clamp, the symmetry, the stiffnesses at the pairs.
struct HalfRod {
  int N = 0;
  double h = 0.0, R = 0.0;
  Vec3 clamp = Vec3::Zero();
  Quat clamp_frame = Quat(1, 0, 0, 0);
  Vec3 axis = Vec3::UnitX(), origin = Vec3::Zero(), across1, across2;
  Mat4 image;  // q of the image edge = image * q (the half-turn about the axis, and about the director)
  std::vector<Vec3> B;  // B at node j = 0..N (the pairs: clamp-edge 0 at node 0, edges j-1, j at node j)
  int constrained = 0;  // nodes 1..constrained carry rho >= R
  std::vector<Vec3> seed_nodes;
  std::vector<Quat> seed_frames;
  double node_box = 0.0;  // half-width of the trust region's box for the nodes
};

// Half-width of the trust region's box for the frames' quaternion components: neighbouring
// frames, a fraction of a radian apart, cannot turn relative to each other through pi within it,
// where the energy (a function of sin of half the relative angle) would let the twist unwind.
constexpr double kFrameBox = 0.3;

class HardContactNLP : public Ipopt::TNLP {
 public:
  HardContactNLP(const HalfRod& rod, HardSelfContactPlectoneme* out) : rod_(rod), out_(out) {
    const int N = rod_.N;
    // Lower triangle of the Lagrangian's Hessian: the frames' blocks and their neighbours', the
    // constrained nodes' blocks.
    for (int i = 0; i < N; ++i) {
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c <= r; ++c) entry(q(i) + r, q(i) + c);
      if (i + 1 < N)
        for (int r = 0; r < 4; ++r)
          for (int c = 0; c < 4; ++c) entry(q(i + 1) + r, q(i) + c);
    }
    for (int j = 1; j <= rod_.constrained; ++j)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c <= r; ++c) entry(x(j) + r, x(j) + c);
  }

  int q(int i) const { return 4 * i; }
  int x(int j) const { return 4 * rod_.N + 3 * (j - 1); }  // nodes 1..N
  int edge_row(int i) const { return 3 * i; }
  int unit_row(int i) const { return 3 * rod_.N + i; }
  int axis_row() const { return 4 * rod_.N; }
  int contact_row(int j) const { return 4 * rod_.N + 2 + (j - 1); }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_hess, IndexStyleEnum& style) override {
    const int N = rod_.N;
    n = 7 * N;
    m = 4 * N + 2 + rod_.constrained;
    nnz_jac = 3 * (4 + 1) * N + 3 * (N - 1) + 4 * N + 6 + 3 * rod_.constrained;
    nnz_hess = static_cast<Index>(hessian_rows_.size());
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l, Number* g_u) override {
    std::fill(x_l, x_l + n, -kIpoptInfinity);
    std::fill(x_u, x_u + n, kIpoptInfinity);
    // The trust region about the seed (see solve_hard_self_contact).
    for (int i = 0; i < rod_.N; ++i)
      for (int a = 0; a < 4; ++a)
        x_l[q(i) + a] = rod_.seed_frames[i][a] - kFrameBox, x_u[q(i) + a] = rod_.seed_frames[i][a] + kFrameBox;
    for (int j = 1; j <= rod_.N; ++j)
      for (int a = 0; a < 3; ++a)
        x_l[x(j) + a] = rod_.seed_nodes[j][a] - rod_.node_box, x_u[x(j) + a] = rod_.seed_nodes[j][a] + rod_.node_box;
    std::fill(g_l, g_l + m, 0.0);
    std::fill(g_u, g_u + m, 0.0);
    for (int j = 1; j <= rod_.constrained; ++j) g_u[contact_row(j)] = kIpoptInfinity;
    return true;
  }

  bool get_starting_point(Index, bool, Number* v, bool, Number*, Number*, Index, bool, Number*) override {
    for (int i = 0; i < rod_.N; ++i) Eigen::Map<Quat>(v + q(i)) = rod_.seed_frames[i];
    for (int j = 1; j <= rod_.N; ++j) Eigen::Map<Vec3>(v + x(j)) = rod_.seed_nodes[j];
    return true;
  }

  bool eval_f(Index, const Number* v, bool, Number& f) override {
    f = 0.0;
    for_each_pair(v, [&](const Pair& p) { f += p.energy; });
    return true;
  }

  bool eval_grad_f(Index n, const Number* v, bool, Number* grad) override {
    std::fill(grad, grad + n, 0.0);
    for_each_pair(v, [&](const Pair& p) {
      if (p.a >= 0) Eigen::Map<Quat>(grad + q(p.a)) += p.grad_a;
      Eigen::Map<Quat>(grad + q(p.b)) += p.grad_b;
    });
    return true;
  }

  bool eval_g(Index, const Number* v, bool, Index, Number* g) override {
    for (int i = 0; i < rod_.N; ++i) {
      const Quat qi = frame(v, i);
      const Vec3 e = (node(v, i + 1) - node(v, i)) / rod_.h;
      Eigen::Map<Vec3>(g + edge_row(i)) = director3(qi) - e;
      g[unit_row(i)] = qi.squaredNorm() - 1.0;
    }
    const Vec3 end = node(v, rod_.N) - rod_.origin;
    g[axis_row()] = rod_.across1.dot(end);
    g[axis_row() + 1] = rod_.across2.dot(end);
    for (int j = 1; j <= rod_.constrained; ++j) g[contact_row(j)] = radial(node(v, j)).squaredNorm() - rod_.R * rod_.R;
    return true;
  }

  bool eval_jac_g(Index, const Number* v, bool, Index, Index, Index* rows, Index* cols, Number* values) override {
    int k = 0;
    auto put = [&](int r, int c, double value) {
      if (values) values[k] = value;
      else rows[k] = r, cols[k] = c;
      ++k;
    };
    const QuaternionForms& forms = this->forms();
    for (int i = 0; i < rod_.N; ++i) {
      const Quat qi = v ? frame(v, i) : Quat::Zero();
      for (int c = 0; c < 3; ++c) {
        const Quat dq = 2.0 * forms.D[c] * qi;
        for (int a = 0; a < 4; ++a) put(edge_row(i) + c, q(i) + a, dq[a]);
        if (i >= 1) put(edge_row(i) + c, x(i) + c, 1.0 / rod_.h);
        put(edge_row(i) + c, x(i + 1) + c, -1.0 / rod_.h);
      }
      for (int a = 0; a < 4; ++a) put(unit_row(i), q(i) + a, 2.0 * qi[a]);
    }
    for (int c = 0; c < 3; ++c) put(axis_row(), x(rod_.N) + c, rod_.across1[c]);
    for (int c = 0; c < 3; ++c) put(axis_row() + 1, x(rod_.N) + c, rod_.across2[c]);
    for (int j = 1; j <= rod_.constrained; ++j) {
      const Vec3 d = v ? radial(node(v, j)) : Vec3::Zero();
      for (int c = 0; c < 3; ++c) put(contact_row(j), x(j) + c, 2.0 * d[c]);
    }
    return true;
  }

  bool eval_h(Index, const Number* v, bool, Number sigma, Index, const Number* lambda, bool, Index, Index* rows,
              Index* cols, Number* values) override {
    if (!values) {
      std::copy(hessian_rows_.begin(), hessian_rows_.end(), rows);
      std::copy(hessian_cols_.begin(), hessian_cols_.end(), cols);
      return true;
    }
    std::fill(values, values + hessian_rows_.size(), 0.0);
    auto add = [&](int row0, int col0, const auto& block, double weight) {
      for (int r = 0; r < block.rows(); ++r)
        for (int c = 0; c < block.cols(); ++c)
          if (row0 + r >= col0 + c) values[hessian_index_.at(key(row0 + r, col0 + c))] += weight * block(r, c);
    };
    for_each_pair(v, [&](const Pair& p) {
      if (p.a >= 0) {
        add(q(p.a), q(p.a), p.hessian.topLeftCorner<4, 4>(), sigma);
        add(q(p.b), q(p.a), p.hessian.bottomLeftCorner<4, 4>(), sigma);
      }
      add(q(p.b), q(p.b), p.hessian.bottomRightCorner<4, 4>(), sigma);
    });
    const QuaternionForms& forms = this->forms();
    for (int i = 0; i < rod_.N; ++i) {
      Mat4 H = 2.0 * lambda[unit_row(i)] * Mat4::Identity();
      for (int c = 0; c < 3; ++c) H += 2.0 * lambda[edge_row(i) + c] * forms.D[c];
      add(q(i), q(i), H, 1.0);
    }
    const Mat3 across = Mat3::Identity() - rod_.axis * rod_.axis.transpose();
    for (int j = 1; j <= rod_.constrained; ++j) add(x(j), x(j), 2.0 * across, lambda[contact_row(j)]);
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn status, Index, const Number* v, const Number*, const Number*, Index,
                         const Number*, const Number* lambda, Number f, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    HardSelfContactPlectoneme& out = *out_;
    out.converged = status == Ipopt::SUCCESS;
    out.status = out.converged ? "converged" : "ipopt status " + std::to_string(static_cast<int>(status));
    out.energy = f;
    const int N = rod_.N;
    out.nodes.resize(N + 1);
    out.node_force.assign(N + 1, 0.0);
    out.node_radius.resize(N + 1);
    for (int j = 0; j <= N; ++j) {
      out.nodes[j] = node(v, j);
      out.node_radius[j] = radial(out.nodes[j]).norm();
    }
    // The constraint rho^2 - R^2 >= 0 pushes with -lambda grad = -2 lambda rho outwards.
    for (int j = 1; j <= rod_.constrained; ++j) out.node_force[j] = -2.0 * lambda[contact_row(j)] * out.node_radius[j];
    const Vec3 n0 = -Eigen::Map<const Vec3>(lambda + edge_row(0)) / rod_.h;
    // n is constant between the clamp and the first contact: n_0 is n(0), read along the clamp's d3.
    out.T_ext = n0.dot(director3(rod_.clamp_frame));
    // The twist rate from the exact angle of the relative rotation in the middle of the half rod.
    const int mid = N / 2;
    Quat p = multiply(conjugate(frame(v, mid - 1)), frame(v, mid));
    if (p[0] < 0) p = -p;
    const double sine = p.tail<3>().norm();
    const Vec3 rotation = sine > 0 ? Vec3(2.0 * std::atan2(sine, p[0]) * p.tail<3>() / sine) : Vec3::Zero();
    out.m3 = rod_.B[mid][2] * rotation[2] / rod_.h;
    measure_contact(v, &out);
    out.box_active = 0;
    for (int i = 0; i < N; ++i)
      for (int a = 0; a < 4; ++a)
        out.box_active += std::abs(v[q(i) + a] - rod_.seed_frames[i][a]) >= (1.0 - 1e-6) * kFrameBox;
    for (int j = 1; j <= N; ++j)
      for (int a = 0; a < 3; ++a)
        out.box_active += std::abs(v[x(j) + a] - rod_.seed_nodes[j][a]) >= (1.0 - 1e-6) * rod_.node_box;
    out.frames.resize(N);
    for (int i = 0; i < N; ++i) out.frames[i] = frame(v, i);
  }

 private:
  // One term of the energy: the pair (frame a, frame b), a = -1 for the clamp's frame, b = a for
  // the pair of the last edge with its image; its value, gradient and Hessian in (q_a, q_b)
  // (for the image pair only in q_b, in the bottom-right block).
  struct Pair {
    int a = -1, b = 0;
    double energy = 0.0;
    Quat grad_a = Quat::Zero(), grad_b = Quat::Zero();
    Eigen::Matrix<double, 8, 8> hessian = Eigen::Matrix<double, 8, 8>::Zero();
  };

  template <class Visit>
  void for_each_pair(const Number* v, const Visit& visit) const {
    const QuaternionForms& forms = this->forms();
    const int N = rod_.N;
    const double h = rod_.h;
    Pair p;
    // Clamp: kappa_k = Qc^T C_k q_0 is linear in q_0; the pair is h/2 apart, weight 4 B_k / h.
    p.a = -1;
    p.b = 0;
    p.energy = 0.0;
    p.grad_b.setZero();
    p.hessian.setZero();
    const Quat q0 = frame(v, 0);
    for (int k = 0; k < 3; ++k) {
      const double w = 4.0 * rod_.B[0][k] / h;
      const Quat g = forms.C[k].transpose() * rod_.clamp_frame;
      const double kappa = g.dot(q0);
      p.energy += w * kappa * kappa;
      p.grad_b += 2.0 * w * kappa * g;
      p.hessian.bottomRightCorner<4, 4>() += 2.0 * w * g * g.transpose();
    }
    visit(p);
    // Neighbouring edges: kappa_k = a^T C_k b, weight 2 B_k / h.
    for (int i = 0; i + 1 < N; ++i) {
      p.a = i;
      p.b = i + 1;
      p.energy = 0.0;
      p.grad_a.setZero();
      p.grad_b.setZero();
      p.hessian.setZero();
      const Quat a = frame(v, i), b = frame(v, i + 1);
      for (int k = 0; k < 3; ++k) {
        const double w = 2.0 * rod_.B[i + 1][k] / h;
        const Quat ga = forms.C[k] * b, gb = forms.C[k].transpose() * a;
        const double kappa = a.dot(ga);
        Eigen::Matrix<double, 8, 1> g;
        g << ga, gb;
        p.energy += w * kappa * kappa;
        p.grad_a += 2.0 * w * kappa * ga;
        p.grad_b += 2.0 * w * kappa * gb;
        p.hessian += 2.0 * w * g * g.transpose();
        p.hessian.topRightCorner<4, 4>() += 2.0 * w * kappa * forms.C[k];
        p.hessian.bottomLeftCorner<4, 4>() += 2.0 * w * kappa * forms.C[k].transpose();
      }
      visit(p);
    }
    // The last edge and its image, h apart, counted half: weight B_k / h, kappa_k = a^T Q_k a.
    p.a = -1;
    p.b = N - 1;
    p.energy = 0.0;
    p.grad_b.setZero();
    p.hessian.setZero();
    const Quat a = frame(v, N - 1);
    for (int k = 0; k < 3; ++k) {
      const double w = rod_.B[N][k] / h;
      const Mat4 Q = 0.5 * (forms.C[k] * rod_.image + (forms.C[k] * rod_.image).transpose());
      const Quat g = 2.0 * Q * a;
      const double kappa = a.dot(Q * a);
      p.energy += w * kappa * kappa;
      p.grad_b += 2.0 * w * kappa * g;
      p.hessian.bottomRightCorner<4, 4>() += 2.0 * w * (g * g.transpose() + 2.0 * kappa * Q);
    }
    visit(p);
  }

  void measure_contact(const Number* v, HardSelfContactPlectoneme* out) const {
    const int N = rod_.N;
    const double largest = *std::max_element(out->node_force.begin(), out->node_force.end());
    out->min_gap = INFINITY;
    out->min_force = INFINITY;
    out->complementarity = 0.0;
    for (int j = 1; j <= rod_.constrained; ++j) {
      const double gap = out->node_radius[j] - rod_.R;
      out->min_gap = std::min(out->min_gap, gap / rod_.R);
      if (largest > 0) {
        out->min_force = std::min(out->min_force, out->node_force[j] / largest);
        out->complementarity = std::max(out->complementarity, std::abs(out->node_force[j] * gap) / (largest * rod_.R));
      }
    }
    int first = N + 1, last = -1;
    for (int j = 1; j <= rod_.constrained; ++j)
      if (largest > 0 && out->node_force[j] >= kContactFraction * largest) first = std::min(first, j), last = j;
    if (last < first) return;
    out->contact_start = first * rod_.h;
    out->contact_end = last * rod_.h;
    const int quarter = (last - first) / 4;
    double angle = 0.0, radius = 0.0, pressure = 0.0;
    int count = 0;
    for (int j = first + quarter; j <= last - quarter; ++j, ++count) {
      angle += std::acos(std::min(1.0, std::abs(director3(frame(v, j)).normalized().dot(rod_.axis))));
      radius += out->node_radius[j];
      pressure += out->node_force[j] / rod_.h;
    }
    out->helix_angle = angle / count;
    out->helix_radius = radius / count;
    out->contact_pressure = pressure / count;
  }

  Quat frame(const Number* v, int i) const { return Eigen::Map<const Quat>(v + q(i)); }
  Vec3 node(const Number* v, int j) const { return j == 0 ? rod_.clamp : Vec3(Eigen::Map<const Vec3>(v + x(j))); }
  Vec3 radial(const Vec3& r) const {
    const Vec3 d = r - rod_.origin;
    return d - rod_.axis * rod_.axis.dot(d);
  }
  static const QuaternionForms& forms() {
    static const QuaternionForms instance;
    return instance;
  }
  static long long key(int r, int c) { return static_cast<long long>(r) << 32 | static_cast<unsigned>(c); }
  void entry(int r, int c) {
    if (hessian_index_.emplace(key(r, c), static_cast<int>(hessian_rows_.size())).second) {
      hessian_rows_.push_back(r);
      hessian_cols_.push_back(c);
    }
  }

  const HalfRod& rod_;
  HardSelfContactPlectoneme* out_;
  std::vector<Index> hessian_rows_, hessian_cols_;
  std::unordered_map<long long, int> hessian_index_;
};

Quat quaternion_of(const Mat3& R) {
  const Eigen::Quaterniond e(R);
  return Quat(e.w(), e.x(), e.y(), e.z());
}

HalfRod half_rod(const ShootingProblem& problem, const Eigen::VectorXd& x, const HardSelfContactOptions& options) {
  const RodModel& model = problem.equations(problem.parameters_at(x))->model();
  const HalfTurnSelfContact* contact = find_half_turn_self_contact(model);
  if (!contact) throw std::invalid_argument("hard self-contact needs a rod with [rod.self_contact]");
  if (problem.definition().kind != RodKind::Spatial || model.extensible)
    throw std::invalid_argument("hard self-contact: only inextensible, unshearable spatial (Kirchhoff) rods");
  if (!(options.spacing > 0 && options.spacing <= 1)) throw std::invalid_argument("hard self-contact: spacing must be in (0, 1] (units of R)");
  if (!(options.tolerance > 0) || options.max_iterations < 1 || !(options.trust_radius > 0) || options.max_rounds < 1)
    throw std::invalid_argument("hard self-contact: tolerance, max_iterations, trust_radius and max_rounds must be > 0");
  const auto& o = contact->options();
  HalfRod rod;
  const double Lh = model.length;
  rod.R = o.radius;
  rod.N = std::max(8, static_cast<int>(std::ceil(Lh / (options.spacing * o.radius))));
  rod.h = Lh / rod.N;
  for (int j = 0; j <= 20; ++j)
    for (int k = 0; k < 3; ++k)
      if (model.u_hat[k](Lh * j / 20) != 0.0 || model.v_hat[k](Lh * j / 20) != (k == 2 ? 1.0 : 0.0))
        throw std::invalid_argument("hard self-contact: natural curvature or strain is not modelled");
  for (int j = 0; j <= rod.N; ++j) rod.B.emplace_back(model.B[0](j * rod.h), model.B[1](j * rod.h), model.B[2](j * rod.h));
  rod.axis = o.axis.normalized();
  rod.origin = o.origin;
  rod.across1 = rod.axis.unitOrthogonal();
  rod.across2 = rod.axis.cross(rod.across1);
  rod.node_box = options.trust_radius * o.radius;
  for (int j = 1; j <= rod.N && Lh - j * rod.h >= 2.0 * o.adjacent - 1e-12 * Lh; ++j) rod.constrained = j;

  // The seed: nodes at s = j h, frames mid-edge, both from the shooting solution.
  std::vector<double> s;
  for (int k = 0; k <= 2 * rod.N; ++k) s.push_back(std::min(Lh, 0.5 * k * rod.h));
  const std::vector<RodPoint> samples = problem.sample(x, s);
  rod.clamp = samples.front().r;
  rod.clamp_frame = quaternion_of(samples.front().R);
  for (int j = 0; j <= rod.N; ++j) rod.seed_nodes.push_back(samples[2 * j].r);
  Quat previous = rod.clamp_frame;
  for (int i = 0; i < rod.N; ++i) {
    Quat qi = quaternion_of(samples[2 * i + 1].R);
    if (qi.dot(previous) < 0) qi = -qi;  // neighbouring frames on the same side of the double cover
    rod.seed_frames.push_back(qi);
    previous = qi;
  }
  // The image of an edge's frame: F(L - s) = S F(s) diag(+-1) with S the half-turn about the
  // axis and the diagonal turning the frame by pi about the director that lies along the axis
  // at s = L/2, so that d3 reverses (the image runs the other way).
  const Mat3& end_frame = samples.back().R;
  const Quat about_director = std::abs(end_frame.col(0).dot(rod.axis)) >= std::abs(end_frame.col(1).dot(rod.axis))
                                  ? Quat(0, 1, 0, 0)
                                  : Quat(0, 0, 1, 0);
  const Quat half_turn(0, rod.axis.x(), rod.axis.y(), rod.axis.z());
  for (int c = 0; c < 4; ++c) rod.image.col(c) = multiply(multiply(half_turn, Mat4::Identity().col(c)), about_director);
  return rod;
}

}  // namespace

HardSelfContactPlectoneme solve_hard_self_contact(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                                  const HardSelfContactOptions& options) {
  HalfRod rod = half_rod(problem, x, options);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = detail::make_ipopt_application();
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", options.tolerance);
  app->Options()->SetIntegerValue("max_iter", options.max_iterations);
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  // Exact complementarity: by default Ipopt relaxes bounds by 1e-8 (see discrete_elastica.cpp).
  app->Options()->SetNumericValue("bound_relax_factor", 0.0);
  if (app->Initialize() != Ipopt::Solve_Succeeded) throw std::runtime_error("Ipopt failed to initialise");
  // Each round minimises within the trust region about the last round's result; a minimum inside
  // it (no bound of the region active) is the answer.
  HardSelfContactPlectoneme out;
  int iterations = 0;
  for (int round = 1; round <= options.max_rounds; ++round) {
    out = HardSelfContactPlectoneme{};
    out.radius = rod.R;
    out.segments = rod.N;
    out.spacing = rod.h;
    out.rounds = round;
    Ipopt::SmartPtr<Ipopt::TNLP> nlp = new HardContactNLP(rod, &out);
    app->OptimizeTNLP(nlp);
    if (Ipopt::IsValid(app->Statistics())) iterations += app->Statistics()->IterationCount();
    out.iterations = iterations;
    if (!out.converged || out.box_active == 0) break;
    rod.seed_nodes.assign(out.nodes.begin(), out.nodes.end());
    rod.seed_frames = out.frames;
  }
  if (out.converged && out.box_active > 0) {
    out.converged = false;
    out.status = "no minimum inside the trust region after " + std::to_string(out.rounds) + " rounds";
  }
  // Ipopt's word is not taken alone: the contact set is checked from the solution itself (the
  // nodes' distances and the multipliers' forces, measure_contact): no strand inside the other,
  // no pulling force, force only where the strands touch. Measured at L/2R = 100 and 200: gaps
  // >= -1e-12 R, force x gap <= 4e-12 of the largest force x R; the bound is 100 times Ipopt's
  // tolerance (1e-10 by default), so only a solution that is not a complementarity point fails.
  const double bound = std::max(1e-8, 100.0 * options.tolerance);
  if (out.converged && !(out.min_gap >= -bound && out.min_force >= -bound && out.complementarity <= bound)) {
    out.converged = false;
    char text[200];
    std::snprintf(text, sizeof text,
                  "complementarity check failed: smallest gap %.2e R, smallest force %.2e, force x gap %.2e (bound %.0e)",
                  out.min_gap, out.min_force, out.complementarity, bound);
    out.status = text;
  }
  return out;
}

std::vector<PointContact> ply_contacts(const HardSelfContactPlectoneme& solution) {
  const auto& f = solution.node_force;
  const double largest = f.empty() ? 0.0 : *std::max_element(f.begin(), f.end());
  // Inactive constraints' multipliers are ~1e-8 of the active ones' (Ipopt's interior point).
  const double pressed = 1e-6 * largest;
  std::vector<PointContact> out;
  const double h = solution.spacing;
  for (size_t i = 0; i < f.size();) {
    if (!(f[i] > pressed)) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < f.size() && f[j + 1] > pressed) ++j;
    PointContact c;
    c.obstacle = 0;
    if (static_cast<int>(j - i + 1) <= kPointContactNodes) {
      double total = 0.0, moment = 0.0;
      for (size_t k = i; k <= j; ++k) total += f[k], moment += f[k] * k * h;
      c.s = moment / total;
      c.force = total;
    } else {
      c.extended = true;
      c.s = i * h;
      c.s_end = j * h;
      c.force = std::max(0.0, f[i] - f[i + 1]);
      c.force_end = std::max(0.0, f[j] - f[j - 1]);
    }
    out.push_back(c);
    i = j + 1;
  }
  return out;
}

}  // namespace kirchhoff

// The stability index from a discretised energy's projected Hessian (see discrete_stability.hpp).
#include "kirchhoff/discrete_stability.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace kirchhoff {
namespace {

using Vec2 = Eigen::Vector2d;

// Where a constraint acts: a position component or the angle at one end.
enum class Held { StartPosition, EndPosition, StartAngle, EndAngle };

struct Constraint {
  Held kind = Held::StartPosition;
  Vec2 direction = Vec2::Zero();  // positions: the component held (unit)
  double value = 0.0;             // e.r or theta held at this value
};

// What the case says of its ends and loads, independent of the number of elements.
struct Reading {
  Vec2 start_force = Vec2::Zero(), end_force = Vec2::Zero();  // dead loads applied at the ends
  double start_moment = 0.0, end_moment = 0.0;
  std::vector<Constraint> constraints;
};

std::string format(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

// How the imposed value of a slot changes with a parameter (central difference of a closed form).
Vec3 slot_rate(const SlotCondition& slot, const Parameters& p, const std::string& name) {
  const double value = p.get(name), step = 1e-6 * std::max(1.0, std::abs(value));
  Parameters plus = p, minus = p;
  plus.set(name, value + step);
  minus.set(name, value - step);
  if (slot.slot == Slot::Orientation) {
    auto vector = [&](const Parameters& q) { return Vec3(slot.orientation(q).axis.normalized() * slot.orientation(q).angle); };
    return (vector(plus) - vector(minus)) / (2 * step);
  }
  return (slot.value(plus) - slot.value(minus)) / (2 * step);
}

// The unknown parameters that are end loads (Lagrange multipliers), or why one is not.
std::string multiplier_loads(const ShootingProblem& problem, const Parameters& p, std::vector<std::string>* loads) {
  const ProblemDefinition& d = problem.definition();
  for (const std::string& name : d.unknown_parameters) {
    if (d.model_parameters.count(name) || d.obstacle_parameters.count(name))
      return "the unknown parameter '" + name + "' changes the rod or an obstacle, not an end load";
    bool load = false;
    for (const EndCondition* end : {&d.start, &d.end})
      for (const SlotCondition& slot : end->conditions()) {
        if (slot.extra || slot_rate(slot, p, name).norm() == 0.0) continue;
        if (slot.slot == Slot::Position || slot.slot == Slot::Orientation)
          return "the unknown parameter '" + name + "' moves an imposed " + to_string(slot.slot);
        load = true;
      }
    if (!load) return "the unknown parameter '" + name + "' is not an end load";
    loads->push_back(name);
  }
  return "";
}

// Spatial, extensible, contacts, half rods, sleeves: what this discretisation does not model.
std::string not_covered(const ShootingProblem& problem, const Eigen::VectorXd& x, const RodModel& model) {
  const ProblemDefinition& d = problem.definition();
  if (d.kind != RodKind::Planar) return "a spatial rod: the discrete check is planar";
  if (model.extensible) return "an extensible rod: the discrete check is for inextensible rods";
  for (int i : {0, 2})
    if (!model.v_hat[i].is_constant() || model.v_hat[i](0.0) != (i == 2 ? 1.0 : 0.0))
      return "natural shear or stretch (v_hat is not (0, 0, 1)): not modelled by the discrete check";
  if (!problem.contacts_at(x).empty()) return "active contacts: not modelled by the discrete check";
  for (const EndCondition* end : {&d.start, &d.end}) {
    if (end->is_half_turn_symmetry()) return "half of a symmetric rod: the discrete check needs the whole rod";
    int extra_slots = 0;
    for (const SlotCondition& slot : end->conditions()) extra_slots += slot.extra ? 1 : 0;
    if (end->extra_count() > extra_slots)
      return "an end closed by the continuity of H (a sleeve): its sliding length is not modelled";
  }
  return "";
}

// Reads one end's conditions: dead loads into `force`/`moment`, held quantities into constraints.
void read_end(const RodEquations& eq, const EndCondition& end, bool at_start, const RodPoint& point,
              const Parameters& p, const std::vector<std::string>& multipliers, Reading* out) {
  Vec2& force = at_start ? out->start_force : out->end_force;
  double& moment = at_start ? out->start_moment : out->end_moment;
  const Held position = at_start ? Held::StartPosition : Held::EndPosition;
  const Held angle = at_start ? Held::StartAngle : Held::EndAngle;
  const double theta = point.turn_angle;
  for (const SlotCondition& slot : end.conditions()) {
    if (slot.extra) continue;  // selects the equilibrium only
    const Eigen::MatrixXd basis = slot.basis(eq);
    const Eigen::MatrixXd projector = basis * basis.transpose();
    switch (slot.slot) {
      case Slot::Position:
        for (int k = 0; k < basis.cols(); ++k) {
          const Vec3 e = basis.col(k);
          out->constraints.push_back({position, e.head<2>(), e.dot(slot.value(p))});
        }
        break;
      case Slot::Orientation: {
        // The planar rotation error is theta - target exactly, turns included, given the state's
        // angle with its turns (state() alone would put it in (-pi, pi]).
        Eigen::VectorXd y = eq.state(point);
        y[eq.turn_angle_index()] = theta;
        const Vec3 error = eq.orientation_error(y, slot.orientation(p), slot.track_turns, nullptr);
        out->constraints.push_back({angle, Vec2::Zero(), theta - error.z()});
        break;
      }
      case Slot::Force:
      case Slot::Moment: {
        const Vec3 load = projector * slot.value(p);
        if (slot.slot == Slot::Force) force += load.head<2>();
        else moment += load.z();
        for (const std::string& name : multipliers) {
          const Vec3 rate = projector * slot_rate(slot, p, name);
          if (rate.norm() == 0.0) continue;
          // The multiplier's conjugate displacement is held at the solution's value.
          if (slot.slot == Slot::Moment) {
            out->constraints.push_back({angle, Vec2::Zero(), theta});
          } else {
            const Vec2 e = rate.head<2>().normalized();
            out->constraints.push_back({position, e, e.dot(point.r.head<2>())});
          }
        }
        break;
      }
    }
  }
}

// The discretised rod at N elements: energy, constraints and their derivatives.
class DiscreteRod {
 public:
  DiscreteRod(const RodModel& model, const Reading& reading, const std::vector<RodPoint>& nodes)
      : N_(static_cast<int>(nodes.size()) - 1), h_(model.length / N_), reading_(reading) {
    bending_.resize(N_);
    natural_.resize(N_);
    for (int e = 0; e < N_; ++e) {
      const double s = (e + 0.5) * h_;
      bending_[e] = model.B[1](s);
      natural_[e] = model.u_hat[1](s);
    }
    // Dead loads and the field lumped on the nodes with the trapezoid weights.
    nodal_.assign(N_ + 1, Vec2::Zero());
    for (int i = 0; i <= N_ && model.field; ++i)
      nodal_[i] = h_ * weight(i) * model.field->force(nodes[i].s, nodes[i].r).head<2>();
    nodal_.front() += reading.start_force;
    nodal_.back() += reading.end_force;
    stiffness_scale_ = *std::max_element(bending_.begin(), bending_.end()) / (model.length * model.length);
    load_scale_ = (std::abs(reading.start_moment) + std::abs(reading.end_moment)) / model.length;
    for (const Vec2& f : nodal_) load_scale_ += f.norm();
  }

  int elements() const { return N_; }
  int unknowns() const { return N_ + 3; }  // r_0 (2), theta_0..theta_N
  int constraints() const { return static_cast<int>(reading_.constraints.size()); }
  double h() const { return h_; }
  double weight(int i) const { return (i == 0 || i == N_) ? 0.5 : 1.0; }
  double stiffness_scale() const { return stiffness_scale_; }
  static int angle(int j) { return 2 + j; }

  Vec2 end_position(const Eigen::VectorXd& z) const {
    Vec2 r = z.head<2>();
    for (int j = 0; j <= N_; ++j) r += h_ * weight(j) * tangent(z[angle(j)]);
    return r;
  }

  Eigen::VectorXd constraint_values(const Eigen::VectorXd& z) const {
    Eigen::VectorXd g(constraints());
    const Vec2 end = end_position(z);
    for (int k = 0; k < constraints(); ++k) {
      const Constraint& c = reading_.constraints[k];
      switch (c.kind) {
        case Held::StartPosition: g[k] = c.direction.dot(z.head<2>()) - c.value; break;
        case Held::EndPosition: g[k] = c.direction.dot(end) - c.value; break;
        case Held::StartAngle: g[k] = z[angle(0)] - c.value; break;
        case Held::EndAngle: g[k] = z[angle(N_)] - c.value; break;
      }
    }
    return g;
  }

  Eigen::MatrixXd constraint_jacobian(const Eigen::VectorXd& z) const {
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(constraints(), unknowns());
    for (int k = 0; k < constraints(); ++k) {
      const Constraint& c = reading_.constraints[k];
      switch (c.kind) {
        case Held::EndPosition:
          for (int j = 0; j <= N_; ++j) J(k, angle(j)) = h_ * weight(j) * c.direction.dot(normal(z[angle(j)]));
          [[fallthrough]];
        case Held::StartPosition: J.block<1, 2>(k, 0) = c.direction.transpose(); break;
        case Held::StartAngle: J(k, angle(0)) = 1.0; break;
        case Held::EndAngle: J(k, angle(N_)) = 1.0; break;
      }
    }
    return J;
  }

  // Gradient and Hessian of the Lagrangian energy + lambda.g. The loads (dead, field, and the
  // position constraints' multipliers acting as reactions -lambda e) enter through
  // G_j = sum_i P_i a_ij, a_ij = [j < i] + [1 <= j <= i], since dr_i/dtheta_j = h/2 a_ij t'(theta_j).
  void lagrangian(const Eigen::VectorXd& z, const Eigen::VectorXd& lambda, Eigen::VectorXd* gradient,
                  Eigen::MatrixXd* hessian) const {
    std::vector<Vec2> force = nodal_;
    gradient->setZero(unknowns());
    for (int k = 0; k < constraints(); ++k) {
      const Constraint& c = reading_.constraints[k];
      if (c.kind == Held::StartPosition) force.front() -= lambda[k] * c.direction;
      if (c.kind == Held::EndPosition) force.back() -= lambda[k] * c.direction;
      if (c.kind == Held::StartAngle) (*gradient)[angle(0)] += lambda[k];
      if (c.kind == Held::EndAngle) (*gradient)[angle(N_)] += lambda[k];
    }
    std::vector<Vec2> beyond(N_ + 2, Vec2::Zero());  // sum_{i >= j} P_i
    for (int j = N_; j >= 0; --j) beyond[j] = beyond[j + 1] + force[j];
    gradient->head<2>() -= beyond[0];
    (*gradient)[angle(0)] -= reading_.start_moment;
    (*gradient)[angle(N_)] -= reading_.end_moment;
    if (hessian) hessian->setZero(unknowns(), unknowns());
    for (int j = 0; j <= N_; ++j) {
      const double theta = z[angle(j)];
      const Vec2 G = beyond[j + 1] + (j >= 1 ? beyond[j] : Vec2::Zero());
      (*gradient)[angle(j)] -= 0.5 * h_ * normal(theta).dot(G);
      if (hessian) (*hessian)(angle(j), angle(j)) += 0.5 * h_ * tangent(theta).dot(G);
    }
    add_bending(z, gradient, hessian);
  }

  // The bending part of the Hessian alone (for the bending share of a mode's eigenvalue).
  Eigen::MatrixXd bending_hessian() const {
    Eigen::VectorXd unused = Eigen::VectorXd::Zero(unknowns()), gradient(unknowns());
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(unknowns(), unknowns());
    add_bending(unused, &gradient, &K);
    return K;
  }

  // Scale of the angle equations: a moment balance over a length h in units of the force scale.
  double residual_scale(const Eigen::VectorXd& lambda) const {
    double scale = stiffness_scale_ + load_scale_;
    for (int k = 0; k < constraints(); ++k) {
      const bool angular = reading_.constraints[k].kind == Held::StartAngle || reading_.constraints[k].kind == Held::EndAngle;
      scale += std::abs(lambda[k]) / (angular ? N_ * h_ : 1.0);
    }
    return scale;
  }

  // Dimensionless KKT residual: angle equations / (h F), position equations / F, positions / L,
  // angles in radians.
  double kkt_residual(const Eigen::VectorXd& z, const Eigen::VectorXd& lambda) const {
    Eigen::VectorXd gradient;
    lagrangian(z, lambda, &gradient, nullptr);
    const double F = residual_scale(lambda);
    double worst = gradient.head<2>().cwiseAbs().maxCoeff() / F;
    worst = std::max(worst, gradient.tail(N_ + 1).cwiseAbs().maxCoeff() / (h_ * F));
    const Eigen::VectorXd g = constraint_values(z);
    for (int k = 0; k < constraints(); ++k) {
      const bool angular = reading_.constraints[k].kind == Held::StartAngle || reading_.constraints[k].kind == Held::EndAngle;
      worst = std::max(worst, std::abs(g[k]) / (angular ? 1.0 : N_ * h_));
    }
    return worst;
  }

 private:
  static Vec2 tangent(double theta) { return Vec2(std::cos(theta), std::sin(theta)); }
  static Vec2 normal(double theta) { return Vec2(-std::sin(theta), std::cos(theta)); }

  void add_bending(const Eigen::VectorXd& z, Eigen::VectorXd* gradient, Eigen::MatrixXd* hessian) const {
    for (int e = 0; e < N_; ++e) {
      const double k = bending_[e] / h_;
      const double moment = k * (z[angle(e + 1)] - z[angle(e)] - h_ * natural_[e]);  // B (theta' - u_hat)
      (*gradient)[angle(e + 1)] += moment;
      (*gradient)[angle(e)] -= moment;
      if (!hessian) continue;
      (*hessian)(angle(e), angle(e)) += k;
      (*hessian)(angle(e + 1), angle(e + 1)) += k;
      (*hessian)(angle(e), angle(e + 1)) -= k;
      (*hessian)(angle(e + 1), angle(e)) -= k;
    }
  }

  int N_;
  double h_;
  const Reading& reading_;
  std::vector<double> bending_, natural_;  // at the element midpoints
  std::vector<Vec2> nodal_;                // dead loads and lumped field forces
  double stiffness_scale_ = 1.0, load_scale_ = 0.0;
};

// One discrete solve and its spectrum.
struct Spectrum {
  double kkt_residual = NAN;
  double angle_deviation = NAN;
  int iterations = 0;
  int translations = 0;
  std::vector<double> eigenvalues;  // all, increasing
  // int B dtheta'^2 / int dtheta^2 of each mode (when asked); the rest of its eigenvalue is the
  // loads' part.
  std::vector<double> bending;
};

// Starting values: the shooting solution at the nodes, multipliers by least squares.
void starting_point(const DiscreteRod& rod, const std::vector<RodPoint>& nodes, Eigen::VectorXd* z,
                    Eigen::VectorXd* lambda) {
  z->resize(rod.unknowns());
  z->head<2>() = nodes.front().r.head<2>();
  for (int j = 0; j <= rod.elements(); ++j) (*z)[DiscreteRod::angle(j)] = nodes[j].turn_angle;
  Eigen::VectorXd gradient;
  rod.lagrangian(*z, Eigen::VectorXd::Zero(rod.constraints()), &gradient, nullptr);
  const Eigen::MatrixXd Jt = rod.constraint_jacobian(*z).transpose();
  *lambda = Jt.cols() == 0 ? Eigen::VectorXd(0) : Eigen::VectorXd(Jt.completeOrthogonalDecomposition().solve(-gradient));
}

// Partial-pivoting LU, or where the KKT matrix is singular to round-off (a zero mode: a rod
// turning about the pin its ends share) the rank-revealing least-norm step, which does not move
// the rod along the symmetry.
Eigen::VectorXd kkt_step(const Eigen::MatrixXd& K, const Eigen::VectorXd& rhs) {
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(K);
  if (lu.rcond() > 1e-12) return lu.solve(rhs);
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> solver;
  solver.setThreshold(1e-13);
  return solver.compute(K).solve(rhs);
}

// Newton on the KKT system [H J^T; J 0] with the exact Hessian.
void refine(const DiscreteRod& rod, Eigen::VectorXd* z, Eigen::VectorXd* lambda, Spectrum* out) {
  const int n = rod.unknowns(), m = rod.constraints();
  // Quadratic convergence reaches round-off in 3-5 iterations from an O(h^2) start; there the
  // residual stops falling, and a step without a new best ends the loop.
  constexpr int kMaxIterations = 30, kPatience = 1;
  double residual = rod.kkt_residual(*z, *lambda);
  Eigen::VectorXd z_at = *z, lambda_at = *lambda;
  int since_best = 0;
  for (out->iterations = 0; out->iterations < kMaxIterations && since_best < kPatience && residual > 1e-15;
       ++out->iterations) {
    Eigen::VectorXd gradient;
    Eigen::MatrixXd H;
    rod.lagrangian(z_at, lambda_at, &gradient, &H);
    Eigen::MatrixXd K(n + m, n + m);
    const Eigen::MatrixXd J = rod.constraint_jacobian(z_at);
    K << H, J.transpose(), J, Eigen::MatrixXd::Zero(m, m);
    Eigen::VectorXd rhs(n + m);
    rhs << -gradient, -rod.constraint_values(z_at);
    const Eigen::VectorXd step = kkt_step(K, rhs);
    z_at += step.head(n);
    lambda_at += step.tail(m);
    const double next = rod.kkt_residual(z_at, lambda_at);
    ++since_best;
    if (next < residual) {
      *z = z_at;
      *lambda = lambda_at;
      residual = next;
      since_best = 0;
    }
  }
  out->kkt_residual = residual;
}

// The Hessian of the Lagrangian on the admissible perturbations, with the weight M = diag(h c_j)
// of int dtheta^2. The start position r_0 enters the energy linearly, so it drops out: of the
// constraints J_r dr_0 + J_theta dtheta = 0, those combinations free of r_0 (U^T J_r = 0) restrict
// dtheta, the rest fix dr_0, and directions of r_0 that no constraint sees are rigid translations.
// In y = M^1/2 dtheta the problem is the compression of A = M^-1/2 H M^-1/2 onto the complement of
// the constraint rows V; it is computed as the spectrum of P A P + sigma V V^T (P = I - V V^T)
// with sigma above every eigenvalue of A, so the c constrained directions sit at the top.
void spectrum(const DiscreteRod& rod, const Eigen::VectorXd& z, const Eigen::VectorXd& lambda, bool modes,
              Spectrum* out) {
  const int n = rod.elements() + 1;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd H;
  rod.lagrangian(z, lambda, &gradient, &H);
  const Eigen::MatrixXd J = rod.constraint_jacobian(z);
  Eigen::VectorXd root_mass(n);
  for (int j = 0; j < n; ++j) root_mass[j] = std::sqrt(rod.h() * rod.weight(j));
  Eigen::MatrixXd C(0, n);
  out->translations = 2;
  if (J.rows() > 0) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J.leftCols(2), Eigen::ComputeFullU);
    int rank = 0;  // J_r's entries are unit directions: singular values are 0 or O(1)
    for (int i = 0; i < svd.singularValues().size(); ++i) rank += svd.singularValues()[i] > 1e-10 ? 1 : 0;
    out->translations = 2 - rank;
    C = svd.matrixU().rightCols(J.rows() - rank).transpose() * J.rightCols(n);
  }
  const Eigen::MatrixXd scaled_rows = root_mass.cwiseInverse().asDiagonal() * C.transpose();  // n x c
  const Eigen::MatrixXd V = Eigen::HouseholderQR<Eigen::MatrixXd>(scaled_rows).householderQ() *
                            Eigen::MatrixXd::Identity(n, C.rows());
  const Eigen::VectorXd inverse_root = root_mass.cwiseInverse();
  const Eigen::MatrixXd A = inverse_root.asDiagonal() * H.bottomRightCorner(n, n) * inverse_root.asDiagonal();
  const double sigma = 2 * A.cwiseAbs().rowwise().sum().maxCoeff() + 1;  // twice Gershgorin's bound
  const Eigen::MatrixXd AV = A * V, VAV = V.transpose() * AV;
  const Eigen::MatrixXd projected =
      A - AV * V.transpose() - V * AV.transpose() + V * (VAV + sigma * Eigen::MatrixXd::Identity(V.cols(), V.cols())) * V.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(projected, modes ? Eigen::ComputeEigenvectors : Eigen::EigenvaluesOnly);
  const int k = n - static_cast<int>(V.cols());
  out->eigenvalues.assign(eig.eigenvalues().data(), eig.eigenvalues().data() + k);
  if (!modes) return;
  const Eigen::MatrixXd K = rod.bending_hessian().bottomRightCorner(n, n);
  const Eigen::MatrixXd modes_of_unit_weight = inverse_root.asDiagonal() * eig.eigenvectors().leftCols(k);
  const Eigen::VectorXd bending = (modes_of_unit_weight.transpose() * K * modes_of_unit_weight).diagonal();
  out->bending.assign(bending.data(), bending.data() + k);
}

// modes: also the eigenvectors' bending parts (the scale of the eigenvalues' discretisation error).
Spectrum solve_and_analyse(const RodModel& model, const Reading& reading, const std::vector<RodPoint>& nodes,
                           bool modes) {
  Spectrum out;
  const DiscreteRod rod(model, reading, nodes);
  Eigen::VectorXd z, lambda;
  starting_point(rod, nodes, &z, &lambda);
  const Eigen::VectorXd start = z;
  refine(rod, &z, &lambda, &out);
  out.angle_deviation = (z - start).tail(rod.elements() + 1).cwiseAbs().maxCoeff();
  spectrum(rod, z, lambda, modes, &out);
  return out;
}

// Constraint rows made unit and their smallest singular value: dependent rows mean no
// perturbation keeps them to first order (a straight rod whose chord is held along its axis).
bool independent_constraints(const DiscreteRod& rod, const std::vector<RodPoint>& nodes) {
  if (rod.constraints() == 0) return true;
  Eigen::VectorXd z, lambda;
  starting_point(rod, nodes, &z, &lambda);
  Eigen::MatrixXd J = rod.constraint_jacobian(z);
  for (int k = 0; k < J.rows(); ++k) J.row(k).normalize();
  if (J.rows() > J.cols()) return false;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J);
  // Unit rows that are independent are so by O(h) at least (end rows weigh h per node); 1e-8 is
  // round-off away from exact dependence and far below any genuine independence.
  return svd.singularValues().tail(1)[0] > 1e-8;
}

struct Counts {
  int index = 0, zero = 0;
};

Counts count(const Spectrum& s, double zero_tolerance) {
  Counts c;
  c.zero = s.translations;
  for (double mu : s.eigenvalues) {
    if (mu < -zero_tolerance) ++c.index;
    else if (mu <= zero_tolerance) ++c.zero;
  }
  return c;
}

// The self-checks of discrete_stability.hpp, in order; "" when all pass.
std::string self_check(const Spectrum& fine, const Spectrum& coarse, double zero_tolerance) {
  for (const Spectrum* s : {&fine, &coarse})
    if (!(s->kkt_residual <= kDiscreteStabilityKktTolerance))
      return "the discrete KKT residual is " + format(s->kkt_residual) + " (tolerance " +
             format(kDiscreteStabilityKktTolerance) + "): Newton did not converge";
  if (!(fine.angle_deviation <= kDiscreteStabilityAngleTolerance))
    return "the discrete equilibrium is " + format(fine.angle_deviation) +
           " rad from the shooting one: another equilibrium, or the discretisation does not resolve it";
  if (fine.angle_deviation > 1e-9 && !(fine.angle_deviation < coarse.angle_deviation))
    return "the discrete equilibrium does not approach the shooting one as the elements halve (" +
           format(coarse.angle_deviation) + " rad, then " + format(fine.angle_deviation) + ")";
  const Counts a = count(fine, zero_tolerance), b = count(coarse, zero_tolerance);
  if (a.index != b.index || a.zero != b.zero)
    return "N and N/2 elements disagree: index " + std::to_string(a.index) + " / " + std::to_string(b.index) +
           ", zero modes " + std::to_string(a.zero) + " / " + std::to_string(b.zero);
  // The reported eigenvalues, and every one up to the first above the index and zero modes.
  const size_t wanted = std::max(kDiscreteStabilityReported, a.index + a.zero - fine.translations + 1);
  const size_t compared = std::min({wanted, coarse.bending.size(), fine.eigenvalues.size(), coarse.eigenvalues.size()});
  for (size_t i = 0; i < compared; ++i) {
    const double mu = fine.eigenvalues[i], change = std::abs(mu - coarse.eigenvalues[i]);
    const double parts = std::abs(coarse.bending[i]) + std::abs(coarse.eigenvalues[i] - coarse.bending[i]);
    if (change > kDiscreteStabilityAgreement * parts + zero_tolerance)
      return "eigenvalue " + std::to_string(i + 1) + " is " + format(mu) + " at N elements and " +
             format(coarse.eigenvalues[i]) + " at N/2: not resolved";
    const bool zero = std::abs(mu) <= zero_tolerance && std::abs(coarse.eigenvalues[i]) <= zero_tolerance;
    if (!zero && (std::abs(mu) <= change || (mu > 0) != (coarse.eigenvalues[i] > 0)))
      return "eigenvalue " + std::to_string(i + 1) + " (" + format(mu) +
             ") is within its discretisation error of zero: its sign, and the index, are not decided";
  }
  return "";
}

}  // namespace

DiscreteStability discrete_stability(const ShootingProblem& problem, const Eigen::VectorXd& x, int elements) {
  DiscreteStability out;
  out.elements = elements;
  if (elements < 8 || elements % 2 != 0) {
    out.reason = "the number of elements must be even and at least 8, got " + std::to_string(elements);
    return out;
  }
  const Parameters p = problem.parameters_at(x);
  const std::shared_ptr<const RodEquations> eq = problem.equations(p);
  const RodModel& model = eq->model();
  out.reason = not_covered(problem, x, model);
  std::vector<std::string> multipliers;
  if (out.reason.empty()) out.reason = multiplier_loads(problem, p, &multipliers);
  if (!out.reason.empty()) return out;

  std::vector<double> s(elements + 1);
  for (int j = 0; j <= elements; ++j) s[j] = model.length * j / elements;
  const std::vector<RodPoint> nodes = problem.sample(x, s);
  for (const RodPoint& q : nodes)
    if (model.field && model.field->force_gradient(q.s, q.r).norm() > 0) {
      out.reason = "the external field depends on position: only uniform fields are modelled";
      return out;
    }
  Reading reading;
  const ProblemDefinition& d = problem.definition();
  read_end(*eq, d.start, true, nodes.front(), p, multipliers, &reading);
  read_end(*eq, d.end, false, nodes.back(), p, multipliers, &reading);
  if (!independent_constraints(DiscreteRod(model, reading, nodes), nodes)) {
    out.reason = "the held quantities are dependent to first order (a straight rod whose chord is held along "
                 "its axis): the projected Hessian does not define the index";
    return out;
  }
  std::vector<RodPoint> coarse_nodes;
  for (int j = 0; j <= elements; j += 2) coarse_nodes.push_back(nodes[j]);

  // The modes' bending parts only scale the tolerance of the comparison: the coarse solve's
  // eigenvectors give them at an eighth of the cost of the fine one's.
  const Spectrum fine = solve_and_analyse(model, reading, nodes, false);
  const Spectrum coarse = solve_and_analyse(model, reading, coarse_nodes, true);
  const double scale = DiscreteRod(model, reading, nodes).stiffness_scale();
  out.zero_tolerance = kDiscreteStabilityZeroTolerance * scale;
  const Counts counts = count(fine, out.zero_tolerance);
  out.index = counts.index;
  out.zero_modes = counts.zero;
  const int reported = std::min<int>(kDiscreteStabilityReported, static_cast<int>(fine.eigenvalues.size()));
  out.lowest_eigenvalues.assign(fine.eigenvalues.begin(), fine.eigenvalues.begin() + reported);
  out.coarse_eigenvalues.assign(coarse.eigenvalues.begin(),
                                coarse.eigenvalues.begin() + std::min<int>(reported, coarse.eigenvalues.size()));
  out.kkt_residual = std::max(fine.kkt_residual, coarse.kkt_residual);
  out.angle_deviation = fine.angle_deviation;
  out.coarse_angle_deviation = coarse.angle_deviation;
  out.newton_iterations = fine.iterations;
  out.check_message = self_check(fine, coarse, out.zero_tolerance);
  out.trustworthy = out.check_message.empty();
  if (out.trustworthy) out.check_message = "passed";
  return out;
}

std::string describe(const DiscreteStability& result) {
  if (!result.index) return "discrete index undefined: " + result.reason;
  std::ostringstream out;
  out << "discrete index " << *result.index;
  if (result.zero_modes > 0) out << ", " << result.zero_modes << " zero mode" << (result.zero_modes > 1 ? "s" : "");
  out << " (" << result.elements << " elements, "
      << (result.trustworthy ? "self-check passed" : "NOT trustworthy: " + result.check_message) << ")";
  return out.str();
}

}  // namespace kirchhoff

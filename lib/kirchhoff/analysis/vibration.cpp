// Linear vibrations about a planar equilibrium (see vibration.hpp for the equations and the
// choices made there).
#include "kirchhoff/analysis/vibration.hpp"

#include <algorithm>
#include <array>
#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/equations/detail/integrator_impl.hpp"
#include "kirchhoff/equations/detail/planar_state.hpp"

namespace kirchhoff {
namespace {

// The state layout (planar_state.hpp).
using detail::kPlanarStateSize, detail::kX, detail::kY, detail::kTheta, detail::kNx, detail::kNy, detail::kMoment;
constexpr int kState = kPlanarStateSize;
// At most three perturbations start from each end (six unknowns, three conditions per end).
constexpr int kColumns = 3;

// theta_e varying by less than this along the rod counts as straight: the solver returns straight
// columns exactly (theta_e = 0 to round-off), while any buckled equilibrium worth the name has
// theta_e of 1e-6 or more.
constexpr double kStraightTolerance = 1e-9;
// Boundary rows and directions below this are zero: they are built from exact unit vectors.
constexpr double kRowTolerance = 1e-9;
// At a genuine eigenfrequency the scaled matching matrix is singular to the integration error
// (~1e-10 relative); a sign change with sigma_min / sigma_max above this is not a frequency.
constexpr double kMatchingResidualLimit = 1e-6;
// TOMS 748 stops when the bracket is this narrow relative to omega; the determinant is only
// accurate to the integration tolerance, so narrower brackets would chase noise.
constexpr double kRootRelativeTolerance = 1e-13;
constexpr std::uintmax_t kRootMaxIterations = 100;
// Points sampled to decide whether the equilibrium is straight.
constexpr int kStraightnessSamples = 65;
// Points sampled for the bound on the growth rates: the largest compression, curvature and field
// gradient vary on the rod's own scale, which 257 points resolve to a fraction of a percent, and
// the search goes twice beyond the bound.
constexpr int kBoundSamples = 257;

std::string format(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

// The linearised equations (B.4), integrated together with the equilibrium (B.3) so that theta_e,
// n_e are exact at every stage of the integrator. The equilibrium's right-hand side is the planar
// core's; K perturbation columns follow it.
template <int K>
struct LinearisedFlow {
  using State = std::array<double, kState * (K + 1)>;
  const RodEquations* equations;
  double inertia;  // rhoS omega^2 (negative for the unstable modes)

  void operator()(const State& y, State& dy, double s) const {
    const Eigen::Map<const Eigen::Matrix<double, kState, 1>> y_e(y.data());
    const Eigen::VectorXd dy_e = equations->derivative(y_e, s);
    for (int i = 0; i < kState; ++i) dy[i] = dy_e[i];
    const RodModel& model = equations->model();
    const double c = std::cos(y_e[kTheta]), sn = std::sin(y_e[kTheta]);
    const double axial_force = y_e[kNx] * c + y_e[kNy] * sn;  // n_xe cos + n_ye sin = n_e . d3
    const double inverse_EI = 1.0 / model.B[1](s);
    // nbar' = -(rhoS omega^2 I + df/dr) rbar: inertia (B.4b) plus the linearised field force.
    Eigen::Matrix2d stiffness = inertia * Eigen::Matrix2d::Identity();
    if (model.field) stiffness += model.field->force_gradient(s, Vec3(y_e[kX], y_e[kY], 0.0)).topLeftCorner<2, 2>();
    for (int j = 0; j < K; ++j) {
      const double* q = y.data() + kState * (j + 1);
      double* dq = dy.data() + kState * (j + 1);
      dq[kX] = -q[kTheta] * sn;
      dq[kY] = q[kTheta] * c;
      dq[kTheta] = q[kMoment] * inverse_EI;
      dq[kNx] = -(stiffness(0, 0) * q[kX] + stiffness(0, 1) * q[kY]);
      dq[kNy] = -(stiffness(1, 0) * q[kX] + stiffness(1, 1) * q[kY]);
      dq[kMoment] = q[kNx] * sn - q[kNy] * c + q[kTheta] * axial_force;
    }
  }
};

// Orthonormal basis of the column space of A (rank decided at kRowTolerance).
Eigen::MatrixXd orthonormal_columns(const Eigen::MatrixXd& A) {
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  qr.setThreshold(kRowTolerance);
  const int rank = static_cast<int>(qr.rank());
  return qr.householderQ() * Eigen::MatrixXd::Identity(A.rows(), rank);
}

// One end's conditions linearised: the Jacobian rows of its complete (non-extra) set, i.e. the
// same conditions with every imposed value held (dead loads, fixed supports).
Eigen::MatrixXd held_condition_rows(const RodEquations& eq, const EndCondition& given, bool at_start,
                                    const Eigen::VectorXd& y, const Parameters& p) {
  const char* where = at_start ? "s = 0" : "s = L";
  EndCondition held;
  int extra_slots = 0;
  for (const auto& c : given.conditions()) {
    if (c.extra)
      ++extra_slots;
    else
      held.add(c);
  }
  if (given.extra_count() > extra_slots)
    throw std::invalid_argument(std::string("vibrations: the end at ") + where +
                                " is closed by the continuity of H (a sleeve): its position along the rod is not a "
                                "fixed end condition, not supported");
  std::vector<double> residual;
  std::vector<StateRow> rows;
  held.append_residuals(eq, at_start, y, p, &residual, &rows);
  Eigen::MatrixXd B(rows.size(), kState);
  for (size_t i = 0; i < rows.size(); ++i) B.row(static_cast<Eigen::Index>(i)) = rows[i];
  if (B.rows() != 3 || orthonormal_columns(B.transpose()).cols() != 3)
    throw std::invalid_argument(std::string("vibrations: the conditions at ") + where +
                                " are not three independent conditions (" + std::to_string(B.rows()) + " rows)");
  return B;
}

// The terms of eq. (95b), in order: 1/2 EI thetabar'^2, -thetabar (nbar x d3).e_z,
// 1/2 rhoS omega^2 |rbar|^2, -1/2 thetabar^2 n_e.d3 (omega2 = omega^2, negative for unstable modes).
std::array<double, 4> eq95b_terms(double EI, double rho_s, double omega2, double theta_e, double n_xe, double n_ye,
                                  const VibrationState& q) {
  const double c = std::cos(theta_e), sn = std::sin(theta_e);
  const double theta_prime = q[kMoment] / EI;
  return {0.5 * EI * theta_prime * theta_prime, -q[kTheta] * (q[kNx] * sn - q[kNy] * c),
          0.5 * rho_s * omega2 * (q[kX] * q[kX] + q[kY] * q[kY]),
          -0.5 * q[kTheta] * q[kTheta] * (n_xe * c + n_ye * sn)};
}


// Marches a combined (equilibrium, perturbations) state from `from` to `to`. With multiple
// shooting the equilibrium's node states are the solution and one integration across many
// segments would drift from it, so the equilibrium part restarts from them at every node passed.
template <class State, class Flow>
void march_through_nodes(State& state, double from, double to, const Flow& flow, const std::vector<double>& node_s,
                         const std::vector<Eigen::VectorXd>& node_y, const IntegratorOptions& options) {
  double at = from;
  auto between = [&](double s) { return to > from ? (s > at && s <= to) : (s < at && s >= to); };
  const int last = static_cast<int>(node_s.size()) - 1;
  for (int k = 0; k <= last; ++k) {
    const int i = to > from ? k : last - k;  // nodes in the marching direction
    if (!between(node_s[i])) continue;
    detail::march(state, at, node_s[i], flow, options);
    for (int j = 0; j < kState; ++j) state[j] = node_y[i][j];
    at = node_s[i];
  }
  detail::march(state, at, to, flow, options);
}

// Eq. (97) with omega^2 signed.
double eq97_terms(double EI, double rho_s, double omega2, double P, const ColumnDeflection& d, bool as_printed) {
  const double P_term = as_printed ? d.w * d.w : d.w1 * d.w1;
  return 0.5 * EI * d.w2 * d.w2 + 0.5 * rho_s * omega2 * d.w * d.w - 0.5 * P * P_term - EI * d.w1 * d.w3;
}

}  // namespace

std::string vibration_refusal(const ProblemDefinition& definition, const VibrationOptions& options) {
  if (definition.kind != RodKind::Planar)
    return "vibrate handles planar rods only (the vibration equations B.4 are planar); this case is spatial";
  return options.validate();
}

std::string VibrationOptions::validate() const {
  if (modes < 1) return "modes must be >= 1, got " + std::to_string(modes);
  if (!(rho_s > 0.0) || !std::isfinite(rho_s)) return "rho_s (mass per unit length) must be > 0, got " + format(rho_s);
  if (!(grid_step > 0.0) || !std::isfinite(grid_step)) return "grid_step must be > 0, got " + format(grid_step);
  if (!(omega_min > 0.0) || !std::isfinite(omega_min))
    return "omega_min must be > 0 (omega = 0 is a root for every free rigid motion), got " + format(omega_min);
  if (!(omega_max == 0.0 || omega_max > omega_min)) return "omega_max must be 0 (no limit) or > omega_min";
  if (!(sigma_max == 0.0 || sigma_max > omega_min)) return "sigma_max must be 0 (the bound) or > omega_min";
  if (max_grid_points < 2) return "max_grid_points must be >= 2";
  if (profile_samples < 3) return "profile_samples must be >= 3, got " + std::to_string(profile_samples);
  return integrator.validate();
}

double VibrationMode::growth_rate() const { return omega2 < 0.0 ? std::sqrt(-omega2) : 0.0; }

std::vector<double> VibrationAnalysis::omega2() const {
  std::vector<double> out;
  for (const auto* list : {&unstable_modes, &modes})
    for (const auto& m : *list) out.push_back(m.omega2);
  return out;
}

std::vector<double> VibrationAnalysis::frequencies() const {
  std::vector<double> out;
  for (const auto& m : modes) out.push_back(m.omega);
  return out;
}

struct VibrationProblem::Matching {
  Eigen::MatrixXd M;             // dimensionless, columns normalised
  Eigen::VectorXd column_norms;  // of the dimensionless matrix before normalising
};

VibrationProblem::VibrationProblem(const ShootingProblem& problem, const Eigen::VectorXd& x, VibrationOptions options)
    : options_(std::move(options)) {
  const ProblemDefinition& definition = problem.definition();
  if (definition.kind != RodKind::Planar)
    throw std::invalid_argument("vibrations: only planar rods are supported (eqs. B.4); this rod is spatial");
  if (const std::string why = options_.validate(); !why.empty())
    throw std::invalid_argument("vibrations: " + why);
  if (!definition.contacts.empty())
    throw std::invalid_argument("vibrations: equilibria with active contacts are not supported (n jumps at a contact)");
  if (x.size() != problem.size())
    throw std::invalid_argument("vibrations: the equilibrium has " + std::to_string(x.size()) +
                                " unknowns, the problem " + std::to_string(problem.size()));

  const Parameters p = problem.parameters_at(x);
  equations_ = problem.equations(p);
  const RodModel& model = equations_->model();
  if (model.extensible)
    throw std::invalid_argument("vibrations: only inextensible, unshearable rods are supported (eqs. B.4)");
  if (!model.v_hat[0].is_constant() || model.v_hat[0](0.0) != 0.0 || !model.v_hat[2].is_constant() ||
      model.v_hat[2](0.0) != 1.0)
    throw std::invalid_argument("vibrations: the rod must have v = (0, 0, 1) (no natural shear or stretch)");
  length_ = model.length;
  if (const auto jumps = model.jumps(); !jumps.empty())  // (its own marches are not the equations')
    options_.integrator.jumps = std::make_shared<const std::vector<ProfileJump>>(jumps);
  omega_scale_ = std::sqrt(model.B[1](0.0) / (options_.rho_s * std::pow(length_, 4)));

  try {
    // Shooting nodes s_i = L i / M and the equilibrium there (x holds y(s_0..s_{M-1})).
    const int segments = problem.segments();
    for (int i = 0; i < segments; ++i) {
      node_s_.push_back(length_ * i / segments);
      node_y_.push_back(x.segment(i * kState, kState));
    }
    node_s_.push_back(length_);
    node_y_.push_back(
        equations_->flow(node_y_.back(), node_s_[segments - 1], length_, false, options_.integrator).y);
    y_start_ = node_y_.front();
    y_end_ = node_y_.back();
    std::vector<double> s(kStraightnessSamples);
    for (int i = 0; i < kStraightnessSamples; ++i) s[i] = length_ * i / (kStraightnessSamples - 1);
    double theta_range = 0.0;
    for (const RodPoint& point : problem.sample(x, s))
      theta_range = std::max(theta_range, std::abs(point.turn_angle - y_start_[kTheta]));
    straight_ = theta_range <= kStraightTolerance;
    std::vector<double> fine(kBoundSamples);
    for (int i = 0; i < kBoundSamples; ++i) fine[i] = length_ * i / (kBoundSamples - 1);
    bound_growth_rate(problem.sample(x, fine), definition);
  } catch (const IntegrationError& e) {
    throw std::invalid_argument(std::string("vibrations: the equilibrium cannot be integrated: ") + e.what());
  }

  const Eigen::MatrixXd start_rows = held_condition_rows(*equations_, definition.start, true, y_start_, p);
  const Eigen::MatrixXd end_rows = held_condition_rows(*equations_, definition.end, false, y_end_, p);
  matching_spaces(start_rows, end_rows);

  // Dimensionless components: lengths by L, forces by EI/L^2, moments by EI/L.
  const double EI = model.B[1](0.0);
  row_scale_.resize(kState);
  row_scale_ << 1.0 / length_, 1.0 / length_, 1.0, length_ * length_ / EI, length_ * length_ / EI, length_ / EI;
}

// The spaces the matching matrix is built on: the perturbations each end's linearised
// conditions admit, and the rows matched at the far end. The degenerate straight case, a pure
// axial force perturbation z free at both ends, is solved as the transverse problem.
void VibrationProblem::matching_spaces(const Eigen::MatrixXd& start_rows, const Eigen::MatrixXd& end_rows) {
  auto null_space = [](const Eigen::MatrixXd& B) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(B, Eigen::ComputeFullV);
    return Eigen::MatrixXd(svd.matrixV().rightCols(kState - B.rows()));
  };
  start_basis_ = null_space(start_rows);
  end_basis_ = null_space(end_rows);

  // The degenerate straight case: a pure axial force perturbation z free at both ends.
  const double theta0 = y_start_[kTheta];
  const Eigen::Vector2d t(std::cos(theta0), std::sin(theta0)), normal(-t.y(), t.x());
  VibrationState z = VibrationState::Zero();
  z[kNx] = t.x();
  z[kNy] = t.y();
  axial_indeterminate_ = straight_ && (start_rows * z).norm() < kRowTolerance &&
                         (end_rows * z).norm() < kRowTolerance;
  if (axial_indeterminate_) {
    // Solve the transverse problem: drop z from the starting spaces and the axial pair
    // (rbar.t, nbar.t), identically zero on the modes, from the matching rows.
    const Eigen::MatrixXd drop_z = Eigen::MatrixXd::Identity(kState, kState) - z * z.transpose();
    start_basis_ = orthonormal_columns(drop_z * start_basis_);
    end_basis_ = orthonormal_columns(drop_z * end_basis_);
    row_projection_ = Eigen::MatrixXd::Zero(4, kState);
    row_projection_(0, kX) = normal.x();
    row_projection_(0, kY) = normal.y();
    row_projection_(1, kTheta) = 1.0;
    row_projection_(2, kNx) = normal.x();
    row_projection_(2, kNy) = normal.y();
    row_projection_(3, kMoment) = 1.0;
  } else {
    row_projection_ = Eigen::MatrixXd::Identity(kState, kState);
  }
  if (start_basis_.cols() + end_basis_.cols() != row_projection_.rows())
    throw std::logic_error("vibrations: matching matrix is not square");
}

void VibrationProblem::bound_growth_rate(const std::vector<RodPoint>& points, const ProblemDefinition& definition) {
  const RodModel& model = equations_->model();
  double compression = 0.0, curvature = 0.0, stiffness = INFINITY, gradient = 0.0;
  for (const RodPoint& q : points) {
    compression = std::max(compression, -q.n.dot(q.R.col(2)));
    curvature = std::max(curvature, std::abs(q.u.y()));
    stiffness = std::min(stiffness, model.B[1](q.s));
    if (model.field) gradient = std::max(gradient, model.field->force_gradient(q.s, q.r).topLeftCorner<2, 2>().norm());
  }
  // A free end (position not held along some direction) admits the rigid turn's boundary term.
  bool free_end = false;
  for (const EndCondition* end : {&definition.start, &definition.end}) {
    int held = 0;
    for (const auto& c : end->conditions())
      if (c.slot == Slot::Position && !c.extra) held += static_cast<int>(c.basis(*equations_).cols());
    free_end = free_end || held < 2;
  }
  const double turn = free_end ? 12.0 * compression / (length_ * length_) : 0.0;
  sigma_bound_ = std::sqrt((compression * compression / stiffness + compression * curvature * curvature + turn +
                            gradient) / options_.rho_s);
  sigma_max_ = options_.sigma_max > 0.0 ? options_.sigma_max * omega_scale_ : 2.0 * sigma_bound_;
}

VibrationProblem::Matching VibrationProblem::matching(double omega2) const {
  using Flow = LinearisedFlow<kColumns>;
  const Flow flow{equations_.get(), options_.rho_s * omega2};
  auto shoot = [&](const Eigen::VectorXd& y_e, const Eigen::MatrixXd& basis, double from) {
    Flow::State state{};
    for (int i = 0; i < kState; ++i) state[i] = y_e[i];
    for (int j = 0; j < basis.cols(); ++j)
      for (int i = 0; i < kState; ++i) state[kState * (j + 1) + i] = basis(i, j);
    march_through_nodes(state, from, 0.5 * length_, flow, node_s_, node_y_, options_.integrator);
    Eigen::MatrixXd Y(kState, basis.cols());
    for (int j = 0; j < basis.cols(); ++j)
      for (int i = 0; i < kState; ++i) Y(i, j) = state[kState * (j + 1) + i];
    return Y;
  };
  Eigen::MatrixXd raw(kState, start_basis_.cols() + end_basis_.cols());
  raw << shoot(y_start_, start_basis_, 0.0), shoot(y_end_, end_basis_, length_);
  Matching m;
  m.M = row_projection_ * row_scale_.asDiagonal() * raw;
  m.column_norms = m.M.colwise().norm().transpose();
  for (int j = 0; j < m.M.cols(); ++j) m.M.col(j) /= m.column_norms[j];
  return m;
}

double VibrationProblem::scaled_determinant(double omega) const {
  if (!(omega >= 0.0) || !std::isfinite(omega))
    throw std::invalid_argument("vibrations: omega must be finite and >= 0, got " + format(omega));
  return scaled_determinant_at(omega * omega);
}

double VibrationProblem::scaled_determinant_at(double omega2) const {
  if (!std::isfinite(omega2)) throw std::invalid_argument("vibrations: omega^2 must be finite, got " + format(omega2));
  try {
    return matching(omega2).M.determinant();
  } catch (const IntegrationError& e) {
    throw std::invalid_argument("vibrations: integration failed at omega^2 = " + format(omega2) + ": " + e.what());
  }
}

template <class Omega2>
double VibrationProblem::bracketed_root(double a, double fa, double b, double fb, const Omega2& omega2_of,
                                        const char* name) const {
  auto det = [&](double v) { return scaled_determinant_at(omega2_of(v)); };
  double root = b;
  if (fb != 0.0) {
    std::uintmax_t iterations = kRootMaxIterations;
    auto close_enough = [](double lo, double hi) { return std::abs(hi - lo) <= kRootRelativeTolerance * std::abs(hi); };
    const auto [lo, hi] = boost::math::tools::toms748_solve(det, a, b, fa, fb, close_enough, iterations);
    // Each TOMS 748 iteration shrinks the bracket, so running out of iterations with a wide one
    // means the determinant is not behaving like a continuous function there.
    if (!close_enough(lo, hi))
      throw std::invalid_argument(std::string("vibrations: the root bracketed in ") + name + " in [" + format(a) +
                                  ", " + format(b) + "] did not converge");
    root = 0.5 * (lo + hi);
  }
  // A sign change must be a singular matching matrix, not a numerical jump.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(matching(omega2_of(root)).M);
  const double residual = svd.singularValues().tail(1)[0] / svd.singularValues()[0];
  if (residual > kMatchingResidualLimit)
    throw std::invalid_argument(std::string("vibrations: the determinant changes sign near ") + name + " = " +
                                format(root) + " but the boundary conditions are not met there (sigma_min/sigma_max = " +
                                format(residual) + ")");
  return root;
}

// A double root's matching matrix is this much nearer singular at the dip's minimum than at its
// ends (a genuine one: ~1e-10 against ~1e-2, the integration error against the modes' spacing).
constexpr double kDipContrast = 1e3;

// Brent's minimum of the dip to 2^-26 (1.5e-8) relative, the precision a minimum's location has
// in double precision (the function is flat to second order there).
constexpr int kDipMinimumBits = 26;

template <class Omega2>
void VibrationProblem::dip_roots(double a, double fa, double fm, double b, double fb, const Omega2& omega2_of,
                                 const char* name, std::vector<double>* found) const {
  const double sign = fm > 0.0 ? 1.0 : -1.0;
  auto signed_det = [&](double v) { return sign * scaled_determinant_at(omega2_of(v)); };
  std::uintmax_t iterations = kRootMaxIterations;
  const auto [v_min, g_min] = boost::math::tools::brent_find_minima(signed_det, a, b, kDipMinimumBits, iterations);
  if (g_min < 0.0) {  // two simple roots, one on either side of the minimum
    found->push_back(bracketed_root(a, fa, v_min, sign * g_min, omega2_of, name));
    found->push_back(bracketed_root(v_min, sign * g_min, b, fb, omega2_of, name));
    return;
  }
  // No sign change: a multiple root where the matching matrix loses rank at the minimum - and
  // only there. Where the perturbations grow by e^(sigma L / 2) towards the middle (a stiff
  // barrier's field gradient, growth rates of 1e3), the columns shot from one end all turn into
  // the fastest-growing direction and the matrix is as near singular at the dip's ends as at its
  // minimum: a probe's soft wall at log_b = -3 showed four such "double roots", omega^2 = -2.1e6
  // .. -7e5, where the discretised energy has none. A rank lost at the minimum alone is a root.
  const auto smallest_ratio = [&](double v) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(matching(omega2_of(v)).M);
    return svd.singularValues().tail(1)[0] / svd.singularValues()[0];
  };
  const double at_ends = std::min(smallest_ratio(a), smallest_ratio(b));
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(matching(omega2_of(v_min)).M);
  const Eigen::VectorXd& sv = svd.singularValues();
  int nullity = 0;
  for (Eigen::Index j = 0; j < sv.size(); ++j) nullity += sv[j] <= kMatchingResidualLimit * sv[0];
  const bool lost_at_minimum_only = sv.tail(1)[0] / sv[0] * kDipContrast < at_ends;
  if (nullity >= 2 && lost_at_minimum_only)
    for (int k = 0; k < nullity; ++k) found->push_back(v_min);
}

template <class Omega2, class At, class GoOn>
std::vector<double> VibrationProblem::grid_roots(const At& at, const GoOn& go_on, const Omega2& omega2_of,
                                                 const char* name) const {
  std::vector<double> found;
  auto det = [&](double v) { return scaled_determinant_at(omega2_of(v)); };
  struct Sample {
    double v, f;
  };
  Sample before{NAN, NAN}, previous{at(0), det(at(0))};
  for (int i = 1; go_on(i, found); ++i) {
    const Sample current{at(i), det(at(i))};
    const bool changed = current.f == 0.0 || (current.f > 0.0) != (previous.f > 0.0);
    if (changed) {
      found.push_back(bracketed_root(previous.v, previous.f, current.v, current.f, omega2_of, name));
    } else if (std::isfinite(before.f) && (before.f > 0.0) == (previous.f > 0.0) &&
               std::abs(previous.f) <= std::min(std::abs(before.f), std::abs(current.f))) {
      // Between simple roots |det| swings up and back down to zero through a maximum: a minimum
      // of it among three samples of one sign is a dip, where two roots may hide.
      dip_roots(before.v, before.f, previous.f, current.v, current.f, omega2_of, name, &found);
    }
    before = previous;
    previous = current;
  }
  return found;
}

std::vector<double> VibrationProblem::frequencies() const {
  auto omega_at = [&](int i) { return omega_scale_ * (options_.omega_min + i * options_.grid_step); };
  auto go_on = [&](int i, const std::vector<double>& found) {
    if (static_cast<int>(found.size()) >= options_.modes) return false;
    if (i >= options_.max_grid_points || (options_.omega_max > 0.0 && omega_at(i) > options_.omega_max * omega_scale_))
      throw std::invalid_argument("vibrations: found " + std::to_string(found.size()) + " of the " +
                                  std::to_string(options_.modes) + " frequencies requested below omega = " +
                                  format(omega_at(i - 1)) + " (end of the search grid: raise omega_max or max_grid_points)");
    return true;
  };
  std::vector<double> found = grid_roots(omega_at, go_on, [](double w) { return w * w; }, "omega");
  std::sort(found.begin(), found.end());
  if (static_cast<int>(found.size()) > options_.modes) found.resize(options_.modes);  // (a dip's pair at the end)
  return found;
}

std::vector<double> VibrationProblem::negative_omega2() const {
  auto omega2_of = [](double sigma) { return -sigma * sigma; };
  auto sigma_at = [&](int i) { return omega_scale_ * (options_.omega_min + i * options_.grid_step); };
  if (!(sigma_max_ > sigma_at(0))) return {};  // no compression, no field gradient: none exist
  auto go_on = [&](int i, const std::vector<double>&) {
    if (sigma_at(i) > sigma_max_) return false;
    if (i >= options_.max_grid_points)
      throw std::invalid_argument("vibrations: the search for omega^2 < 0 needs more than max_grid_points = " +
                                  std::to_string(options_.max_grid_points) + " points to reach sigma = " +
                                  format(sigma_max_));
    return true;
  };
  std::vector<double> found;
  for (double sigma : grid_roots(sigma_at, go_on, omega2_of, "sigma")) found.push_back(omega2_of(sigma));
  std::sort(found.begin(), found.end());
  return found;
}

std::vector<Eigen::Matrix<double, 12, 1>> VibrationProblem::integrate_samples(const Eigen::VectorXd& y_e,
                                                                              const VibrationState& qbar,
                                                                              const std::vector<double>& s,
                                                                              double omega2) const {
  using Flow = LinearisedFlow<1>;
  const Flow flow{equations_.get(), options_.rho_s * omega2};
  Flow::State state{};
  for (int i = 0; i < kState; ++i) {
    state[i] = y_e[i];
    state[kState + i] = qbar[i];
  }
  std::vector<Eigen::Matrix<double, 12, 1>> out;
  double at = s.front();
  for (double next : s) {
    // Stepping onto each sample keeps the RK78 accuracy (no interpolation).
    march_through_nodes(state, at, next, flow, node_s_, node_y_, options_.integrator);
    at = next;
    out.push_back(Eigen::Map<const Eigen::Matrix<double, 12, 1>>(state.data()));
  }
  return out;
}

VibrationMode VibrationProblem::mode(double omega) const { return mode_at(omega * omega); }

VibrationMode VibrationProblem::mode_at(double omega2) const {
  const Matching m = matching(omega2);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(m.M, Eigen::ComputeFullV);
  VibrationMode out;
  out.omega2 = omega2;
  out.omega = std::sqrt(std::max(omega2, 0.0));
  const std::string where = "omega^2 = " + format(omega2);
  out.matching_residual = svd.singularValues().tail(1)[0] / svd.singularValues()[0];
  // M c = 0 with M = raw diag(1/norms): raw (c / norms) = 0, i.e. Y0 c0 = -YL cL at mid-span.
  const Eigen::VectorXd c = svd.matrixV().col(m.M.cols() - 1).cwiseQuotient(m.column_norms);
  const Eigen::Index k0 = start_basis_.cols();
  const VibrationState from_start = start_basis_ * c.head(k0);
  const VibrationState from_end = -end_basis_ * c.tail(c.size() - k0);

  // Each half from its own end, so neither integrates across the whole rod.
  const int n = options_.profile_samples;
  std::vector<double> left, right;
  for (int i = 0; i < n; ++i) {
    const double s = length_ * i / (n - 1);
    (s <= 0.5 * length_ ? left : right).push_back(s);
  }
  std::reverse(right.begin(), right.end());
  std::vector<Eigen::Matrix<double, 12, 1>> samples;
  try {
    samples = integrate_samples(y_start_, from_start, left, omega2);
    if (!right.empty()) {
      auto tail = integrate_samples(y_end_, from_end, right, omega2);
      samples.insert(samples.end(), tail.rbegin(), tail.rend());
    }
  } catch (const IntegrationError& e) {
    throw std::invalid_argument("vibrations: integration of the mode at " + where + " failed: " + e.what());
  }
  std::reverse(right.begin(), right.end());
  out.s = left;
  out.s.insert(out.s.end(), right.begin(), right.end());

  // Normalise: largest displacement 1 (the rotation when the mode does not displace the centreline).
  double largest = 0.0;
  for (const auto& y : samples)
    for (int i : {kState + kX, kState + kY})
      if (std::abs(y[i]) > std::abs(largest)) largest = y[i];
  if (std::abs(largest) <= kRowTolerance * length_) {
    largest = 0.0;
    for (const auto& y : samples)
      if (std::abs(y[kState + kTheta]) > std::abs(largest)) largest = y[kState + kTheta];
  }
  if (largest == 0.0) throw std::invalid_argument("vibrations: the mode at " + where + " is zero");
  const double normalisation = 1.0 / largest;

  const RodModel& model = equations_->model();
  const double rho_s = options_.rho_s;
  double h_min = INFINITY, h_max = -INFINITY, h_sum = 0.0, scale = 0.0;
  const double theta0 = y_start_[kTheta];
  const Eigen::Vector2d t(std::cos(theta0), std::sin(theta0)), normal(-t.y(), t.x());
  const double P = -(y_start_[kNx] * t.x() + y_start_[kNy] * t.y());  // compression of a straight column
  for (size_t k = 0; k < samples.size(); ++k) {
    const double s = out.s[k];
    const Eigen::Matrix<double, kState, 1> y_e = samples[k].head<kState>();
    const VibrationState q = samples[k].tail<kState>() * normalisation;
    out.state.push_back(q);
    const double EI = model.B[1](s);
    const auto terms = eq95b_terms(EI, rho_s, omega2, y_e[kTheta], y_e[kNx], y_e[kNy], q);
    const double H = terms[0] + terms[1] + terms[2] + terms[3];
    out.H_vib.push_back(H);
    h_min = std::min(h_min, H);
    h_max = std::max(h_max, H);
    h_sum += H;
    for (double term : terms) scale = std::max(scale, std::abs(term));
    if (straight_) {
      // w = rbar.normal and its derivatives through (B.4); m' = -nbar.normal - P thetabar here.
      const double mbar_prime = -(q[kNx] * normal.x() + q[kNy] * normal.y()) - P * q[kTheta];
      const ColumnDeflection d{q[kX] * normal.x() + q[kY] * normal.y(), q[kTheta], q[kMoment] / EI, mbar_prime / EI};
      out.H_vib_column.push_back(eq97_terms(EI, rho_s, omega2, P, d, false));
    }
  }
  out.H_vib_stats.min = h_min;
  out.H_vib_stats.max = h_max;
  out.H_vib_stats.mean = h_sum / static_cast<double>(samples.size());
  out.H_vib_stats.spread = h_max - h_min;
  out.H_vib_stats.scale = scale;
  out.H_vib_stats.applies = H_vib_not_conserved().empty();
  return out;
}

std::string VibrationProblem::H_vib_not_conserved() const {
  if (!straight_) return "the equilibrium is curved (theta_e varies)";
  if (!model().is_uniform()) return "the rod's properties vary along it";
  if (model().field) return "an external field acts (the axial force varies)";
  return "";
}

VibrationAnalysis VibrationProblem::analyse() const {
  VibrationAnalysis out;
  out.straight_equilibrium = straight_;
  out.axial_indeterminate = axial_indeterminate_;
  out.omega_scale = omega_scale_;
  out.H_vib_not_conserved = H_vib_not_conserved();
  for (double omega : frequencies()) out.modes.push_back(mode(omega));
  out.sigma_max = sigma_max_;
  out.unstable_searched = options_.unstable_modes;
  if (options_.unstable_modes)
    for (double omega2 : negative_omega2()) out.unstable_modes.push_back(mode_at(omega2));
  return out;
}

double eq97_hamiltonian(double EI, double rho_s, double omega, double P, const ColumnDeflection& d, bool as_printed) {
  return eq97_terms(EI, rho_s, omega * omega, P, d, as_printed);
}

double eq95b_hamiltonian(double EI, double rho_s, double omega, double theta_e, double n_xe, double n_ye,
                         const VibrationState& qbar) {
  const auto terms = eq95b_terms(EI, rho_s, omega * omega, theta_e, n_xe, n_ye, qbar);
  return terms[0] + terms[1] + terms[2] + terms[3];
}

}  // namespace kirchhoff

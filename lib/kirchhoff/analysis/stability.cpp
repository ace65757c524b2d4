// The index of an equilibrium by conjugate points (see stability.hpp for the method).
#include "kirchhoff/analysis/stability.hpp"

#include "kirchhoff/analysis/detail/eigenphases.hpp"
#include "kirchhoff/analysis/detail/moment_bound.hpp"
#include "kirchhoff/analysis/detail/stability_extended_contact.hpp"
#include "kirchhoff/analysis/detail/stability_free_length.hpp"
#include "kirchhoff/analysis/detail/stability_symmetric.hpp"
#include "kirchhoff/contact/self_contact.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

namespace kirchhoff {
namespace {

using detail::eigenphases;

constexpr double kPi = 3.14159265358979323846;
// An integration step observed on its interpolant (interpolated_step) is at most this many of
// the rate's observation steps long, and its eigenphases stay this far from conjugate points.
constexpr double kInterpolatedSteps = 4.0;
constexpr double kPassageMargin = 0.03;  // rad
// Observation steps aim at eigenphase moves of this fraction of max_phase_step (observation_step
// and the interpolant's sub-steps): beyond max_phase_step a step is halved.
constexpr double kAimedPhaseMove = 0.7;
// Where the eigenphase's speed is bounded (StabilityOptions::bounded_observations) it moves at
// most this much over an observation step: below pi, so that the move read from the step's ends
// is the move itself (no turn unseen, no passage paired wrongly), with 0.64 rad to spare.
constexpr double kBoundedPhaseMove = 2.5;
// A load-controlled mode is an exact zero mode of the isoperimetric correction where its share of
// D is this many times the rest (its sign then decides, as the exact count assumes), or where its
// singular value is below this fraction of the largest (round-off: the decomposition drops it).
constexpr double kExactZeroShare = 1e3;
constexpr double kRoundOffZero = 1e-13;
// The relative error of the conditions' singular values, at least (7e-12 measured on the
// plectoneme's arch in a solve), and ten times the fields' tolerance (1e-8 along a branch).
constexpr double kConditionsNoise = 1e-9;

// Scales making the canonical coordinates dimensionless: lengths by L, forces by B / L^2,
// moments by B / L. The symplectic form only gains the constant factor L / B.
struct Scales {
  double length = 1.0;
  double bending = 1.0;
  // The rotation pair's momentum is divided by this as well (a symplectic rescaling u -> u,
  // p -> p / rate: it changes no crossing nor the inertia of any boundary form). Under loads the
  // fields oscillate with wavenumber ~ sqrt(|n| / B): scaled so, their eigenphases turn at a
  // nearly uniform rate ~ 2 rate / L, instead of spending most of a turn within a short stretch
  // near each conjugate point, where a step could pass a whole turn unseen.
  double rate = 1.0;
  // The force's momentum is divided by it too where positions are configuration variables (the
  // full frame below): the same factor on every momentum keeps the rescaling symplectic.
  double force_rate = 1.0;
  // A spatial rod whose stiffnesses differ by more than kImbalance (a cantilever stiff in its
  // loading plane, soft across it): one B cannot scale every direction's momentum. The rotation
  // pair is then balanced direction by direction, u -> A u, p -> A^-1 p with A = R diag(c) R^T,
  // R the frame and c_k = (B_k B_min)^(1/4) / sqrt(B) (balancing), which puts each direction's
  // momentum at its rotation's size where the force sets the fields' wavenumber sqrt(|n| / B_k).
  // Symplectic at every s (A symmetric and invertible; it varies with s as the frame turns): det U
  // vanishes where it did, so no conjugate point moves, and the boundary forms keep their inertia.
  // Unbalanced, the soft direction's momentum was B_min / B of its rotation: its eigenphase
  // passed pi within that fraction of the rod, between observations, and its end form's
  // eigenvalues fell inside the zero tolerance (an index 0 with a zero mode 2 % past a critical
  // load). 0: not balanced.
  double stiffness_min = 0.0;
};

// Stiffness ratios up to this are left to the one scale B: a twisted rod's twist to bending
// stiffness 1 / (1 + nu) moves its momenta by less than a factor 1.5.
constexpr double kImbalance = 4.0;

// The balancing A of the rotation pair (Scales::stiffness_min) at a point with frame R, in the
// rotation coordinates (the orthonormal basis `rotation_dirs` of the lab's three); the identity
// where the rod is not balanced.
Mat3 balancing(const RodModel& model, const Scales& sc, const Eigen::MatrixXd& rotation_dirs, const Mat3& R, double s) {
  if (!(sc.stiffness_min > 0)) return Mat3::Identity();
  Vec3 c;
  for (int k = 0; k < 3; ++k) c[k] = std::pow(model.B[k](s) * sc.stiffness_min, 0.25) / std::sqrt(sc.bending);
  const Mat3 in_lab = R * c.asDiagonal() * R.transpose();
  return rotation_dirs.transpose() * in_lab * rotation_dirs;
}

// Canonical coordinates of the rod's configuration (position, then rotation, along the
// directions the equations admit) and their momenta.
struct Coordinates {
  Eigen::MatrixXd position_dirs;  // 3 x kr
  Eigen::MatrixXd rotation_dirs;  // 3 x kpsi
  int kr() const { return static_cast<int>(position_dirs.cols()); }
  int size() const { return kr() + static_cast<int>(rotation_dirs.cols()); }
};

// A state perturbation dy in the coordinates (u, p_physical) = T dy; the canonical momentum is
// p = p_physical + G u (G skew: 1/2 m x dpsi on the rotation pair).
struct CanonicalMap {
  Eigen::MatrixXd T;
  Eigen::MatrixXd G;
};

Eigen::Matrix3d cross_matrix(const Vec3& a) {
  Eigen::Matrix3d M;
  M << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return M;
}

// dy -> the lab-frame rotation vector dpsi of the frame at state y (whose frame is R): the
// Jacobian of the orientation error against the frame itself as target.
SlotMap lab_rotation_jacobian(const RodEquations& eq, const Eigen::VectorXd& y, const Mat3& R) {
  const Mat3 reference = eq.is_planar() ? planar_reference_frame() : Mat3::Identity();
  const Eigen::AngleAxisd frame(Mat3(R * reference.transpose()));
  SlotMap jacobian;
  eq.orientation_error(y, OrientationTarget{frame.axis(), frame.angle()}, false, &jacobian);
  return jacobian;
}

// The rows of T and the block of G that depend on the state: the rotation's (its Jacobian
// follows the frame) and G (it holds m). The other rows are constant along the rod.
void update_rotation_part(const RodEquations& eq, const Coordinates& c, const Scales& sc, const Eigen::VectorXd& y,
                          double s, CanonicalMap* map) {
  const int n = c.size(), kr = c.kr();
  const RodPoint point = eq.point(y, s);
  const SlotMap rotation_jacobian = lab_rotation_jacobian(eq, y, point.R);
  const double momentum = sc.length / (sc.bending * sc.rate);
  if (sc.stiffness_min > 0) {  // (balanced: three rotation coordinates)
    const Mat3 A = balancing(eq.model(), sc, c.rotation_dirs, point.R, s), A_inv = A.inverse();
    map->T.middleRows(kr, 3).noalias() = A * c.rotation_dirs.transpose() * rotation_jacobian;
    map->T.bottomRows(3).noalias() = (momentum * A_inv) * c.rotation_dirs.transpose() * eq.slot_map(Slot::Moment);
    map->G.bottomRightCorner(3, 3).noalias() =
        (0.5 * momentum) * A_inv * c.rotation_dirs.transpose() * cross_matrix(point.m) * c.rotation_dirs * A_inv;
    return;
  }
  // (Coefficient-wise products into storage of at most 3 x 3: the dynamic-size product would
  // take the general matrix product's path, a tenth of a spatial index, for 3 x 3 blocks.)
  using Block3 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;
  const Block3 dirs_t = c.rotation_dirs.transpose();
  map->T.middleRows(kr, n - kr).noalias() = dirs_t.lazyProduct(rotation_jacobian);
  const Block3 turned = dirs_t.lazyProduct(cross_matrix(point.m));
  map->G.bottomRightCorner(n - kr, n - kr).noalias() = (0.5 * momentum) * turned.lazyProduct(c.rotation_dirs);
}

CanonicalMap canonical_map(const RodEquations& eq, const Coordinates& c, const Scales& sc, const Eigen::VectorXd& y,
                           double s) {
  const int N = static_cast<int>(y.size()), n = c.size(), kr = c.kr();
  CanonicalMap map;
  map.T = Eigen::MatrixXd::Zero(2 * n, N);
  map.T.topRows(kr) = c.position_dirs.transpose() * eq.slot_map(Slot::Position) / sc.length;
  map.T.middleRows(n, kr) =
      c.position_dirs.transpose() * eq.slot_map(Slot::Force) * (sc.length * sc.length / (sc.bending * sc.force_rate));
  map.T.bottomRows(n - kr) =
      c.rotation_dirs.transpose() * eq.slot_map(Slot::Moment) * (sc.length / (sc.bending * sc.rate));
  map.G = Eigen::MatrixXd::Zero(n, n);
  update_rotation_part(eq, c, sc, y, s, &map);
  return map;
}

// Orthonormal basis of the column space of A (columns below `tol` times the largest dropped).
// (One column: its singular value is its norm, and it is its own direction - a planar frame's
// blocks, most of a planar index's bases, without the decomposition.)
Eigen::MatrixXd column_basis(const Eigen::MatrixXd& A, double tol = 1e-10) {
  if (A.cols() == 0 || A.rows() == 0) return Eigen::MatrixXd(A.rows(), 0);
  if (A.cols() == 1) {
    const double norm = A.norm();
    return norm > tol ? Eigen::MatrixXd(A / norm) : Eigen::MatrixXd(A.rows(), 0);
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU);
  int rank = 0;
  for (int i = 0; i < svd.singularValues().size(); ++i)
    if (svd.singularValues()[i] > tol) ++rank;
  return svd.matrixU().leftCols(rank);
}

// Orthonormal basis of the orthogonal complement of the columns of C in R^n.
Eigen::MatrixXd complement(const Eigen::MatrixXd& C, int n) {
  if (C.cols() == 0) return Eigen::MatrixXd::Identity(n, n);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(C, Eigen::ComputeFullU);
  const int rank = static_cast<int>(column_basis(C).cols());
  return svd.matrixU().rightCols(n - rank);
}

// Orthonormal basis of the null space of A (singular values below tol), as columns.
Eigen::MatrixXd null_space(const Eigen::MatrixXd& A, int cols, double tol) {
  if (A.rows() == 0) return Eigen::MatrixXd::Identity(cols, cols);
  if (cols == 1) return A.norm() > tol ? Eigen::MatrixXd(1, 0) : Eigen::MatrixXd::Identity(1, 1);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  int rank = 0;
  for (int i = 0; i < svd.singularValues().size(); ++i)
    if (svd.singularValues()[i] > tol) ++rank;
  return svd.matrixV().rightCols(cols - rank);
}

double parameter_step(double value) { return 1e-6 * std::max(1.0, std::abs(value)); }

Vec3 orientation_vector(const OrientationTarget& t) { return t.axis.normalized() * t.angle; }

// How a slot's imposed value changes with parameter `name` (central difference of a closed form).
Vec3 slot_sensitivity(const SlotCondition& slot, const Parameters& p, const std::string& name) {
  Parameters plus = p, minus = p;
  const double h = parameter_step(p.get(name));
  plus.set(name, p.get(name) + h);
  minus.set(name, p.get(name) - h);
  if (slot.slot == Slot::Orientation)
    return (orientation_vector(slot.orientation(plus)) - orientation_vector(slot.orientation(minus))) / (2 * h);
  return (slot.value(plus) - slot.value(minus)) / (2 * h);
}

// The unknown parameters that act as Lagrange multipliers (end loads), or why one does not.
std::string classify_unknowns(const ShootingProblem& problem, const Parameters& p,
                              std::vector<std::string>* multipliers) {
  const ProblemDefinition& d = problem.definition();
  for (const std::string& name : d.unknown_parameters) {
    if (is_unfolding_parameter(name)) continue;
    if (d.model_parameters.count(name) || d.obstacle_parameters.count(name))
      return "the unknown parameter '" + name + "' changes the rod or an obstacle, not an end load";
    bool load = false;
    for (const EndCondition* end : {&d.start, &d.end}) {
      for (const SlotCondition& slot : end->conditions()) {
        if (slot.extra) continue;
        const double change = slot_sensitivity(slot, p, name).norm();
        if (change == 0.0) continue;
        if (slot.slot == Slot::Position || slot.slot == Slot::Orientation)
          return "the unknown parameter '" + name + "' moves an imposed " + to_string(slot.slot);
        load = true;
      }
    }
    if (!load) return "the unknown parameter '" + name + "' is not an end load";
    multipliers->push_back(name);
  }
  return "";
}

// The configuration directions an end holds (columns, canonical u coordinates): imposed
// positions and rotations, and the displacements conjugate to multiplier loads.
Eigen::MatrixXd held_directions(const RodEquations& eq, const EndCondition& end, const Coordinates& c,
                                const Parameters& p, const std::vector<std::string>& multipliers) {
  std::vector<Eigen::VectorXd> columns;
  auto add = [&](bool position, const Vec3& lab) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(c.size());
    if (position) u.head(c.kr()) = c.position_dirs.transpose() * lab;
    else u.tail(c.size() - c.kr()) = c.rotation_dirs.transpose() * lab;
    columns.push_back(u);
  };
  for (const SlotCondition& slot : end.conditions()) {
    if (slot.extra) continue;
    const Eigen::MatrixXd basis = slot.basis(eq);
    const bool position = slot.slot == Slot::Position || slot.slot == Slot::Force;
    if (slot.slot == Slot::Position || slot.slot == Slot::Orientation) {
      for (int k = 0; k < basis.cols(); ++k) add(position, basis.col(k));
      continue;
    }
    for (const std::string& name : multipliers) {
      const Eigen::VectorXd along = basis.transpose() * slot_sensitivity(slot, p, name);
      if (along.norm() > 0) add(position, basis * along.normalized());
    }
  }
  Eigen::MatrixXd C(c.size(), static_cast<int>(columns.size()));
  for (size_t k = 0; k < columns.size(); ++k) C.col(static_cast<int>(k)) = columns[k];
  return column_basis(C);
}

std::string unsupported(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  const ProblemDefinition& d = problem.definition();
  const std::vector<Obstacle> obstacles = problem.obstacles(problem.parameters_at(x));
  for (const PointContact& c : problem.contacts_at(x)) {
    if (c.extended)
      return "an extended contact (the rod lying on the obstacle): its second variation is not implemented";
    if (problem.equations(problem.parameters_at(x))->model().extensible)
      return "a contact of an extensible rod: not implemented";
  }
  if (d.start.is_half_turn_symmetry())
    return "half of a symmetric rod with the symmetry point at s = 0: only a half-turn end at s = L is "
           "implemented";
  if (d.end.is_half_turn_symmetry() && d.end.half_turn_director() == 0)
    return "half of a symmetric rod whose half-turn end imposes the loop's rotation (balanced by an unknown "
           "parameter): not implemented";
  if (d.end.is_half_turn_symmetry() && !problem.contacts_at(x).empty())
    return "half of a symmetric rod with contacts (hard self-contact): the antisymmetric perturbations of a pair "
           "contact are not implemented";
  return "";
}

double wrap(double angle) { return std::remainder(angle, 2 * kPi); }

// The end of a step of at most h from s towards `end`, the last steps evened out to land on it.
double step_end(double s, double end, double h) {
  const double left = end - s;
  return left <= h ? end : s + left / std::ceil(left / h);
}

// The frame of Jacobi fields along the rod, in state coordinates, with its canonical blocks.
struct Frame {
  Eigen::VectorXd y;   // the equilibrium state here
  double s = 0.0;
  Eigen::MatrixXd dY;  // N x kpsi: state perturbations of the fields
  Eigen::MatrixXd U, P, P_physical;  // rotation blocks, kpsi x kpsi each; [U; P] orthonormal
  Eigen::MatrixXd R;                  // position perturbation of the fields (kr x kpsi), slaved
  // One field per isoperimetric constraint's multiplier: first those starting at s = 0 (the
  // response to a unit change of the end load along a held chord direction; with the full frame,
  // of the start's load along a position it holds), then one per point contact, zero up to its
  // contact, the response to a unit change of its force beyond; with the full frame last one per
  // position the end holds, identically zero (its load enters through the end's conditions).
  Eigen::MatrixXd particular, particular_U, particular_P, particular_P_physical, particular_R;
  // The constraints read before s = L on the frame's fields and on the particular ones: with the
  // full frame the positions the start holds (at s = 0), then the contacts' nu.dr(s_c) / L,
  // recorded as each contact is passed.
  Eigen::MatrixXd recorded_rows_frame, recorded_rows_particular;
  // d/ds of y and dY where slope_at == s (StabilityAnalysis::slopes), else stale.
  Eigen::VectorXd y_slope;
  Eigen::MatrixXd dY_slope;
  double slope_at = std::numeric_limits<double>::quiet_NaN();
};

// Follows lifted eigenphases, and where they pass odd multiples of pi (a stack per eigenphase:
// a passage downwards pushes, one back upwards pops, so round-off cancels).
struct PhaseTrack {
  Eigen::VectorXd lifted;
  Eigen::VectorXd lowest;  // running minimum of each lifted phase
  std::vector<std::vector<std::pair<long, double>>> passages;  // (k of k pi, s) per eigenphase
  bool reversed = false;  // a genuine passage against the Legendre direction
  double reversed_at = 0.0;
  // A step whose det U changed sign an odd number of times against the passages its eigenphases
  // showed, at the halvings' end (advance): a passage turned a whole turn between observations.
  bool unresolved = false;
  double unresolved_at = 0.0;
};

// The smallest m with (2m + 1) pi > a.
long first_odd_multiple_above(double a) { return static_cast<long>(std::floor((a / kPi - 1) / 2)) + 1; }

int odd_multiples_between(double a, double b) {  // odd k with a < k pi < b (a < b)
  const long lo = first_odd_multiple_above(a);
  const long hi = static_cast<long>(std::ceil((b / kPi - 1) / 2)) - 1;
  return static_cast<int>(std::max(0L, hi - lo + 1));
}

class StabilityAnalysis {
 public:
  // `end` replaces the problem's end conditions and `equations` (when not null) its equations: the
  // antisymmetric half of a half-turn symmetric rod (stability_symmetric.hpp).
  StabilityAnalysis(const ShootingProblem& problem, const Eigen::VectorXd& x, const StabilityOptions& options,
                    const EndCondition& end, std::shared_ptr<const RodEquations> equations)
      : problem_(problem), x_(x), options_(options),
        max_phase_step_(options.max_phase_step / options.observation_density), end_(end), p_(problem.parameters_at(x)),
        eq_(equations ? std::move(equations) : problem.equations(p_)) {
    coords_.position_dirs = eq_->admissible_directions(Slot::Position);
    coords_.rotation_dirs = eq_->admissible_directions(Slot::Orientation);
    scales_.length = eq_->model().length;
    scales_.bending = eq_->model().B[0](0.0);
    field_integrator_ = problem_.definition().options.integrator;
    if (options_.field_tolerance > field_integrator_.abs_tol) {
      field_integrator_.abs_tol = field_integrator_.rel_tol = options_.field_tolerance;
    }
    // The profile sets scales (the fields' rate) and whether a field's gradient acts: integrated
    // to the fields' tolerance, as they are. Where H bounds the moment (moment_bound.hpp) the
    // start alone serves: a fifth of the Elastica's index was this profile.
    profile_ = problem_.sample(x_, {0.0}, &field_integrator_);
    moment_bound_ = detail::moment_bound(*eq_, profile_.front(), !problem_.contacts_at(x_).empty());
    if (!moment_bound_) {
      std::vector<double> s(17);
      for (size_t i = 0; i < s.size(); ++i) s[i] = scales_.length * static_cast<double>(i) / (s.size() - 1);
      profile_ = problem_.sample(x_, s, &field_integrator_);
    }
    scales_.stiffness_min = imbalanced_stiffness_min();
    full_ = options_.positions_as_configuration || positions_are_configuration();
    const int n = coords_.size(), kr = coords_.kr();
    offset_ = full_ ? 0 : kr;
    mU_ = full_ ? n : n - kr;
  }

  // The smallest stiffness of a spatial rod whose stiffnesses differ by more than kImbalance
  // along it (Scales::stiffness_min), else 0.
  double imbalanced_stiffness_min() const {
    if (eq_->is_planar() || coords_.rotation_dirs.cols() != 3) return 0.0;
    const RodModel& model = eq_->model();
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (int i = 0; i <= 16; ++i)
      for (int k = 0; k < 3; ++k) {
        const double B = model.B[k](scales_.length * i / 16.0);
        lo = std::min(lo, B);
        hi = std::max(hi, B);
      }
    return hi > kImbalance * lo ? lo : 0.0;
  }

  // The wavenumber of the Jacobi fields, L sqrt(|n| / B) and L |m| / B at their largest over the
  // rod (at least 1): sets the momentum's scale and the number of steps.
  double field_rate() const {
    const RodModel& model = eq_->model();
    double stiffness = std::numeric_limits<double>::infinity(), rate = 1.0;
    for (const RodPoint& q : profile_)
      for (int k = 0; k < 3; ++k) stiffness = std::min(stiffness, model.B[k](q.s));
    for (const RodPoint& q : profile_)
      rate = std::max({rate, scales_.length * std::sqrt(q.n.norm() / stiffness), scales_.length * q.m.norm() / stiffness});
    if (moment_bound_) rate = std::max(rate, scales_.length * *moment_bound_ / stiffness);
    // A field stiffness k (|df/dr|) makes the fields oscillate like a beam on a foundation, with
    // wavenumber (k / B)^(1/4).
    if (model.field)
      for (const RodPoint& q : profile_)
        rate = std::max(rate, scales_.length * std::pow(model.field->force_gradient(q.s, q.r).norm() / stiffness, 0.25));
    return rate;
  }

  StabilityReport run();

  // Check, at every step of the fields' integration, that the sliding partners of `original`'s
  // half-turn self-contact are defined where it acts (sliding_reason, stability_symmetric.hpp):
  // the steps are refined where the barrier is stiff (field_rate).
  void track_barrier(std::shared_ptr<const RodEquations> original) { barrier_eq_ = std::move(original); }
  const std::string& sliding_reason() const { return sliding_reason_; }
  // Whether run() saw an eigenphase pass against the Legendre direction (its report then has no
  // index): a degenerate Jacobi system, or phases paired wrongly between too long steps.
  bool reversed() const { return reversed_; }

 private:
  struct Held {
    Eigen::MatrixXd position;  // kr x a, position coordinates
    Eigen::MatrixXd rotation;  // kpsi x b, rotation coordinates
  };
  Held held_at(const EndCondition& end, const std::vector<std::string>& multipliers) const;
  // The same with the rotations in the balanced coordinates at state y, arclength s (Scales).
  Held held_at(const EndCondition& end, const std::vector<std::string>& multipliers, const Eigen::VectorXd& y,
               double s) const;
  Mat3 balancing_at(const Eigen::VectorXd& y, double s) const;
  bool positions_are_configuration() const;
  // The configuration directions (the frame's U coordinates) an end holds in the load-controlled
  // problem: its held rotations; positions are never held there.
  Eigen::MatrixXd held_configuration(const Held& held) const;
  Eigen::MatrixXd constraint_directions(const Held& start, const Held& end) const;
  Frame start_frame(const Held& start, const Eigen::MatrixXd& start_multipliers, int contacts, int end_multipliers) const;
  std::string pass_contact(Frame* f, const PointContact& contact, int number, PhaseTrack* track, double* shear);
  const CanonicalMap& map_at(const Eigen::VectorXd& y, double s) const;
  void canonical_blocks(Frame* f) const;
  void orthonormalise(Frame* f) const;
  void flowed(const Frame& f, double s1, CarriedSteps* steps, bool frame_only, Frame* next);
  void march(Frame* f, double end, double longest, double observed, PhaseTrack* track);
  void march_observed(Frame* f, double end, double longest, PhaseTrack* track);
  std::optional<double> phase_speed_bound(const std::vector<PointContact>& contacts) const;
  void march_bounded(Frame* f, double end, PhaseTrack* track);
  bool interpolated_step(Frame* f, double s1, double observed, PhaseTrack* track);
  bool near_passage(const Eigen::VectorXd& from, const Eigen::VectorXd& to) const;
  // A passage of an eigenphase past an odd multiple of pi seen between two observations on an
  // interpolant (interpolated_step), to be located on exact frames once the step is taken.
  struct SeenPassage {
    int j;
    long multiple;
    double a, b, ta, tb;        // the observations' arclengths and tan of half their offsets
    Eigen::VectorXd reference;  // the phases at a, against which trial phases are lifted
  };
  bool clear_or_clean_passage(const Eigen::VectorXd& from, const Eigen::VectorXd& to, double a, double b,
                              std::vector<SeenPassage>* seen) const;
  void slopes(Frame* f);
  bool interpolant_is_close(const Frame& a, const Frame& b) const;
  double observation_step(double longest) const;
  void advance(Frame* f, double s1, PhaseTrack* track, int depth);
  static bool determinant_flipped(const Frame& from, const Frame& to);
  static bool parity_contradicted(const Eigen::VectorXd& from, const Eigen::VectorXd& to, bool det_flipped);
  void record(const Frame& f, const Eigen::VectorXd& after, double s1, PhaseTrack* track);
  double locate_passage(const Frame& f, const Eigen::VectorXd& reference, int j, long multiple, double a, double b,
                        double ta, double tb);
  bool count_interior(const Frame& f, const PhaseTrack& track, const Eigen::VectorXd& start,
                      StabilityReport* report) const;
  Eigen::MatrixXd end_terms(const Frame& f, const Held& end, StabilityReport* report) const;
  std::string end_moment_reason(const Frame& f, const Held& end) const;
  bool constraint_correction(const Frame& f, const Held& end, const Eigen::MatrixXd& constraints,
                             const Eigen::MatrixXd& zero_modes, StabilityReport* report) const;
  // The steps of run(): the eigenphases at s = 0, the pieces the rod is cut into, the fields
  // carried across them, and the count at s = L.
  PhaseTrack starting_track(const Frame& f, int held_count) const;
  std::vector<double> piece_breaks(const std::vector<PointContact>& contacts) const;
  std::string carry_across(Frame* f, const std::vector<PointContact>& contacts, PhaseTrack* track);
  void count_at_end(const Frame& f, const PhaseTrack& track, const Eigen::VectorXd& start_phases, const Held& start,
                    const Held& end, const Eigen::MatrixXd& constraints, StabilityReport* report) const;
  // The shear of the canonical momenta a point quadratic form 1/2 z^T S z of the lab
  // perturbation z = (dr, dpsi) makes (p += S_c u), in the frame's U coordinates.
  Eigen::MatrixXd canonical_shear(const Eigen::MatrixXd& lab_S, const Frame& at) const;

  const ShootingProblem& problem_;
  const Eigen::VectorXd& x_;
  StabilityOptions options_;
  double max_phase_step_;  // the options', over their observation_density
  const EndCondition& end_;
  Parameters p_;
  std::shared_ptr<const RodEquations> eq_;
  Coordinates coords_;
  Scales scales_;
  // The equilibrium at 17 equally spaced points, for the checks above; at s = 0 alone where the
  // moment's bound stands for it.
  std::vector<RodPoint> profile_;
  std::optional<double> moment_bound_;
  long rhs_ = 0;
  long flows_ = 0;  // integrations of the fields (flowed)
  // The bound on the eigenphase's speed where one is proved (phase_speed_bound), else empty.
  std::optional<double> phase_speed_bound_;
  IntegratorOptions field_integrator_;  // the state's, or looser (StabilityOptions::field_tolerance)
  bool reversed_ = false;
  CarriedSteps steps_;  // the step sizes the fields' integration proposes next (flowed)
  // The last observation step taken and the largest move of an eigenphase over it (advance);
  // none yet (zero step) at the start and past a contact.
  struct Observation {
    double step = 0.0, move = 0.0;
  } last_observation_;
  // Workspaces kept across the index's steps (no allocation at each): the map (map_at), the
  // frame a step arrives at (advance), the trial frames of locate_passage and the frames observed
  // on an interpolant (interpolated_step).
  mutable CanonicalMap map_;
  mutable bool map_known_ = false, map_has_G_ = true;
  Frame arriving_, trial_, interpolated_;
  std::vector<SeenPassage> seen_;  // interpolated_step's passages
  Eigen::MatrixXd directions_;  // the fields handed to the integration (flowed)
  // The full frame: positions are configuration variables beside the rotation (see
  // positions_are_configuration); its U block holds (dr / L, dpsi), offset_ = 0. Otherwise the
  // rotation alone, offset_ = kr. mU_ is the size of U.
  bool full_ = false;
  int offset_ = 0, mU_ = 0;
  // Multipliers whose particular fields start at s = 0 and constraints recorded before L (see Frame).
  int start_multipliers_ = 0, recorded_before_contacts_ = 0;
  std::shared_ptr<const RodEquations> barrier_eq_;  // track_barrier
  std::string sliding_reason_;  // track_barrier: the first point where the sliding partners are not defined
};

StabilityAnalysis::Held StabilityAnalysis::held_at(const EndCondition& end,
                                                   const std::vector<std::string>& multipliers) const {
  const Eigen::MatrixXd C = held_directions(*eq_, end, coords_, p_, multipliers);
  const int kr = coords_.kr(), kpsi = coords_.size() - kr;
  Held h;
  h.position = column_basis(C.topRows(kr));
  h.rotation = column_basis(C.bottomRows(kpsi));
  return h;
}

// A held rotation e (e.dpsi = 0) is e.A^-1 u = 0 in the balanced u = A dpsi: the column A^-1 e.
StabilityAnalysis::Held StabilityAnalysis::held_at(const EndCondition& end, const std::vector<std::string>& multipliers,
                                                   const Eigen::VectorXd& y, double s) const {
  Held h = held_at(end, multipliers);
  if (scales_.stiffness_min > 0 && h.rotation.cols() > 0)
    h.rotation = column_basis(balancing_at(y, s).inverse() * h.rotation);
  return h;
}

Mat3 StabilityAnalysis::balancing_at(const Eigen::VectorXd& y, double s) const {
  return balancing(eq_->model(), scales_, coords_.rotation_dirs, eq_->point(y, s).R, s);
}

// Whether positions are configuration variables of their own, beside the rotation: where the
// energy depends on where the rod is, not only on its shape - a field whose force depends on
// position (a soft wall, a barrier: f = -grad V(r)), or a contact with a curved obstacle, whose
// second variation holds the obstacle's curvature at the perturbed contact point dr(s_c) - and
// wherever a point contact is active at all: its force is a multiplier whose change is a load on
// an interior point, which the end loads of the rotation frame do not balance (the response to it
// alone is not an equilibrium; D came out unsymmetric), while the full frame has the translations
// to take it and keeps only the loads that do no work on its zero modes.
//
// Why the rotation alone no longer suffices. The load-controlled problem's energy is
//   E[r0, R] = int W(u, v) + int V(r) - F_L.r(L) + F_0.r(0),   r(s) = r0 + int_0^s R v,
// so its second variation holds int dr.Hess V dr with dr(s) = dr0 + int_0^s (dpsi x d3 + ...): a
// non-local term in the rotation, and the translation dr0 costs energy, so the rigid
// translations are not the zero modes they are without such a field. With (r, R) as the
// configuration the term is local: the Jacobi fields carry dr, and dn' = -(df/dr) dr (the
// shooting core's variational equations already linearise the field, so nothing changes there).
// This is a problem of Lagrange - r' = d3 is a constraint whose multiplier is n, and the
// Hamiltonian's Hessian in the momenta is B^-1 on dm and zero on dn (inextensible rods): the
// Legendre condition holds on the strains, as before, not on the position. Morse's index theorem
// still holds for such problems when they are normal (no perturbation keeps r' = d3 by force
// alone: here a field with dr = dpsi = dm = 0 must have dn along a straight stretch's axis, which
// the load-controlled frame, dn(0) = 0, never contains), and a crossing of the Lagrangian frame
// through det U = 0 has the crossing form dm.B^-1 dm >= 0: the eigenphases of W still pass -1 in
// one direction only. A crossing with dm = 0 as well would be non-regular; the count refuses any
// passage the other way, so such a case is reported undefined, never guessed.
//
// Why the chord constraint changes. With V depending on r, holding r(0) and r(L) is not the same
// as holding r(L) - r(0): each held position is a constraint of its own, e.r(0) and e.r(L), whose
// multiplier is that end's reaction (a force doing work on it). D is then d(held positions) /
// d(reactions) along the load-controlled equilibria, a k x k matrix with k the positions held at
// either end; the bordered-Hessian count index = index_dead + n_+(D) + r_Z - k is unchanged (it
// needs only a quadratic form and linear constraints). Where df/dr = 0 it reduces to the chord
// count: the translations are then zero modes of the load-controlled problem, r_Z is the rank of
// the held directions, and the loads doing no work on the translations are the balanced pairs,
// whose D is the chord's. (The tests check that the two frames agree on every such case.)
bool StabilityAnalysis::positions_are_configuration() const {
  const auto& field = eq_->model().field;
  if (field)
    for (const RodPoint& q : profile_)
      if (field->force_gradient(q.s, q.r).norm() > 0) return true;
  return !problem_.contacts_at(x_).empty();
}

Eigen::MatrixXd StabilityAnalysis::held_configuration(const Held& held) const {
  if (!full_) return held.rotation;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(mU_, held.rotation.cols());
  out.bottomRows(held.rotation.rows()) = held.rotation;
  return out;
}

// Directions along which both ends hold the position: the isoperimetric constraints
// e.(r(L) - r(0)) = const, whose multipliers are the reactions.
Eigen::MatrixXd StabilityAnalysis::constraint_directions(const Held& start, const Held& end) const {
  const int kr = coords_.kr();
  if (start.position.cols() == 0 || end.position.cols() == 0) return Eigen::MatrixXd(kr, 0);
  Eigen::MatrixXd both(kr, start.position.cols() + end.position.cols());
  both << start.position, -end.position;
  const Eigen::MatrixXd pairs = null_space(both, static_cast<int>(both.cols()), 1e-10);
  return column_basis(start.position * pairs.topRows(start.position.cols()));
}

// Jacobi fields of the load-controlled problem meeting the start's conditions: its rotation
// conditions, dn = 0 (a dead load), and dr = 0 - or, with the full frame, dr free (one field per
// translation). Then one particular field per multiplier starting at s = 0, with dn(0) given by
// the columns of start_multipliers (a unit change of the load along a held chord, dn = e_j; with
// the full frame, of the start's reaction along a position it holds, dn(0) = -e_j, the force on
// the rod being -n(0)), room for one per contact and, with the full frame, one per position the
// end holds (zero fields: see Frame).
Frame StabilityAnalysis::start_frame(const Held& start, const Eigen::MatrixXd& start_multipliers, int contacts,
                                     int end_multipliers) const {
  const int n = coords_.size(), kr = coords_.kr();
  const Eigen::MatrixXd held = held_configuration(start);
  const Eigen::MatrixXd free = complement(held, mU_);
  const int starting = static_cast<int>(start_multipliers.cols());
  Eigen::MatrixXd z = Eigen::MatrixXd::Zero(2 * n, mU_ + starting);
  z.block(offset_, 0, mU_, free.cols()) = free;
  z.block(n + offset_, free.cols(), mU_, held.cols()) = held;
  z.block(n, mU_, kr, starting) = start_multipliers;
  Frame f;
  f.s = 0.0;
  f.y = x_.head(problem_.state_size());
  const CanonicalMap map = canonical_map(*eq_, coords_, scales_, f.y, 0.0);
  const Eigen::MatrixXd dY = map.T.completeOrthogonalDecomposition().solve(z);
  f.dY = dY.leftCols(mU_);
  const int multipliers = starting + contacts + end_multipliers;
  f.particular = Eigen::MatrixXd::Zero(dY.rows(), multipliers);
  f.particular.leftCols(starting) = dY.rightCols(starting);
  canonical_blocks(&f);
  // With the full frame, the start's held positions are constraints read here.
  const int recorded = recorded_before_contacts_ + contacts;
  f.recorded_rows_frame = Eigen::MatrixXd::Zero(recorded, mU_);
  f.recorded_rows_particular = Eigen::MatrixXd::Zero(recorded, multipliers);
  if (recorded_before_contacts_ > 0) {
    f.recorded_rows_frame.topRows(recorded_before_contacts_) = start.position.transpose() * f.R;
    f.recorded_rows_particular.topRows(recorded_before_contacts_) = start.position.transpose() * f.particular_R;
  }
  return f;
}

// The canonical map at the frame's point. A planar rod's is the same everywhere (its rotation is
// the state's angle, and G = 1/2 e_z.(m x e_z) = 0): computed once. A spatial rod's changes in its
// rotation rows and G only (update_rotation_part).
const CanonicalMap& StabilityAnalysis::map_at(const Eigen::VectorXd& y, double s) const {
  if (eq_->is_planar() && map_known_) return map_;
  if (map_known_)
    update_rotation_part(*eq_, coords_, scales_, y, s, &map_);
  else
    map_ = canonical_map(*eq_, coords_, scales_, y, s);
  map_known_ = true;
  map_has_G_ = !map_.G.isZero(0.0) || !eq_->is_planar();
  return map_;
}

// Rows [first, first + count) of T dY. T is sparse (each canonical coordinate reads a few state
// components) and small: its nonzeros alone, row by row, cost a fraction of a dense product.
void sparse_rows_product(const Eigen::MatrixXd& T, const Eigen::MatrixXd& dY, int first, int count,
                         Eigen::MatrixXd* out) {
  out->setZero(count, dY.cols());
  for (int r = 0; r < count; ++r)
    for (Eigen::Index k = 0; k < T.cols(); ++k)
      if (const double t = T(first + r, k); t != 0.0) out->row(r) += t * dY.row(k);
}

void StabilityAnalysis::canonical_blocks(Frame* f) const {
  const int n = coords_.size(), kr = coords_.kr();
  const CanonicalMap& map = map_at(f->y, f->s);
  auto blocks = [&](const Eigen::MatrixXd& dY, Eigen::MatrixXd* U, Eigen::MatrixXd* P, Eigen::MatrixXd* P_phys,
                    Eigen::MatrixXd* R) {
    sparse_rows_product(map.T, dY, offset_, mU_, U);
    sparse_rows_product(map.T, dY, n + offset_, mU_, P_phys);
    *P = *P_phys;
    if (map_has_G_) P->noalias() += map.G.bottomRightCorner(mU_, mU_).lazyProduct(*U);
    sparse_rows_product(map.T, dY, 0, kr, R);
  };
  blocks(f->dY, &f->U, &f->P, &f->P_physical, &f->R);
  blocks(f->particular, &f->particular_U, &f->particular_P, &f->particular_P_physical, &f->particular_R);
}

// Keeps the frame's columns orthonormal in (U, P) (the span, a Lagrangian plane, is unchanged):
// the columns times R^-1 of the QR factorisation of [U; P] (one field: divided by its norm).
void StabilityAnalysis::orthonormalise(Frame* f) const {
  const int m = static_cast<int>(f->U.cols());
  if (m == 0) return;
  auto apply = [&](auto&& divide) {
    for (Eigen::MatrixXd* X : {&f->dY, &f->dY_slope, &f->U, &f->P, &f->P_physical, &f->R, &f->recorded_rows_frame})
      if (X->size() > 0) divide(*X);
  };
  if (m == 1) {
    const double norm = std::hypot(f->U(0, 0), f->P(0, 0));
    apply([&](Eigen::MatrixXd& X) { X /= norm; });
    return;
  }
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 12, 6>;
  Small Z(2 * m, m);
  Z << f->U, f->P;
  const Eigen::HouseholderQR<Small> qr(Z);
  const Small R = qr.matrixQR().topRows(m);
  // X R^-1 column by column (m <= 6: the triangular solver's blocked path costs more here).
  apply([&](Eigen::MatrixXd& X) {
    for (int j = 0; j < m; ++j) {
      for (int k = 0; k < j; ++k) X.col(j) -= R(k, j) * X.col(k);
      X.col(j) /= R(j, j);
    }
  });
}

// New eigenphases matched to the lifted old ones (nearest on the circle) and lifted.
Eigen::VectorXd lift(const Eigen::VectorXd& before, const Eigen::VectorXd& phases) {
  const int m = static_cast<int>(phases.size());
  std::array<bool, 12> used{};
  Eigen::VectorXd lifted(m);
  for (int j = 0; j < m; ++j) {
    int best = -1;
    double best_move = 0.0;
    for (int k = 0; k < m; ++k) {
      if (used[k]) continue;
      const double move = wrap(phases[k] - before[j]);
      if (best < 0 || std::abs(move) < std::abs(best_move)) best = k, best_move = move;
    }
    used[best] = true;
    lifted[j] = before[j] + best_move;
  }
  return lifted;
}

// Records the step from f (phases track->lifted) to s1 (phases `phases`): lifts them (lift), and a
// phase within 1e-9 of an odd multiple of pi is put on it: a field that stays at a conjugate point
// (held at s = 0, or abnormal) then never passes it by round-off. Passages downwards are located
// (locate_passage) and pushed, passages back upwards pop.
void StabilityAnalysis::record(const Frame& f, const Eigen::VectorXd& phases, double s1, PhaseTrack* track) {
  const Eigen::VectorXd before = track->lifted;
  const int m = static_cast<int>(phases.size());
  Eigen::VectorXd lifted = lift(before, phases);
  for (int j = 0; j < m; ++j) {
    const double off = wrap(lifted[j] - kPi);
    if (std::abs(off) < 1e-9) lifted[j] -= off;
  }
  const double h = 1e-3;  // a passage back needs a move well beyond round-off
  for (int j = 0; j < m; ++j) {
    auto& stack = track->passages[j];
    const double lo = std::min(lifted[j], before[j]), hi = std::max(lifted[j], before[j]);
    const int passed = odd_multiples_between(lo, hi);
    const long first = first_odd_multiple_above(lo);  // lowest m of (2m+1) pi passed
    for (int k = 0; k < passed; ++k) {
      const long multiple = 2 * (lifted[j] < before[j] ? first + passed - 1 - k : first + k) + 1;
      if (lifted[j] < before[j]) {
        const double ta = std::tan(0.5 * (before[j] - multiple * kPi)), tb = std::tan(0.5 * (lifted[j] - multiple * kPi));
        stack.emplace_back(multiple, locate_passage(f, before, j, multiple, f.s, s1, ta, tb));
      }
      else if (!stack.empty() && stack.back().first == multiple) stack.pop_back();
    }
    track->lowest[j] = std::min(track->lowest[j], lifted[j]);
    if (!track->reversed && odd_multiples_between(track->lowest[j] + h, lifted[j] - h) > 0) {
      track->reversed = true;
      track->reversed_at = s1;
    }
  }
  track->lifted = lifted;
}

// Where eigenphase j passes multiple * pi within (a, b), f.s <= a < b: near a passage the phase
// goes as k pi - 2 atan(c (s - s*)), so t(s) = tan of half its offset is close to linear in s, from
// ta > 0 at a to tb < 0 at b. Regula falsi on t (the Illinois variant, so that an end kept twice
// does not stall it), each t from the frame carried from f to the trial point and its phases
// lifted against `reference` (those at a: no phase moves by max_phase_step between a and b),
// until the estimate moves less than passage_tolerance: the position is then exact to the fields'
// integration, not to a step's interpolation. The trial frames are not kept (the march goes on
// from the step's end).
double StabilityAnalysis::locate_passage(const Frame& f, const Eigen::VectorXd& reference, int j, long multiple,
                                         double a, double b, double ta, double tb) {
  const double tolerance = options_.passage_tolerance * scales_.length;
  double estimate = a + ta / (ta - tb) * (b - a);
  int kept = 0;  // the end the last step kept: +1 a, -1 b
  for (int i = 0; i < options_.max_locating_steps && b - a > tolerance; ++i) {
    CarriedSteps steps{estimate - f.s, estimate - f.s};  // one integration step to the trial point
    flowed(f, estimate, &steps, true, &trial_);
    canonical_blocks(&trial_);
    orthonormalise(&trial_);
    const double t = std::tan(0.5 * (lift(reference, eigenphases(trial_.U, trial_.P, true))[j] - multiple * kPi));
    if (t > 0) {
      a = estimate, ta = t;
      if (kept == -1) tb *= 0.5;  // b kept twice
      kept = -1;
    } else {
      b = estimate, tb = t;
      if (kept == 1) ta *= 0.5;
      kept = 1;
    }
    const double next = a + ta / (ta - tb) * (b - a);
    const bool converged = std::abs(next - estimate) < tolerance || t == 0.0;
    estimate = t == 0.0 ? estimate : next;
    if (converged) break;
  }
  return estimate;
}

// The equilibrium, the frame's fields and the particular fields that have started carried to s1,
// as one integration continued from the previous step's (*steps): the fields are the directions
// of the variational equations, so only they are integrated, not the whole of Phi. Particular
// fields that have not started yet are zero, and stay so; frame_only leaves all of them behind
// (the trial frames of locate_passage need U and P alone).
void StabilityAnalysis::flowed(const Frame& f, double s1, CarriedSteps* steps, bool frame_only, Frame* next) {
  std::array<int, 16> started;
  int count = 0;
  for (int c = 0; !frame_only && c < f.particular.cols(); ++c)
    if (!f.particular.col(c).isZero(0.0)) {
      if (count == static_cast<int>(started.size())) throw std::logic_error("stability: more than 16 multipliers");
      started[count++] = c;
    }
  const int m = static_cast<int>(f.dY.cols());
  directions_.resize(f.dY.rows(), m + count);
  directions_.leftCols(m) = f.dY;
  for (int i = 0; i < count; ++i) directions_.col(m + i) = f.particular.col(started[i]);
  DirectionalFlow flow =
      eq_->flow_directions(f.y, directions_, f.s, s1, field_integrator_, steps);
  rhs_ += flow.rhs_evaluations;
  ++flows_;
  next->y.swap(flow.y);
  next->s = s1;
  next->slope_at = std::numeric_limits<double>::quiet_NaN();
  next->dY = flow.directions.leftCols(m);
  next->particular.setZero(f.particular.rows(), frame_only ? 0 : f.particular.cols());
  for (int i = 0; i < count; ++i) next->particular.col(started[i]) = flow.directions.col(m + i);
  if (frame_only) return;
  next->recorded_rows_frame = f.recorded_rows_frame;
  next->recorded_rows_particular = f.recorded_rows_particular;
}

// Marches the frame to `end` (a shooting node, a contact or L) in the integration's own steps,
// up to kInterpolatedSteps times `longest` (the rate's step, carry_across), each observed in
// between on its interpolant at most `observed` apart
// (interpolated_step); a step in which an eigenphase comes near a conjugate point, or whose
// interpolant cannot be followed, is marched again in observation steps of their own
// (march_observed), which locate the passage on exact frames. Where the sliding partners of a
// self-contact are tracked (track_barrier), every observation is of an exact state.
void StabilityAnalysis::march(Frame* f, double end, double longest, double observed, PhaseTrack* track) {
  if (barrier_eq_ || !options_.interpolated_observations) return march_observed(f, end, observed, track);
  const double sliver = 1e-12 * scales_.length;
  if (!(steps_.directions > 0)) steps_.directions = observed;
  while (end - f->s > sliver) {
    const double s1 = step_end(f->s, end, std::min(kInterpolatedSteps * longest, steps_.directions));
    // Where the integration's step is not much longer than an observation step, the step is
    // observed at its end alone (the interpolant's slopes would cost more than they save).
    if (s1 - f->s < 1.5 * observation_step(observed)) advance(f, s1, track, 0);
    else if (!interpolated_step(f, s1, observed, track)) march_observed(f, s1, observed, track);
  }
}

// Marches the frame to `end` as one adaptive integration observed at the end of each of its own
// steps: each observation step is the step the integrator proposes (steps_), so none is cut
// short to land on a grid and its right-hand sides are those of the integration alone. At most
// `longest` (twice it where the phases move slowly, observation_step), so that no eigenphase turns
// by pi between two observations unseen (see run); the last steps are evened out to land on `end`.
void StabilityAnalysis::march_observed(Frame* f, double end, double longest, PhaseTrack* track) {
  const double sliver = 1e-12 * scales_.length;
  // The integration's first trial step is the observation step itself (not a fraction of it,
  // which the integrator would have to grow through several short steps).
  if (!(steps_.directions > 0)) steps_.directions = longest;
  while (end - f->s > sliver) {
    double h = observation_step(longest);
    if (steps_.directions > 0) h = std::min(h, steps_.directions);
    advance(f, step_end(f->s, end, h), track, 0);
  }
}

// The bound on the eigenphase's speed (per unit arclength) where it is proved, else empty: a
// planar rod (one eigenphase: the frame holds the rotation alone) whose force is the same all
// along it - uniform, inextensible, no field, no contact, so that n is its value at s = 0. With
// u the rotation's perturbation and p = dm L / (B_s rate) (Scales; B_s = scales_.bending),
//   u' = dm / B = (B_s rate / (L B)) p,   p' = -c (L / (B_s rate)) u,
// where c = dm'/dtheta = -(n x dr'/dtheta).e_z, |c| <= |n| |v_hat| (r' = R v_hat). So u + ip turns
// at most at the larger coefficient, and W = (u + ip) / (u - ip) at twice that.
std::optional<double> StabilityAnalysis::phase_speed_bound(const std::vector<PointContact>& contacts) const {
  const RodModel& model = eq_->model();
  if (!options_.bounded_observations || !eq_->is_planar() || full_ || mU_ != 1 || !contacts.empty() || barrier_eq_ ||
      model.field || model.extensible || !model.is_uniform() || profile_.empty())
    return std::nullopt;
  const double B = model.B[1](0.0), L = scales_.length, Bs = scales_.bending, rate = scales_.rate;
  const double v_hat = std::hypot(model.v_hat[0](0.0), model.v_hat[2](0.0));
  const double c = profile_.front().n.norm() * v_hat;
  return 2.0 * std::max(Bs * rate / (L * B), c * L / (Bs * rate));
}

// Marches the frame to `end` in equal observation steps over which the eigenphase moves at most
// kBoundedPhaseMove (phase_speed_bound): each observed on an exact frame, the passages located on
// exact frames too (record).
void StabilityAnalysis::march_bounded(Frame* f, double end, PhaseTrack* track) {
  const double sliver = 1e-12 * scales_.length;
  const double h = kBoundedPhaseMove / (*phase_speed_bound_ * options_.observation_density);
  if (!(steps_.directions > 0)) steps_.directions = h;
  while (end - f->s > sliver) advance(f, step_end(f->s, end, h), track, 0);
}

// Whether an eigenphase moving from `from` to `to` (lifted) passes an odd multiple of pi or
// comes within kPassageMargin of one: there march_observed takes over.
bool StabilityAnalysis::near_passage(const Eigen::VectorXd& from, const Eigen::VectorXd& to) const {
  for (int j = 0; j < from.size(); ++j) {
    const double lo = std::min(from[j], to[j]) - kPassageMargin, hi = std::max(from[j], to[j]) + kPassageMargin;
    if (odd_multiples_between(lo, hi) > 0) return true;
  }
  return false;
}

// Whether each eigenphase moving from `from` at a to `to` at b (lifted, one observation step on an
// interpolant) stays kPassageMargin clear of the odd multiples of pi, or passes one of them
// downwards (the Legendre direction) with both observations kPassageMargin clear of it; those
// passages are appended to `seen`. The interpolant's phases are good to a third of the margin
// (interpolant_is_close), so the exact ones bracket the same multiple: counting it and locating it
// on exact frames (locate_passage) needs no march in observation steps. A phase that ends near a
// multiple or moves upwards past one is neither: march_observed follows it on exact frames.
bool StabilityAnalysis::clear_or_clean_passage(const Eigen::VectorXd& from, const Eigen::VectorXd& to, double a,
                                               double b, std::vector<SeenPassage>* seen) const {
  for (int j = 0; j < from.size(); ++j) {
    const double lo = std::min(from[j], to[j]), hi = std::max(from[j], to[j]);
    const int near = odd_multiples_between(lo - kPassageMargin, hi + kPassageMargin);
    if (near == 0) continue;
    if (!(to[j] < from[j]) || near != 1 || odd_multiples_between(lo + kPassageMargin, hi - kPassageMargin) != 1)
      return false;
    const long multiple = 2 * first_odd_multiple_above(lo) + 1;
    seen->push_back({j, multiple, a, b, std::tan(0.5 * (from[j] - multiple * kPi)),
                     std::tan(0.5 * (to[j] - multiple * kPi)), from});
  }
  return true;
}

// The frame's slopes (Frame::y_slope, dY_slope) where not known yet: the right-hand side, and its
// derivatives along the fields by forward differences (to ~1e-7 of the fields, far below what
// observing their eigenphases on an interpolant needs). One right-hand side each. (The frame's
// orthonormalisation then keeps them, as it does the fields.)
void StabilityAnalysis::slopes(Frame* f) {
  if (f->slope_at == f->s) return;
  f->y_slope = eq_->derivative(f->y, f->s);
  f->dY_slope.resize(f->dY.rows(), f->dY.cols());
  const double size = std::max(1.0, f->y.norm());
  for (Eigen::Index j = 0; j < f->dY.cols(); ++j) {
    const double norm = f->dY.col(j).norm();
    const double e = norm > 0 ? 1e-7 * size / norm : 0.0;
    if (e > 0) f->dY_slope.col(j) = (eq_->derivative(f->y + e * f->dY.col(j), f->s) - f->y_slope) / e;
    else f->dY_slope.col(j).setZero();
  }
  f->slope_at = f->s;
  rhs_ += 1 + f->dY.cols();
}

// The state and the fields at a fraction t of the way from frame a to frame b, on their cubic
// Hermite interpolant (the slopes at both ends known). The particular fields are not observed.
void hermite(const Frame& a, const Frame& b, double t, Frame* out) {
  const double h = b.s - a.s, t2 = t * t, t3 = t2 * t;
  const double at_a = 2 * t3 - 3 * t2 + 1, slope_a = (t3 - 2 * t2 + t) * h, slope_b = (t3 - t2) * h;
  out->s = a.s + t * h;
  out->y = at_a * a.y + slope_a * a.y_slope + (1 - at_a) * b.y + slope_b * b.y_slope;
  out->dY = at_a * a.dY + slope_a * a.dY_slope + (1 - at_a) * b.dY + slope_b * b.dY_slope;
  if (out->particular.rows() != a.y.size()) out->particular.resize(a.y.size(), 0);  // (a default-made frame)
}

// One integration step of the fields from f to s1, their eigenphases observed in between on the
// cubic Hermite interpolant of the state and the fields (the slopes at both ends), in sub-steps
// on which no phase moves more than max_phase_step. Integration steps up to kInterpolatedSteps
// observation steps long turn the fields by ~1 rad at the rate's estimate: the interpolant is
// good to ~(1 rad)^4 / 384, 3e-3, and the phases to about twice that, inside kPassageMargin.
// That is checked, not assumed (interpolant_is_close). The step is taken (f moves to s1, the
// phases recorded) where every phase stays that margin clear of the odd multiples of pi or passes
// one cleanly (clear_or_clean_passage), so that no conjugate point can hide in the interpolant's
// error; the passages are then located on exact frames. False (f and the track unchanged)
// otherwise, and where the sub-steps would be shorter than 1 / 256 of the step.
bool StabilityAnalysis::interpolated_step(Frame* f, double s1, double observed, PhaseTrack* track) {
  if (near_passage(track->lifted, track->lifted)) return false;
  const CarriedSteps before = steps_;
  Frame& next = arriving_;
  flowed(*f, s1, &steps_, false, &next);
  slopes(f);
  slopes(&next);
  if (!interpolant_is_close(*f, next)) {
    steps_ = before;
    return false;
  }
  Eigen::VectorXd lifted = track->lifted, lowest = track->lowest;
  const Observation before_step = last_observation_;
  const double h = s1 - f->s;
  double t = 0.0, dt = std::min(1.0, observation_step(observed) / h);
  seen_.clear();
  while (t < 1.0) {
    const double t1 = std::min(1.0, t + dt);
    if (t1 < 1.0) hermite(*f, next, t1, &interpolated_);
    else interpolated_ = next;
    canonical_blocks(&interpolated_);
    // Only the frame arrived at is kept (and so kept orthonormal); eigenphases() takes the
    // others' plane as it is.
    const bool arrived = t1 == 1.0;
    const bool det_flipped = arrived && determinant_flipped(*f, interpolated_);
    if (arrived) orthonormalise(&interpolated_);
    const Eigen::VectorXd phases = lift(lifted, eigenphases(interpolated_.U, interpolated_.P, arrived));
    const double largest = phases.size() == 0 ? 0.0 : (phases - lifted).cwiseAbs().maxCoeff();
    if (largest > max_phase_step_ && dt > 1.0 / 256) {
      dt *= 0.5;
      continue;
    }
    if (largest > max_phase_step_ || !clear_or_clean_passage(lifted, phases, f->s + t * h, f->s + t1 * h, &seen_) ||
        (arrived && det_flipped != (seen_.size() % 2 == 1))) {
      steps_ = before;
      last_observation_ = before_step;
      return false;
    }
    lifted = phases;
    lowest = lowest.cwiseMin(phases);
    last_observation_ = {(t1 - t) * h, largest};
    t = t1;
    dt = std::min(2.0 * dt, largest > 0 ? dt * kAimedPhaseMove * max_phase_step_ / largest : 2.0 * dt);
  }
  for (const SeenPassage& p : seen_)
    track->passages[p.j].emplace_back(p.multiple, locate_passage(*f, p.reference, p.j, p.multiple, p.a, p.b, p.ta, p.tb));
  std::swap(*f, interpolated_);
  track->lifted = lifted;
  track->lowest = lowest;
  return true;
}

// Whether the cubic Hermite interpolant of each field between frames a and b (its slopes known)
// is good to a few 1e-3 of it: its cubic term D = h (Y'(a) + Y'(b)) - 2 (Y(b) - Y(a)), which for
// a field turning by x rad over the step is x^3 / 6 of it, at most 0.25 (x < 1.15), where the
// interpolant's own error, x^4 / 384, is below 4.5e-3, and the eigenphases' (W is quadratic in
// the fields) below 0.009, a third of kPassageMargin.
bool StabilityAnalysis::interpolant_is_close(const Frame& a, const Frame& b) const {
  const double h = b.s - a.s;
  for (Eigen::Index j = 0; j < a.dY.cols(); ++j) {
    const double cubic = (h * (a.dY_slope.col(j) + b.dY_slope.col(j)) - 2.0 * (b.dY.col(j) - a.dY.col(j))).norm();
    if (!(cubic <= 0.25 * std::max(a.dY.col(j).norm(), b.dY.col(j).norm()))) return false;
  }
  return true;
}

// The next observation step: `longest` (the fields' rate's, carry_across) where nothing is
// known yet, else the last one scaled so that the eigenphases would move about kAimedPhaseMove
// max_phase_step over it (growing at most twofold), between a quarter of `longest` and twice it.
// Where the phases turn slower than the rate allows (most of a twisted rod), fewer observations
// serve. None passes a turn unseen: a move of 2 pi - max_phase_step would look like one of
// max_phase_step, beyond which advance() halves the step, so a phase would have to turn over 20
// times faster than over the last step, where the rate's steps (L / (4 rate), at most twice
// them here) keep the estimated move near 0.5 rad.
double StabilityAnalysis::observation_step(double longest) const {
  const Observation& last = last_observation_;
  if (!(last.step > 0)) return longest;
  const double target = kAimedPhaseMove * max_phase_step_;
  const double grown = last.move > 0 ? last.step * std::min(2.0, target / last.move) : 2.0 * last.step;
  return std::clamp(grown, 0.25 * longest, 2.0 * longest);
}

// det A, written out up to 3 x 3 (the rotation blocks of planar and spatial rods), where the
// dynamic-size LU would allocate at every observation.
double small_determinant(const Eigen::MatrixXd& A) {
  switch (A.rows()) {
    case 1: return A(0, 0);
    case 2: return A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
    case 3: return A.topLeftCorner<3, 3>().determinant();
    default: return A.determinant();
  }
}

// Whether det U changed sign from frame `from` to `to`, the fields carried from it (to's U before
// it is orthonormalised: the columns are then the same fields, continuous in s in between).
// U(s) is singular exactly at conjugate points, so its determinant changes sign an odd number of
// times where an odd number of eigenphases pass odd multiples of pi, counted with multiplicity.
bool StabilityAnalysis::determinant_flipped(const Frame& from, const Frame& to) {
  if (from.U.size() == 0) return false;
  return (small_determinant(from.U) < 0) != (small_determinant(to.U) < 0);
}

// Whether the passages of the lifted eigenphases from `from` to `to` contradict the parity of det
// U's sign changes over the step. A phase that turns a whole turn between two observations (a
// field whose momentum is small against its rotation in the canonical scales, as the soft bending
// of a rod much stiffer in its other direction: the lateral-torsional buckling of a 3D cantilever,
// whose passages then take a thousandth of the rod) looks from its ends like a small move, and
// its conjugate point was lost; det U still changed sign. Not decided where a phase lies within
// 1e-6 of an odd multiple of pi at either end (det U then within round-off of zero).
bool StabilityAnalysis::parity_contradicted(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                            bool det_flipped) {
  int passages = 0;
  for (Eigen::Index j = 0; j < from.size(); ++j) {
    if (std::abs(wrap(from[j] - kPi)) < 1e-6 || std::abs(wrap(to[j] - kPi)) < 1e-6) return false;
    passages += odd_multiples_between(std::min(from[j], to[j]), std::max(from[j], to[j]));
  }
  return det_flipped != (passages % 2 == 1);
}

// One observation step, halved while an eigenphase moves more than max_phase_step over it as
// record() pairs them (so that it pairs none wrongly, nor misses a turn), or while its passages
// contradict det U's change of sign (parity_contradicted).
void StabilityAnalysis::advance(Frame* f, double s1, PhaseTrack* track, int depth) {
  const CarriedSteps before = steps_;
  Frame& next = arriving_;
  flowed(*f, s1, &steps_, false, &next);
  canonical_blocks(&next);
  const bool det_flipped = determinant_flipped(*f, next);
  orthonormalise(&next);
  const Eigen::VectorXd phases = eigenphases(next.U, next.P, true);
  // The moves of the phases as record() pairs them: where two phases come close, a long step can
  // pair them wrongly though each lies near some new phase.
  const Eigen::VectorXd lifted = lift(track->lifted, phases);
  const double largest = phases.size() == 0 ? 0.0 : (lifted - track->lifted).cwiseAbs().maxCoeff();
  const bool parity_fails = parity_contradicted(track->lifted, lifted, det_flipped);
  if ((largest > max_phase_step_ || parity_fails) && depth < options_.max_halvings) {
    const double mid = 0.5 * (f->s + s1);
    steps_ = before;  // the halves continue from f, not from the step taken past them
    advance(f, mid, track, depth + 1);
    advance(f, s1, track, depth + 1);
    return;
  }
  if (parity_fails && !track->unresolved) {
    track->unresolved = true;
    track->unresolved_at = s1;
  }
  record(*f, phases, s1, track);
  last_observation_ = {s1 - f->s, largest};
  std::swap(*f, next);  // (next keeps f's storage for the following step)
  if (barrier_eq_ && sliding_reason_.empty())
    sliding_reason_ = kirchhoff::sliding_reason(*barrier_eq_, eq_->point(f->y, f->s), options_.zero_tolerance);
}

// Across a point contact (normal nu, force f > 0, the rod curving away from the obstacle):
//  - the equilibrium's force jumps by -f nu; in the load-controlled problem the contact force is
//    a dead load on its material point, so the fields' dn is continuous;
//  - the contact point slides along the obstacle: to second order the rod stays off it iff the
//    minimum over s of its gap G(s) = g(r(s)) does. With G(s_c) = G'(s_c) = 0 and G''(s_c) > 0,
//      min_s G = dG(s_c) + 1/2 d2G(s_c) - (dG'(s_c))^2 / (2 G''(s_c))  (to second order),
//    and the Lagrangian E - lambda min_s G (lambda = f / |grad g|) gains, per unit |grad g|,
//      f (nu.dr' + k.dr)^2 / (2 g'') - f dr.K dr / 2,
//    K = Hess g / |grad g| the obstacle's curvature, k = K d3, nu.dr' = dpsi.(d3 x nu) and
//    g'' = nu.d3' + d3.K d3 the rate at which the rod curves away from the obstacle (relative
//    to it). On a plane K = 0: f (nu.dr')^2 / (2 g''). The curvature term is the multiplier
//    times the constraint's curvature: a convex obstacle (K >= 0) lets a tangential shift open
//    the gap, which lowers the energy. (Holding the contact at its material point instead leaves
//    out the sliding term and gives another, wrong count.) For the fields, a point quadratic
//    form 1/2 z.S z of z = (dr, dpsi) is a jump of the momenta (dn, dm) += S z: a shear
//    p += S u that leaves U, so no conjugate point; on a curved obstacle it holds dr, which only
//    the full frame carries;
//  - nu.dr(s_c) = 0 is one more isoperimetric constraint, its multiplier the change of the force:
//    its particular field starts here with dn = -nu.
std::string StabilityAnalysis::pass_contact(Frame* f, const PointContact& contact, int number, PhaseTrack* track,
                                            double* shear) {
  const int n = coords_.size(), kr = coords_.kr();
  const RodPoint here = eq_->point(f->y, f->s);
  const Obstacle obstacle = problem_.obstacles(p_)[contact.obstacle];  // obstacles() returns a copy
  const Vec3 nu = obstacle.normal(here.r);
  const Mat3 K = obstacle.hessian(here.r) / obstacle.gradient(here.r).norm();
  const Vec3 d3 = here.R.col(2), curving = here.R * here.u.cross(Vec3::UnitZ());  // d3' of an inextensible rod
  const double g2 = nu.dot(curving) + d3.dot(K * d3), scale = 1.0 / scales_.length;
  if (!(contact.force > 1e-10 * scales_.bending / (scales_.length * scales_.length)))
    return "a contact with zero force (weakly active): the index depends on higher-order terms, not defined here";
  // Judged on the equilibrium at the state's tolerance too (contact_bending), not only on the
  // frame's state, integrated with the fields at theirs (a branch's 1e-8): at the wall's
  // contact_flattens, located where g'' = 1e-13, the frame gave 1.8e-8 and the row an index.
  const double g2_state = problem_.contact_bending(x_, contact) / obstacle.gradient(here.r).norm();
  if (!(g2 > 1e-9 * scale) || !(g2_state > 1e-9 * scale))
    return "a contact where the rod does not curve away from the obstacle (g'' = 0: it is about to flatten or wrap "
           "onto it)";
  if (!full_ && K.norm() > 0) throw std::logic_error("stability: a curved obstacle needs the full frame");
  const Eigen::VectorXd nu_r = coords_.position_dirs.transpose() * nu;
  f->recorded_rows_frame.row(recorded_before_contacts_ + number) = nu_r.transpose() * f->R;
  f->recorded_rows_particular.row(recorded_before_contacts_ + number) = nu_r.transpose() * f->particular_R;
  // The equilibrium's jump.
  f->y += eq_->slot_map(Slot::Force).transpose() * (-contact.force * nu);
  // The point form on z = (dr, dpsi) in the lab: S = (f / g'') a a^T - f diag(K, 0), a = (k, w).
  Eigen::Matrix<double, 6, 1> a;
  a << K * d3, d3.cross(nu);
  Eigen::Matrix<double, 6, 6> S_lab = Eigen::Matrix<double, 6, 6>::Zero();
  if (options_.contact_sliding) S_lab += (contact.force / g2) * a * a.transpose();
  S_lab.topLeftCorner<3, 3>() -= contact.force * K;
  const Eigen::MatrixXd S = canonical_shear(S_lab, *f);
  *shear = S.norm();
  // The shear leaves U, so no eigenphase passes -1 through it: each stays in its sheet between
  // consecutive odd multiples of pi (it may turn almost a whole turn inside it, so it is not
  // followed by small steps, which could not tell such a turn from a small one back).
  const Eigen::VectorXd sheared = eigenphases(f->U, f->P + S * f->U, false);
  std::vector<bool> used(sheared.size(), false);
  for (int j = 0; j < track->lifted.size(); ++j) {
    const double sheet = 2 * kPi * std::round(track->lifted[j] / (2 * kPi));
    int best = -1;
    for (int k = 0; k < sheared.size(); ++k)
      if (!used[k] && (best < 0 || std::abs(wrap(sheared[k] - track->lifted[j])) <
                                       std::abs(wrap(sheared[best] - track->lifted[j]))))
        best = k;
    used[best] = true;
    track->lifted[j] = sheet + sheared[best];
    track->lowest[j] = std::min(track->lowest[j], track->lifted[j]);
  }
  // The same jump on the fields' state, (dn, dm) += S_lab (dr, dpsi): on the frame and on the
  // particular fields that have started (they are Jacobi fields of the same system; leaving them
  // out makes D = dg/dlambda lose its symmetry).
  Eigen::MatrixXd to_lab(6, f->dY.rows());
  to_lab << eq_->slot_map(Slot::Position), lab_rotation_jacobian(*eq_, f->y, here.R);
  Eigen::MatrixXd from_lab(f->dY.rows(), 6);
  from_lab << eq_->slot_map(Slot::Force).transpose(), eq_->slot_map(Slot::Moment).transpose();
  const Eigen::MatrixXd jump = from_lab * S_lab * to_lab;
  f->dY += jump * f->dY;
  f->particular += jump * f->particular;
  // The force's particular field.
  Eigen::VectorXd z = Eigen::VectorXd::Zero(2 * n);
  z.segment(n, kr) = -nu_r;
  const CanonicalMap map = canonical_map(*eq_, coords_, scales_, f->y, f->s);
  f->particular.col(start_multipliers_ + number) = map.T.completeOrthogonalDecomposition().solve(z);
  canonical_blocks(f);
  orthonormalise(f);
  return "";
}

// z = (dr, dpsi) in the lab is (L position_dirs u_r, rotation_dirs u_psi) in the frame's U
// coordinates, and the momenta (dn, dm) are scaled by (L^2, L) / (B rate): S_c = L / (B rate)
// J^T S J with J = diag(L position_dirs, rotation_dirs) - symmetric, as a point form must be.
// The rotation-only frame keeps the rotation block (S has no position part there).
Eigen::MatrixXd StabilityAnalysis::canonical_shear(const Eigen::MatrixXd& lab_S, const Frame& at) const {
  const int kr = coords_.kr(), kpsi = coords_.size() - kr;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, coords_.size());
  J.topLeftCorner(3, kr) = scales_.length * coords_.position_dirs;
  // (Balanced coordinates: dpsi = A^-1 u.)
  if (scales_.stiffness_min > 0) J.bottomRightCorner(3, 3) = coords_.rotation_dirs * balancing_at(at.y, at.s).inverse();
  else J.bottomRightCorner(3, kpsi) = coords_.rotation_dirs;
  const Eigen::MatrixXd S = (scales_.length / (scales_.bending * scales_.rate)) * J.transpose() * lab_S * J;
  return S.bottomRightCorner(mU_, mU_);
}

// A dead couple on an end free to turn about two or more axes does work that depends on the path
// of the rotation (Ziegler): not conservative, and the second variation is not defined. In the
// canonical coordinates the end's natural conditions then fail to be a Lagrangian plane. The test
// is relative to the zero tolerance, not round-off: where the couple's work vanishes because the
// equilibrium makes it so (the antisymmetric half of a half-turn end, free to turn across the axis:
// the work is m.a, zero to the solve's tolerance, ~1e-9 of |m|), that is what zero means.
std::string StabilityAnalysis::end_moment_reason(const Frame& f, const Held& end) const {
  const CanonicalMap map = canonical_map(*eq_, coords_, scales_, f.y, f.s);
  const Eigen::MatrixXd G = map.G.bottomRightCorner(mU_, mU_);
  const Eigen::MatrixXd free_rotation = complement(held_configuration(end), mU_);
  if ((free_rotation.transpose() * G * free_rotation).norm() > options_.zero_tolerance * (1.0 + G.norm()))
    return "the end's loads are not conservative (a dead couple on an end free to rotate in 3D)";
  return "";
}

// Conjugate points in (0, L): net passages of the lifted eigenphases from start to end. Fields
// with U c = 0 at s = L end exactly on a conjugate point, which is not inside (0, L).
bool StabilityAnalysis::count_interior(const Frame& f, const PhaseTrack& track, const Eigen::VectorXd& start,
                                       StabilityReport* report) const {
  const int m = static_cast<int>(f.U.cols());
  Eigen::VectorXd end = track.lifted;
  const int at_end = m - static_cast<int>(column_basis(f.U, options_.zero_tolerance).cols());
  std::vector<int> order(m);
  for (int j = 0; j < m; ++j) order[j] = j;
  auto distance_to_odd = [&](double t) { return std::abs(wrap(t - kPi)); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return distance_to_odd(end[a]) < distance_to_odd(end[b]); });
  for (int k = 0; k < at_end; ++k) end[order[k]] -= wrap(end[order[k]] - kPi);
  int interior = 0;
  for (int j = 0; j < m; ++j) {
    const double a = std::min(start[j], end[j]) + 1e-9, b = std::max(start[j], end[j]) - 1e-9;
    const int passed = a < b ? odd_multiples_between(a, b) : 0;
    interior += end[j] <= start[j] ? passed : -passed;
  }
  if (interior < 0) {
    report->reason = "the conjugate-point count came out negative: the Jacobi system is degenerate";
    report->resolution_limited = true;
    return false;
  }
  report->interior_count = interior;
  // Where: the passages left on the stacks. When round-off made them disagree with the count,
  // no positions are claimed.
  for (int j = 0; j < m; ++j)
    for (const auto& passage : track.passages[j])
      if (passage.second < scales_.length * (1 - 1e-9)) report->conjugate_points.push_back(passage.second);
  std::sort(report->conjugate_points.begin(), report->conjugate_points.end());
  if (static_cast<int>(report->conjugate_points.size()) != interior) report->conjugate_points.clear();
  return true;
}

// The count at s = L for the load-controlled problem: negative directions of q(c) = (P c).(U c)
// over the fields meeting the held rotations, and the fields with U c = 0 whose natural (dead
// moment) conditions fail, which are negative just before L. Returns the zero modes (fields
// meeting every condition) as frame coefficients.
Eigen::MatrixXd StabilityAnalysis::end_terms(const Frame& f, const Held& end, StabilityReport* report) const {
  const int m = static_cast<int>(f.U.cols());
  const double tol = options_.zero_tolerance;
  const Eigen::MatrixXd held = held_configuration(end);
  const Eigen::MatrixXd free_rotation = complement(held, m);
  const Eigen::MatrixXd kernel_U = null_space(f.U, m, tol);
  const Eigen::MatrixXd admissible = null_space(held.transpose() * f.U, m, tol);
  const Eigen::MatrixXd rest = column_basis(admissible - kernel_U * (kernel_U.transpose() * admissible));
  const Eigen::MatrixXd q = f.P.transpose() * f.U;
  const Eigen::MatrixXd q_rest = rest.transpose() * (0.5 * (q + q.transpose())) * rest;
  int negative = 0;
  if (q_rest.rows() > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(q_rest);
    for (int i = 0; i < eig.eigenvalues().size(); ++i)
      if (eig.eigenvalues()[i] < -tol) ++negative;
  }
  const Eigen::MatrixXd natural_failure = free_rotation.transpose() * f.P_physical * kernel_U;
  report->end_count = negative + static_cast<int>(column_basis(natural_failure, tol).cols());
  Eigen::MatrixXd conditions(held.cols() + free_rotation.cols(), m);
  conditions << held.transpose() * f.U, free_rotation.transpose() * f.P_physical;
  return null_space(conditions, m, tol);
}

// The load-controlled problem's modes as the isoperimetric correction sees them. Each mode j
// (singular triplet u_j, sigma_j, v_j of the end conditions) adds to D the part
// -g_j (u_j.loads) / sigma_j, g_j its chord change.
//  - `exact`: the modes below the zero tolerance enter as exact zero modes (r_Z, and D on the
//    loads that do no work on them) - the limit sigma -> 0 at a fixed g, right where their part
//    outgrows the rest of D (and where sigma is zero to round-off). Where it does not, such a
//    mode is near zero without being one - an isotropic rod's turn about its axis as its twist
//    goes to zero, sigma ~ twist^2 and g ~ twist, so that g^2 / sigma stays finite - and D is
//    taken with it, as with any other mode: counting it as exact there gave the plectoneme arch at
//    turns 1e-6 .. 2.5e-4 index 1 between index 0 at turns 0 and past 2.6e-4.
//  - `resolution(v, floor)`: how far an eigenvalue of D along v is known: `floor` (below) plus, for
//    each part, the relative error of its sigma_j, `noise` of the largest over sigma_j: on the
//    plectoneme arch a part of 0.04 through sigma = 2e-11 of 0.36 came out 12 % off, and with the
//    fields at a branch's 1e-8 one through sigma = 8e-6 left D = 1e-5 where the rod's turn makes
//    it 0.
struct NearZeroModes {
  bool exact = false;
  // Whether the modes between round-off and the tolerance are exact too (their part of D outgrows
  // the rest), not only those the decomposition drops.
  bool exact_below_tolerance = false;
  Eigen::MatrixXd dropped;  // the modes the decomposition drops (dropped_modes), frame coefficients
  std::vector<std::pair<Eigen::MatrixXd, double>> parts;  // (symmetrised part, its relative error)
  double resolution(const Eigen::VectorXd& v, double floor) const {
    double r = floor;
    for (const auto& [part, error] : parts) r += error * std::abs(v.dot(part * v));
    return r;
  }
};

// The right singular vectors of the end conditions that the decomposition drops (round-off zeros).
Eigen::MatrixXd dropped_modes(const Eigen::JacobiSVD<Eigen::MatrixXd>& svd) {
  const Eigen::VectorXd& sigma = svd.singularValues();
  std::vector<Eigen::Index> dropped;
  for (Eigen::Index j = 0; j < sigma.size(); ++j)
    if (sigma[j] <= kRoundOffZero * sigma[0]) dropped.push_back(j);
  Eigen::MatrixXd out(svd.matrixV().rows(), static_cast<Eigen::Index>(dropped.size()));
  for (size_t i = 0; i < dropped.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = svd.matrixV().col(dropped[i]);
  return out;
}

// `svd`: the end conditions' (full U and V).
NearZeroModes near_zero_modes(const Eigen::JacobiSVD<Eigen::MatrixXd>& svd, const Eigen::MatrixXd& loads,
                              const Eigen::MatrixXd& frame_values, const Eigen::MatrixXd& particular_values,
                              double tol, double noise) {
  NearZeroModes out;
  const Eigen::VectorXd& sigma = svd.singularValues();
  if (sigma.size() == 0) return out;
  out.dropped = dropped_modes(svd);
  out.exact = out.dropped.cols() > 0;
  Eigen::MatrixXd below = Eigen::MatrixXd::Zero(loads.cols(), loads.cols()), rest = particular_values;
  for (Eigen::Index j = 0; j < sigma.size(); ++j) {
    if (sigma[j] <= kRoundOffZero * sigma[0]) {  // dropped by the decomposition: no part of D
      out.parts.push_back({Eigen::MatrixXd::Zero(loads.cols(), loads.cols()), 0.0});
      continue;
    }
    const Eigen::MatrixXd part =
        -(frame_values * svd.matrixV().col(j)) * (svd.matrixU().col(j).transpose() * loads) / sigma[j];
    (sigma[j] <= tol ? below : rest) += part;
    out.parts.push_back({0.5 * (part + part.transpose()), noise * sigma[0] / sigma[j]});
  }
  // Compared on the loads that do no work on the dropped modes, whose chord changes leave D in any
  // case: on plectoneme.toml at slenderness 50 (positions in the frame) the near-zero mode's part
  // (g^2 / sigma, 4e6 at turns = 1e-4 and growing as turns^-2) lies along those, 2e6 times the
  // rest, but on the others it cancels the rest to leave the rod's turn about its axis as a zero
  // mode (D = -1e-6 at turns = 1e-3, the mode above the tolerance).
  const Eigen::MatrixXd quiet = null_space((frame_values * out.dropped).transpose(),
                                           static_cast<int>(loads.cols()), tol);
  out.exact_below_tolerance = (quiet.transpose() * below * quiet).norm() >
                              kExactZeroShare * std::max((quiet.transpose() * rest * quiet).norm(), tol);
  out.exact = out.exact || out.exact_below_tolerance;
  if (out.exact_below_tolerance)  // the modes below the tolerance are projected out of D (parts[j] is mode j's)
    for (Eigen::Index j = 0; j < sigma.size(); ++j)
      if (sigma[j] <= tol) out.parts[static_cast<size_t>(j)].second = 0.0;
  return out;
}

// The zero tolerance of an eigenvalue of D along v (unit): `tol` of the size of the terms D is
// made of along v, |v|.(|frame_values| |c| + |particular_values|) |v| - not of the sum, which cancels
// where D is near zero - and never more than `tol` itself. A constraint that the load barely moves
// is not a zero mode: on the soft wall's switched branch at log_b = -4, where the rod is all but
// straight (Delta ~ 8e-10), D's eigenvalue along the load that crosses zero at the fold at P =
// 112.1 is -1e-10 .. +9e-11 out of terms of 3e-10 .. 2e-9, smooth along the branch to three digits.
// Against the absolute tolerance 1e-6 it was taken as a zero mode from P = 104.7 to 119.2 (index
// 1 with a zero mode, where the discretised energy has 1 without one to the fold, 2 after it).
// (A direction whose terms all vanish, a constraint no load moves, never gets here: the
// degenerate-constraint test above leaves the index undefined first.)
double eigenvalue_floor(const Eigen::VectorXd& v, const Eigen::MatrixXd& frame_values, const Eigen::MatrixXd& c,
                        const Eigen::MatrixXd& particular_values, double tol) {
  const Eigen::VectorXd a = v.cwiseAbs();
  const double terms = a.dot((frame_values.cwiseAbs() * c.cwiseAbs() + particular_values.cwiseAbs()) * a);
  return tol * std::min(1.0, terms);
}

// An eigenvalue of D farther from zero than this many times its resolution is decisively not zero:
// it overrules the whole problem's null-space test (constraint_correction).
constexpr double kDecisiveResolutions = 10.0;

// Whether every singular value of the load-controlled conditions below the zero tolerance is zero
// to the fields' accuracy (below kExactLoadControlledZero of the largest). Between that and the
// tolerance a mode is near zero without being zero, and taking it as exact (r_Z, D on the loads
// doing no work on it) can lose the whole problem's zero mode: the soft wall's branch point at
// log_b = -4 (a conjugate point of the clamped problem 4e-8 from the end, singular value 2.6e-7)
// kept D's eigenvalues at -0.21 and 2.8e-3 while the whole problem is singular. The indenter's
// structural zero comes out at 1e-13 of the largest, at the state's tolerance as at a branch's 1e-8.
constexpr double kExactLoadControlledZero = 1e-10;
bool exact_load_controlled_zeros(const Eigen::VectorXd& sigma, double tol) {
  for (Eigen::Index j = 0; j < sigma.size(); ++j)
    if (sigma[j] <= tol && sigma[j] > kExactLoadControlledZero * sigma[0]) return false;
  return true;
}

// The whole problem's zero modes: frame fields c and load changes l with conditions c + loads l = 0
// and frame_values c + particular_values l = 0. The load columns are first reduced by the frame
// fields that answer them (c = -conditions^+ loads), a column operation that keeps the null space:
// they then carry the chord's response to the loads (D). The particular fields themselves grow
// with the frame's (as exp(sqrt(P) L) on a rod in tension) and lie within 1e-7 of the frame's span
// at s = L where D is 3e-3, the compliance of a string. Only the conditions' singular directions
// within 1e2 of the largest answer: a near-singular one (a conjugate point near L, as at a branch
// point) would amplify the matrix's error past the zero tolerance (the soft wall's branch point:
// smallest singular value 8e-8 unreduced, 2e-6 reduced through one of 2.4e-4).
// `svd`: the conditions' (full U and V).
int whole_problem_zero_modes(const Eigen::MatrixXd& conditions, const Eigen::JacobiSVD<Eigen::MatrixXd>& svd,
                             const Eigen::MatrixXd& loads, const Eigen::MatrixXd& frame_values,
                             const Eigen::MatrixXd& particular_values, double tol) {
  const Eigen::Index m = conditions.cols(), k = loads.cols();
  Eigen::MatrixXd answer = Eigen::MatrixXd::Zero(m, k);  // -conditions^+ loads, truncated
  if (m > 0 && k > 0) {
    for (Eigen::Index j = 0; j < svd.singularValues().size(); ++j)
      if (svd.singularValues()[j] > std::max(tol, 1e-2 * svd.singularValues()[0]))
        answer -= svd.matrixV().col(j) * (svd.matrixU().col(j).transpose() * loads) / svd.singularValues()[j];
  }
  Eigen::MatrixXd all(m + k, m + k);
  all << conditions, loads + conditions * answer, frame_values, particular_values + frame_values * answer;
  for (Eigen::Index i = m; i < m + k; ++i)
    if (all.row(i).norm() > 0) all.row(i) /= all.row(i).norm();
  return static_cast<int>(null_space(all, static_cast<int>(m + k), tol).cols());
}

// Of D's undecided eigenvalues (within kDecisiveResolutions of their resolution), the `zeros` closest
// to zero relative to their resolution are the whole problem's zero modes that change the chord: how
// many of those were counted positive. A zero mode is neither positive nor negative - counted
// positive as well, one eigenvalue entered the index twice (as the zero mode and through n_+(D)):
// on plectoneme.toml's ply at turns = 2.8293 the rod's turn about the clamps' axis had D's
// eigenvalue -2.4e-7, then 1.6e-5 a parameter step of 1e-9 further, at a resolution of 3e-6, and
// the index rose from 0 to 1 with the zero mode kept.
int undecided_counted_positive(std::vector<std::pair<double, bool>>* undecided, int zeros) {
  std::sort(undecided->begin(), undecided->end());
  int counted = 0;
  for (int i = 0; i < std::min<int>(zeros, static_cast<int>(undecided->size())); ++i) counted += (*undecided)[i].second;
  return counted;
}

// The isoperimetric correction (Maddocks; Manning, Rogers & Maddocks 1998): with the end
// positions held along k directions, index = index_dead + r_Z + n_+(D) - k, where D = dg/dF is how
// the chord g = r(L) - r(0) along them moves per unit change of the end load (the multiplier),
// along the load-controlled equilibria, and r_Z the rank of the chord change along the
// load-controlled problem's zero modes (D is then taken on the loads that do no work on them).
// Zero modes of the whole problem: fields meeting every condition, load changes included.
bool StabilityAnalysis::constraint_correction(const Frame& f, const Held& end, const Eigen::MatrixXd& constraints,
                                              const Eigen::MatrixXd& zero_modes, StabilityReport* report) const {
  const int m = static_cast<int>(f.U.cols());
  const double tol = options_.zero_tolerance;
  // Every isoperimetric constraint's value on the frame's fields and on the particular ones, in
  // the order of the multipliers (Frame::particular): the chord along the held directions at
  // s = L, then the contacts' nu.dr(s_c); with the full frame the start's held positions, the
  // contacts, then the end's held positions (`constraints` is then end.position).
  const int all_constraints = static_cast<int>(f.particular.cols());
  const int recorded = static_cast<int>(f.recorded_rows_frame.rows()), at_end = static_cast<int>(constraints.cols());
  Eigen::MatrixXd values(all_constraints, m + all_constraints);
  values.block(full_ ? recorded : 0, 0, at_end, m + all_constraints) << constraints.transpose() * f.R,
      constraints.transpose() * f.particular_R;
  values.block(full_ ? 0 : at_end, 0, recorded, m + all_constraints) << f.recorded_rows_frame,
      f.recorded_rows_particular;
  // A constraint that no perturbation changes to first order - the chord of a straight
  // inextensible rod held at its full length - is degenerate: it holds at second order only
  // (every perturbation shortens the chord), and its multiplier (the axial force) is
  // indeterminate though it enters the second variation. The index is then not defined.
  const Eigen::MatrixXd active = column_basis(values, tol);  // in constraint coordinates
  if (active.cols() < all_constraints) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(values);
    std::ostringstream why;
    why << "a degenerate constraint: a held chord (or contact) that perturbations change to first order by at most "
        << svd.singularValues()[svd.singularValues().size() - 1] << " (the zero tolerance is " << tol
        << "), as a straight inextensible rod held at its full length or clamped ends held where they meet "
           "(and near them); its multiplier is indeterminate";
    report->reason = why.str();
    return false;
  }
  const Eigen::MatrixXd frame_values = active.transpose() * values.leftCols(m);
  const Eigen::MatrixXd particular_values = active.transpose() * values.rightCols(all_constraints) * active;
  // With the full frame, a unit change of the end's reaction along a held position e enters the
  // end's natural conditions: dn(L) = e (its particular field is zero).
  Eigen::MatrixXd end_loads = Eigen::MatrixXd::Zero(m, all_constraints);
  if (full_) end_loads.block(0, all_constraints - at_end, coords_.kr(), at_end) = constraints;
  const Eigen::MatrixXd particular_U = f.particular_U * active,
                        particular_P_physical = (f.particular_P_physical - end_loads) * active;
  const int k = static_cast<int>(active.cols());
  const Eigen::MatrixXd held = held_configuration(end);
  const Eigen::MatrixXd free_rotation = complement(held, m);
  Eigen::MatrixXd conditions(m, m), loads(m, k);
  conditions << held.transpose() * f.U, free_rotation.transpose() * f.P_physical;
  loads << held.transpose() * particular_U, free_rotation.transpose() * particular_P_physical;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(conditions, Eigen::ComputeFullU | Eigen::ComputeFullV);
  report->zero_modes = whole_problem_zero_modes(conditions, svd, loads, frame_values, particular_values, tol);
  int correction = 0;
  if (k > 0) {
    const Eigen::MatrixXd c = -conditions.completeOrthogonalDecomposition().solve(loads);
    const Eigen::MatrixXd chord = frame_values * c + particular_values;  // D, k x k

    const NearZeroModes near = near_zero_modes(svd, loads, frame_values, particular_values, tol,
                                               std::max(kConditionsNoise, 10 * field_integrator_.rel_tol));
    // Where the decomposition drops modes but those between round-off and the tolerance are not
    // exact, only the dropped ones enter as zero modes: the near-zero one (the turn about the axis
    // of a slightly twisted arch, singular value 2.2e-7 at turns = 1e-4) stays in D. Taken as exact
    // with them, it gave plectoneme.toml at slenderness 50 (positions in the frame, 9 held
    // directions) index 1 at turns 1e-6 .. 2e-4 between 0 on either side.
    const Eigen::MatrixXd exact_zero_modes = near.exact_below_tolerance ? zero_modes : near.dropped;
    const Eigen::MatrixXd chord_zero = near.exact ? Eigen::MatrixXd(frame_values * exact_zero_modes)  // k x z
                                                  : Eigen::MatrixXd(k, 0);
    const int r_z = static_cast<int>(column_basis(chord_zero, tol).cols());
    const Eigen::MatrixXd quiet = null_space(chord_zero.transpose(), k, tol);  // loads doing no work on them
    // D = C H^-1 C^T is symmetric (reciprocity of the multipliers' responses): 1e-14 of its size
    // on the cases of the tests once every Jacobi field gets each contact's jump.
    const Eigen::MatrixXd D_quiet = quiet.transpose() * chord * quiet;
    const Eigen::MatrixXd D = 0.5 * (D_quiet + D_quiet.transpose());
    // Eigenvalues of D within its resolution are zero: the whole problem's zero modes. Where more
    // lie there than it has (one past the tolerance but within the resolution) D does not say.
    int positive = 0, unresolved = 0, not_decisive = 0;
    double unresolved_value = 0.0, unresolved_resolution = 0.0;
    std::vector<std::pair<double, bool>> undecided;  // (|lambda| / resolution, counted positive)
    if (D.rows() > 0) {
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(D);
      for (int i = 0; i < eig.eigenvalues().size(); ++i) {
        const double lambda = eig.eigenvalues()[i];
        const Eigen::VectorXd v = quiet * eig.eigenvectors().col(i);
        const double resolution =
            near.resolution(v, eigenvalue_floor(v, frame_values, c, particular_values, tol));
        if (std::abs(lambda) <= kDecisiveResolutions * resolution) {
          ++not_decisive;
          undecided.push_back({std::abs(lambda) / resolution, lambda > resolution});
        }
        if (lambda > resolution) ++positive;
        else if (std::abs(lambda) <= resolution) {
          ++unresolved;
          unresolved_value = lambda;
          unresolved_resolution = resolution;
        }
      }
    }
    if (unresolved > report->zero_modes) {
      std::ostringstream why;
      why << "the isoperimetric correction is not resolved: the chord's response to the multipliers has an "
          << "eigenvalue " << unresolved_value << " within its resolution " << unresolved_resolution
          << " (a load-controlled mode near zero), and the whole problem not as many zero modes";
      report->reason = why.str();
      report->resolution_limited = true;
      return false;
    }
    // The isoperimetric theory's count of the whole problem's zero modes: the load-controlled ones
    // that leave the chord unchanged (the planar arch's turn about the clamps' axis), and D's zero
    // eigenvalues. The null-space test above backs D's near-zero eigenvalues; where it finds more
    // than D leaves undecided (within kDecisiveResolutions of its resolution: a located branch
    // point's D eigenvalue, 5e-5 at a resolution of 3.6e-5, is its zero mode), D has resolved them
    // as nonzero and the bordered conditions are only near singular through weak couplings: on
    // indenter.toml at rise = 0.3663 their smallest singular value was 9e-8, a zero mode, with D's
    // eigenvalues -71.7, 5.1e-4 and 3.6e-2 at a resolution of 1e-6 (the discretised energy's
    // lowest eigenvalue +218), and along that branch the count flickered between 0 and 1. Only
    // where the load-controlled zero modes are exact (exact_load_controlled_zeros): a near-zero one
    // taken as exact can take the whole problem's zero mode with it.
    if (exact_load_controlled_zeros(svd.singularValues(), tol)) {
      const int unchanging = static_cast<int>(zero_modes.cols()) -
                             static_cast<int>(column_basis(frame_values * zero_modes, tol).cols());
      report->zero_modes = std::min(report->zero_modes, unchanging + not_decisive);
      positive -= undecided_counted_positive(&undecided, report->zero_modes - unchanging);
    }
    correction = r_z + positive - k;
  }
  report->constraint_count = k;
  report->constraint_correction = correction;
  return true;
}

// The eigenphases at s = 0. The fields held there start exactly at a conjugate point (U c = 0):
// their eigenphase is pi, leaving it in the Legendre direction.
PhaseTrack StabilityAnalysis::starting_track(const Frame& f, int held_count) const {
  const int m = static_cast<int>(f.U.cols());
  PhaseTrack track;
  track.lifted = eigenphases(f.U, f.P, true);
  std::vector<int> order(m);
  for (int j = 0; j < m; ++j) order[j] = j;
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return std::abs(wrap(track.lifted[a] - kPi)) < std::abs(wrap(track.lifted[b] - kPi)); });
  for (int k = 0; k < held_count; ++k) track.lifted[order[k]] = kPi;
  for (int j = 0; j < m; ++j)
    if (track.lifted[j] < -kPi + 1e-9) track.lifted[j] += 2 * kPi;
  track.lowest = track.lifted;
  track.passages.assign(m, {});
  return track;
}

// The rod in pieces between shooting nodes and contacts (their arclengths, the ends included).
std::vector<double> StabilityAnalysis::piece_breaks(const std::vector<PointContact>& contacts) const {
  std::vector<double> breaks = problem_.node_arclengths(x_);
  for (const PointContact& c : contacts) breaks.push_back(c.s);
  breaks.push_back(scales_.length);
  std::sort(breaks.begin(), breaks.end());
  breaks.erase(std::unique(breaks.begin(), breaks.end(),
                           [&](double a, double b) { return std::abs(a - b) < 1e-12 * scales_.length; }),
               breaks.end());
  return breaks;
}

// The fields carried from s = 0 to L across the pieces, each contact applying its jump; the
// reason where a contact cannot be passed, else empty.
std::string StabilityAnalysis::carry_across(Frame* f, const std::vector<PointContact>& contacts, PhaseTrack* track) {
  const std::vector<double> breaks = piece_breaks(contacts);
  const int pieces = static_cast<int>(breaks.size()) - 1;
  // Steps no longer than these, so that the eigenphases, turning at ~2 rate / L, move ~0.5 rad
  // per step at most (march takes the integrator's own steps below that).
  const int wanted = std::max(options_.min_steps, static_cast<int>(std::ceil(4.0 * scales_.rate)));
  const int steps = std::max(2, (wanted + pieces - 1) / pieces);
  const int observed_wanted = std::max(static_cast<int>(options_.min_steps * options_.observation_density),
                                       static_cast<int>(std::ceil(4.0 * scales_.rate)));
  const int observed_steps = std::max(2, (observed_wanted + pieces - 1) / pieces);
  double shear = 0.0;  // of the contact just passed
  for (int i = 0; i < pieces; ++i) {
    const double longest = (breaks[i + 1] - breaks[i]) / steps, observed = (breaks[i + 1] - breaks[i]) / observed_steps;
    // Past a contact whose shear S is large (the contact near flattening, f / g'' large) the
    // fields turn on the length L / S: steps grow geometrically from a fraction of it, so no
    // eigenphase turns a whole turn within one (which a step could not tell from no turn).
    for (double h = 0.25 * scales_.length / (1.0 + shear); shear > 0 && h < observed; h *= 2)
      advance(f, breaks[i] + h, track, 0);
    shear = 0.0;
    if (phase_speed_bound_) march_bounded(f, breaks[i + 1], track);
    else march(f, breaks[i + 1], longest, observed, track);
    for (size_t c = 0; c < contacts.size(); ++c) {
      if (std::abs(contacts[c].s - breaks[i + 1]) > 1e-12 * scales_.length) continue;
      if (std::string why = pass_contact(f, contacts[c], static_cast<int>(c), track, &shear); !why.empty()) return why;
      last_observation_ = {};  // the contact's shear moves the phases anew
    }
  }
  return "";
}

// The index from the fields at s = L: the conjugate points inside, the end's terms, the
// isoperimetric correction and the zero modes; report->reason set (no index) where it is not defined.
void StabilityAnalysis::count_at_end(const Frame& f, const PhaseTrack& track, const Eigen::VectorXd& start_phases,
                                     const Held& start, const Held& end, const Eigen::MatrixXd& constraints,
                                     StabilityReport* report) const {
  report->resolution_limited = track.unresolved || track.reversed;
  if (track.unresolved && !track.reversed) {
    std::ostringstream reason;
    reason << "a conjugate point near s = " << track.unresolved_at
           << " is not resolved: det U changes sign where the eigenphases show no passage, at the finest steps";
    report->reason = reason.str();
    return;
  }
  if (track.reversed) {
    std::ostringstream reason;
    reason << "an eigenphase passed against the Legendre direction near s = " << track.reversed_at
           << ": the Jacobi system is degenerate there and the count is not valid";
    report->reason = reason.str();
    return;
  }
  if (!count_interior(f, track, start_phases, report)) return;
  if (std::string why = end_moment_reason(f, end); !why.empty()) {
    report->reason = why;
    return;
  }
  const Eigen::MatrixXd zero_modes = end_terms(f, end, report);
  report->dead_load_index = report->interior_count + report->end_count;
  if (!constraint_correction(f, end, constraints, zero_modes, report)) return;
  // Rigid translations along directions neither end holds map equilibria to equilibria (the full
  // frame carries them, and counts them where they are zero modes).
  Eigen::MatrixXd held(coords_.kr(), start.position.cols() + end.position.cols());
  held << start.position, end.position;
  if (!full_) report->zero_modes += coords_.kr() - static_cast<int>(column_basis(held).cols());
  report->index = report->dead_load_index + report->constraint_correction;
  if (*report->index < 0) {
    report->reason = "the isoperimetric correction exceeds the load-controlled index: degenerate constraints";
    report->resolution_limited = true;
    report->index.reset();
  }
}

StabilityReport StabilityAnalysis::run() {
  StabilityReport report;
  std::vector<std::string> multipliers;
  std::string why = unsupported(problem_, x_);
  if (why.empty()) why = classify_unknowns(problem_, p_, &multipliers);
  if (!why.empty()) {
    report.reason = why;
    return report;
  }
  const ProblemDefinition& d = problem_.definition();
  const Held start = held_at(d.start, multipliers, x_.head(problem_.state_size()), 0.0);
  const Held end = held_at(end_, multipliers);  // (its rotations balanced at s = L, below)
  // The isoperimetric constraints read at s = L: the held chord, or with the full frame every
  // position the end holds (and those the start holds, read at s = 0).
  const Eigen::MatrixXd constraints = full_ ? end.position : constraint_directions(start, end);
  const Eigen::MatrixXd start_multipliers = full_ ? Eigen::MatrixXd(-start.position) : constraints;
  start_multipliers_ = static_cast<int>(start_multipliers.cols());
  recorded_before_contacts_ = full_ ? static_cast<int>(start.position.cols()) : 0;
  const std::vector<PointContact> contacts = problem_.contacts_at(x_);
  scales_.rate = field_rate();
  if (full_) scales_.force_rate = scales_.rate;
  phase_speed_bound_ = phase_speed_bound(contacts);
  // (advance halves a step whose move passes this: never, where the bound holds, but for round-off)
  if (phase_speed_bound_) max_phase_step_ = std::max(max_phase_step_, 1.01 * kBoundedPhaseMove);

  Frame f = start_frame(start, start_multipliers, static_cast<int>(contacts.size()),
                        full_ ? static_cast<int>(end.position.cols()) : 0);
  const Eigen::MatrixXd lagrange = f.U.transpose() * f.P - f.P.transpose() * f.U;
  if (lagrange.norm() > 1e-8 * (1.0 + f.U.norm() * f.P.norm())) {
    report.reason = "the start's loads are not conservative (a dead couple on an end free to rotate in 3D)";
    return report;
  }
  orthonormalise(&f);
  PhaseTrack track = starting_track(f, static_cast<int>(start.rotation.cols()));
  const Eigen::VectorXd start_phases = track.lifted;
  why = carry_across(&f, contacts, &track);
  if (!why.empty()) {
    report.reason = why;
    return report;
  }
  report.rhs_evaluations = rhs_;
  report.field_flows = flows_;
  reversed_ = track.reversed || track.unresolved;
  count_at_end(f, track, start_phases, start, scales_.stiffness_min > 0 ? held_at(end_, multipliers, f.y, f.s) : end,
               constraints, &report);
  return report;
}

}  // namespace

namespace {

// The whole rod's index from its two halves (stability_symmetric.hpp): the counts add, and the
// conjugate points are those of both half problems (half-rod arclengths). Undefined when either is.
StabilityReport whole_rod(const StabilityReport& symmetric, const StabilityReport& antisymmetric) {
  for (const auto* part : {&symmetric, &antisymmetric})
    if (!part->defined()) {
      StabilityReport out = *part;
      out.reason = std::string(part == &symmetric ? "symmetric" : "antisymmetric") +
                   " perturbations of the half-turn symmetric rod: " + part->reason;
      out.rhs_evaluations = symmetric.rhs_evaluations + antisymmetric.rhs_evaluations;
      out.field_flows = symmetric.field_flows + antisymmetric.field_flows;
      return out;
    }
  StabilityReport out;
  out.index = *symmetric.index + *antisymmetric.index;
  out.symmetric_index = symmetric.index;
  out.antisymmetric_index = antisymmetric.index;
  out.zero_modes = symmetric.zero_modes + antisymmetric.zero_modes;
  out.conjugate_points = symmetric.conjugate_points;
  out.conjugate_points.insert(out.conjugate_points.end(), antisymmetric.conjugate_points.begin(),
                              antisymmetric.conjugate_points.end());
  std::sort(out.conjugate_points.begin(), out.conjugate_points.end());
  out.interior_count = symmetric.interior_count + antisymmetric.interior_count;
  out.end_count = symmetric.end_count + antisymmetric.end_count;
  out.dead_load_index = symmetric.dead_load_index + antisymmetric.dead_load_index;
  out.constraint_count = symmetric.constraint_count + antisymmetric.constraint_count;
  out.constraint_correction = symmetric.constraint_correction + antisymmetric.constraint_correction;
  out.rhs_evaluations = symmetric.rhs_evaluations + antisymmetric.rhs_evaluations;
  out.field_flows = symmetric.field_flows + antisymmetric.field_flows;
  return out;
}

// Where the sliding contact partners are not defined (stability_symmetric.hpp), the whole rod's
// index is not; the symmetric half's is given.
StabilityReport sliding_undefined(const std::string& reason, const StabilityReport& symmetric,
                                  const StabilityReport& antisymmetric) {
  StabilityReport out;
  out.reason = reason + "; the symmetric perturbations' index is given";
  out.symmetric_index = symmetric.index;
  out.rhs_evaluations = symmetric.rhs_evaluations + antisymmetric.rhs_evaluations;
  out.field_flows = symmetric.field_flows + antisymmetric.field_flows;
  return out;
}

// A passage against the Legendre direction cannot happen where the Legendre condition holds, so
// it is either a degenerate Jacobi system or eigenphases paired wrongly between observations too
// far apart (where the fields turn faster than the rate estimate says: a stiff self-contact
// barrier, a soft wall). The analysis is run again with observations kKeepRefining times denser
// each time, up to kRefinements times; only a passage that survives them makes the index
// undefined. Measured on plectoneme.toml's branch (turns 0 .. 2.86, 149 points): 40 points
// undefined at the default observations, none at max_phase_step 0.1 and min_steps 64.
constexpr int kRefinements = 2;
constexpr double kKeepRefining = 4.0;

bool same_count(const StabilityReport& a, const StabilityReport& b) {
  return a.index == b.index && a.zero_modes == b.zero_modes;
}

// `run(options, &reversed)`: one analysis with those options, saying whether it saw a reversal.
// The report's right-hand sides are those of every run made. With `confirm` (a rod in an external
// field) a count stands once observations kKeepRefining times denser repeat it: the steps are
// sized by the fields' wave number on a coarse profile (field_rate), which a stiff barrier's spike
// (a self-contact crossing, ~sqrt(R gap) wide) can fall between, and across it a phase can turn a
// whole turn within one step without moving a step's worth from end to end: on plectoneme.toml's
// branch (turns 1.1576, between two folds at index 1) the default observations counted 2, four and
// sixteen times denser ones 1. Denser observations can also see a phase that hovers at pi pass it
// and come back (the soft wall at log_b = -4, Delta = 0.045, s = 0.505): such a run counts nothing.
// A single count that no denser one contradicts stands; counts that differ and are never repeated
// leave the index undefined.
template <class Run>
StabilityReport run_resolved(const StabilityOptions& options, bool confirm, const Run& run) {
  StabilityOptions o = options;
  long rhs_before = 0, flows_before = 0;
  std::vector<StabilityReport> counted;  // the runs without a reversal, in the order made
  StabilityReport last;
  for (int refinement = 0; refinement <= kRefinements; ++refinement) {
    bool reversed = false;
    last = run(o, &reversed);
    last.rhs_evaluations += rhs_before;
    rhs_before = last.rhs_evaluations;
    last.field_flows += flows_before;
    flows_before = last.field_flows;
    if (!reversed) {
      if (!confirm || (!counted.empty() && same_count(counted.back(), last))) return last;
      counted.push_back(last);
    }
    o.observation_density *= kKeepRefining;
  }
  if (counted.empty()) return last;  // a reversal at every density: the index is undefined
  StabilityReport out = counted.back();
  out.rhs_evaluations = rhs_before;
  out.field_flows = flows_before;
  if (counted.size() == 1) return out;
  std::ostringstream why;
  why << "the count is not settled by denser observations of the Jacobi fields (index";
  for (size_t k = 0; k < counted.size(); ++k)
    why << (k ? ", then " : " ") << (counted[k].index ? std::to_string(*counted[k].index) : std::string("undefined"));
  why << "): a stiff field turns them faster than they are observed";
  out.reason = why.str();
  out.index.reset();
  return out;
}

// Whether the rod is in an external field that stiffens its perturbations (a soft wall,
// self-contact's barrier: ExternalField::stiffens_perturbations), whose Jacobi fields may turn
// faster than they are observed. Uniform gravity does not: linear in r, it reaches them only
// through the internal force, as an end load does (the heavy cantilever's index cost 3.6 F + J
// with the confirmation).
bool in_stiffening_field(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  const auto& field = problem.definition().model(problem.parameters_at(x)).field;
  return field != nullptr && field->stiffens_perturbations();
}

// `confirm`: run_resolved's, for a rod in a field (in_stiffening_field).
StabilityReport run_plain(const ShootingProblem& problem, const Eigen::VectorXd& x, const StabilityOptions& options,
                          const EndCondition& end, bool confirm) {
  return run_resolved(options, confirm, [&](const StabilityOptions& o, bool* reversed) {
    StabilityAnalysis analysis(problem, x, o, end, nullptr);
    StabilityReport report = analysis.run();
    *reversed = analysis.reversed();
    return report;
  });
}

}  // namespace

namespace {

StabilityReport analyse_at_field_tolerance(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                           const StabilityOptions& requested) {
  try {
    // In a field that stiffens the perturbations (its counts are confirmed by denser observations)
    // the Jacobi fields are integrated at the state's tolerance, never at a looser
    // StabilityOptions::field_tolerance (a branch's 1e-8): across the barrier's spike their error
    // is amplified past the resolution the count assumes. On plectoneme.toml's branch (turns 0 .. 3,
    // 263 points) fields at 1e-8 left 36 points undefined and 27 with index 1 and no zero mode past
    // turns = 2.83 (D's eigenvalue of the rod's turn about the clamps' axis, a zero mode by
    // symmetry, came out 3.7e-4 at a resolution of 3.4e-5); at the case's 1e-13 every point has an
    // index, 0 with that zero mode on the whole ply past the fold at 2.7257.
    const bool confirm = in_stiffening_field(problem, x);
    StabilityOptions options = requested;
    if (confirm) options.field_tolerance = 0.0;
    // An unknown that changes the rod (a sleeve's sliding length): reduced on it, or null with why.
    if (!rod_changing_unknown(problem).empty()) return analyse_free_length_stability(problem, x, options);
    // The rod lying on an obstacle: its own treatment (the discretised energy for planar rods).
    if (has_extended_contact(problem, x)) {
      if (options.extended_contacts) return extended_contact_stability(problem, x);
      StabilityReport report;
      report.reason = "an extended contact (the rod lying on the obstacle): its index (from the discretised energy, "
                      "seconds per equilibrium) is not computed along a branch; `kirchhoff solve` gives it";
      return report;
    }
    const EndCondition& end = problem.definition().end;
    if (!end.is_half_turn_symmetry() || !unsupported(problem, x).empty())
      return run_plain(problem, x, options, end, confirm);
    // Half of a half-turn symmetric rod: the end as stated holds the symmetric perturbations; the
    // antisymmetric ones have the complementary conditions and, with self-contact, the pair
    // energy's other second variation.
    const auto equations = problem.equations(problem.parameters_at(x));
    const StabilityReport symmetric = run_plain(problem, x, options, end, confirm);
    const EndCondition anti_end = antisymmetric_half_turn_end(end.half_turn_axis());
    std::string sliding;
    const auto run_antisymmetric = [&](const StabilityOptions& o, bool* reversed) {
      StabilityAnalysis anti(problem, x, o, anti_end, antisymmetric_equations(*equations));
      anti.track_barrier(equations);
      StabilityReport report = anti.run();
      *reversed = anti.reversed();
      sliding = anti.sliding_reason();
      return report;
    };
    const StabilityReport antisymmetric = run_resolved(options, confirm, run_antisymmetric);
    if (!sliding.empty()) return sliding_undefined(sliding, symmetric, antisymmetric);
    return whole_rod(symmetric, antisymmetric);
  } catch (const IntegrationError& e) {
    StabilityReport report;
    report.reason = std::string("the Jacobi fields could not be integrated: ") + e.what();
    return report;
  }
}

}  // namespace

StabilityReport analyse_stability(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                  const StabilityOptions& options) {
  StabilityReport report = analyse_at_field_tolerance(problem, x, options);
  // A count the looser fields of a branch (StabilityOptions::field_tolerance, 1e-8) leave
  // undefined is made again at the state's tolerance: their error can exceed a resolution the
  // count needs (the isoperimetric correction of an anisotropic twisted rod under compression,
  // B1 = 3 B2, phi = 32 .. 40: D's eigenvalues of 1e-4 .. 2e-2 within resolutions of 1e-3 .. 9e-2,
  // where the state's tolerance settles index 9 .. 11, as a discretised energy does). Points whose
  // index is undefined for what the case is (a dead couple on an end free to rotate, a degenerate
  // constraint) are not counted again: tighter fields would say the same at twice the cost.
  const bool looser = options.field_tolerance > problem.definition().options.integrator.abs_tol;
  if (report.defined() || !report.resolution_limited || !looser) return report;
  StabilityOptions exact = options;
  exact.field_tolerance = 0.0;
  StabilityReport again = analyse_at_field_tolerance(problem, x, exact);
  again.rhs_evaluations += report.rhs_evaluations;
  again.field_flows += report.field_flows;
  return again;
}

std::string describe(const StabilityReport& report) {
  if (!report.index && report.unstable) {
    // (The reason may say "unstable: ..." itself, as the lift-off's does.)
    const std::string said = "unstable: ";
    const bool says = report.reason.compare(0, said.size(), said) == 0;
    return "unstable, no index: " + report.reason.substr(says ? said.size() : 0);
  }
  if (!report.index) return "index undefined: " + report.reason;
  std::ostringstream out;
  out << (*report.index == 0 ? "stable" : "unstable (index " + std::to_string(*report.index) + ")");
  if (report.zero_modes > 0) out << ", " << report.zero_modes << " zero mode" << (report.zero_modes > 1 ? "s" : "");
  if (report.method == "discretised_energy") out << " (by the discretised energy: " << report.method_reason << ")";
  return out.str();
}

}  // namespace kirchhoff

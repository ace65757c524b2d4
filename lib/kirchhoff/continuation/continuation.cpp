#include "kirchhoff/continuation/continuation.hpp"

#include "kirchhoff/continuation/detail/singular_point_index.hpp"

#include <algorithm>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "kirchhoff/continuation/detail/branch_crossing.hpp"
#include "kirchhoff/continuation/detail/broyden_steps.hpp"
#include "kirchhoff/continuation/detail/continuation_detectors.hpp"
#include "kirchhoff/continuation/detail/kinked_minimum.hpp"
#include "kirchhoff/shooting/detail/jacobian_lu.hpp"
#include "kirchhoff/shooting/newton.hpp"

namespace kirchhoff {
namespace {

// The first step of a run or a branch: initial_step, within [min_step, max_step] (a first step
// of 0.05 under --max-step 0.01 went five times as far as the run allows any).
double first_step(const StepControl& o) { return std::clamp(o.initial_step, o.min_step, o.max_step); }

// The longest step from a point with unknowns x (StepControl::max_step_reference_size).
double longest_step(const StepControl& o, const Eigen::VectorXd& x) {
  if (!(o.max_step_reference_size > 0)) return o.max_step;
  return o.max_step * std::max(1.0, x.norm() / o.max_step_reference_size);
}

// How many times the first step from a branch point is halved before the switch gives up.
constexpr int kFirstStepHalvings = 6;

// The largest distance a march's corrector may move a point from its prediction, as a fraction of
// the step (Continuation::step_from): with the quadratic predictor, and with the tangent alone.
constexpr double kMovedQuadratic = 0.1;
constexpr double kMovedTangent = 0.3;
// Step growth and shrink factors: the usual choices for predictor-corrector continuation.
constexpr double kGrow = 1.5, kShrink = 0.5;
// Location (Illinois, the kinked minimum) stops when the step interval is this small relative to the step.
constexpr double kLocateTolerance = 1e-12;
constexpr int kLocateIterations = 60;
// Chord iterations continue while each one reduces the residual at least by this factor.
constexpr double kChordContraction = 0.3;
// Modified Newton keeps its matrix while each iteration reduces the residual at least by this
// factor (it converges linearly at that rate, still cheaper than a new matrix when one costs
// tens of residuals).
constexpr double kModifiedNewtonContraction = 0.5;

double sign_of(double v) { return v < 0 ? -1.0 : 1.0; }

// Within a bracket this small against the step, a smooth monitor is monotone (its linear term
// dominates, or it has a double root there, which no sign change brackets), so a value at an
// interior trial larger than both ends' is noise at this scale: next to a singular point (the
// Euler column's touching ends) the correctors land on either branch and the determinant's sign
// means nothing, and Illinois went on for its 60 iterations at up to 13 exact matrices each.
// The location is then as good as the correctors allow; the trial with the smallest value is it.
constexpr double kMonotoneBracket = 1e-4;

bool monitor_is_noise(double value, double at_a, double at_b, double bracket, double step) {
  return std::abs(bracket) < kMonotoneBracket * std::abs(step) &&
         std::abs(value) > std::max(std::abs(at_a), std::abs(at_b));
}

// Points a march can be resumed from: a special point (fold, branch point, event, end) is found
// by locating inside a step, and a resumed run finds it again by redoing that step.
bool resumable_type(PointType t) { return t == PointType::Start || t == PointType::Regular; }

// Below this ratio of the smallest singular value to the largest, the square roots of M^T M's
// eigenvalues are replaced by the SVD's (see bordered_singular_values).
constexpr double kSvdBelow = 1e-4;

// The singular values of the bordered matrix, largest first, for the branch-point tests. The
// square roots of the eigenvalues of M^T M cost a fraction of a Jacobi SVD (45 of a 16-unknown
// point's ~740 us) but carry an absolute error ~n eps sigma_max^2 / sigma in each: relative
// n eps / (2 ratio^2), 2e-7 at ratio 1e-4 and less above. Where the smallest falls below that
// ratio (near branch points, where the tests compare it with 1e-7 and count the small ones) the
// SVD gives them all.
Eigen::VectorXd bordered_singular_values(const Eigen::MatrixXd& M) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(M.transpose() * M, Eigen::EigenvaluesOnly);
  if (eigen.info() == Eigen::Success) {
    const Eigen::VectorXd sv = eigen.eigenvalues().reverse().cwiseMax(0.0).cwiseSqrt();
    if (sv[0] > 0 && sv[sv.size() - 1] >= kSvdBelow * sv[0]) return sv;
  }
  return Eigen::JacobiSVD<Eigen::MatrixXd>(M).singularValues();
}

}  // namespace

const char* to_string(PointType type) {
  switch (type) {
    case PointType::Start: return "start";
    case PointType::Regular: return "regular";
    case PointType::Fold: return "fold";
    case PointType::BranchPoint: return "branch_point";
    case PointType::Event: return "event";
    case PointType::Endpoint: return "endpoint";
    case PointType::IndexChange: return "index_change";
  }
  return "?";
}

StopReason failed_start_reason(std::chrono::steady_clock::time_point deadline) {
  return std::chrono::steady_clock::now() >= deadline ? StopReason::TimeLimit : StopReason::StartFailed;
}

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::ReachedTarget: return "reached_target";
    case StopReason::MaxPoints: return "max_points";
    case StopReason::ParameterBounds: return "parameter_bounds";
    case StopReason::StepTooSmall: return "step_too_small";
    case StopReason::EventStop: return "event";
    case StopReason::BranchPointStop: return "branch_point";
    case StopReason::StartFailed: return "start_failed";
    case StopReason::Inadmissible: return "inadmissible";
    case StopReason::TimeLimit: return "time_limit";
    case StopReason::FoldStop: return "fold";
  }
  return "?";
}

std::string ContinuationRange::validate() const {
  if (parameter.empty()) return "no continuation parameter given";
  // Each point keeps its unknowns and derived quantities in memory: 1e7 of them is beyond any
  // branch and still fits; more is a typo.
  if (max_points < 1 || max_points > 10000000) return "max_points must be in [1, 1e7]";
  if (!(parameter_min < parameter_max)) return "parameter_min must be < parameter_max";
  if (std::isinf(target)) return "the target must be finite (NaN: none)";
  return {};
}

std::string StepControl::validate() const {
  if (!(initial_step > 0) || !(min_step > 0) || !(max_step >= min_step)) return "steps must satisfy 0 < min_step <= max_step, initial_step > 0";
  if (!(max_step_reference_size >= 0)) return "max_step_reference_size must be >= 0";
  if (!(0 <= grow_iterations && grow_iterations < shrink_iterations))
    return "grow_iterations must be >= 0 and below shrink_iterations";
  return {};
}

std::string CorrectorOptions::validate() const {
  if (corrector_max_iterations < 1 || !(corrector_tolerance > 0 || std::isnan(corrector_tolerance)))
    return "corrector settings must be positive";
  return {};
}

std::string DetectionOptions::validate() const {
  // A relative singular value: 1 or more would call every point a branch point.
  if (!(branch_point_tolerance > 0 && branch_point_tolerance < 1)) return "branch_point_tolerance must be in (0, 1)";
  if (stop_at_branch_point < 0) return "stop_at_branch_point must be >= 0 (0: never stop at one)";
  // (An event's value may be NaN: a contact leg resumed from a state that recorded none arms an
  // event that never fires.)
  for (const ContinuationEvent& e : events)
    if (e.quantity.empty()) return "an event needs a quantity";
  return {};
}

std::string RecordOptions::validate() const {
  for (const std::string& name : derived)
    if (name.empty()) return "a derived quantity needs a name";
  return {};
}

std::string ContinuationOptions::validate() const {
  for (const std::string& group : {ContinuationRange::validate(), StepControl::validate(), CorrectorOptions::validate(),
                                   DetectionOptions::validate(), RecordOptions::validate()})
    if (!group.empty()) return group;
  if (reuse_jacobian_iterations >= 0 && detect_branch_points)
    return "reusing Jacobians needs detect_branch_points = false (the test functions need each point's own)";
  return {};
}

Continuation::Continuation(std::unique_ptr<ParameterisedSystem> system, ContinuationOptions options)
    : Continuation(std::move(system), std::move(options), {}) {}

Continuation::Continuation(std::unique_ptr<ParameterisedSystem> system, ContinuationOptions options,
                           const DefaultRecorder& default_recorder)
    : system_(std::move(system)), options_(std::move(options)) {
  if (!system_) throw std::invalid_argument("no system to continue");
  if (std::string e = options_.validate(); !e.empty()) throw std::invalid_argument(e);
  configure();
  if (!options_.recorder) options_.recorder = default_recorder ? default_recorder(options_) : PointRecorder{};
}

void Continuation::configure() {
  if (std::isnan(options_.corrector_tolerance)) options_.corrector_tolerance = system_->default_corrector_tolerance();
  // Events read their quantities among the derived ones the recorder fills.
  for (const auto& e : options_.events)
    if (std::find(options_.derived.begin(), options_.derived.end(), e.quantity) == options_.derived.end())
      options_.derived.push_back(e.quantity);
  n_ = system_->size();
}

Eigen::VectorXd Continuation::join(const Eigen::VectorXd& x, double lambda) const {
  Eigen::VectorXd z(n_ + 1);
  z << x, lambda;
  return z;
}

bool Continuation::evaluate(const Eigen::VectorXd& z, Eigen::VectorXd* F, Eigen::MatrixXd* A, std::string* failure,
                            bool march) {
  const double lambda = z[n_];
  const Eigen::VectorXd x = z.head(n_);
  if (!A) {
    ++evaluations_.residuals;
    return system_->residual(x, lambda, F, failure);
  }
  ++evaluations_.matrices;
  return system_->matrix(x, lambda, F, A, failure, march);
}

bool Continuation::matrix_alone(const Eigen::VectorXd& z, Eigen::MatrixXd* A, std::string* failure, bool march) {
  if (!march || !system_->has_approximate_matrices()) {
    Eigen::VectorXd F;
    return evaluate(z, &F, A, failure, march);
  }
  ++evaluations_.matrices;
  return system_->approximate_matrix(z.head(n_), z[n_], A, failure);
}

bool Continuation::correct(Eigen::VectorXd& z, const Eigen::VectorXd& z_predicted, const Eigen::VectorXd& normal,
                           int* iterations, const Eigen::MatrixXd* chord, bool* by_chord, bool march,
                           std::shared_ptr<const Eigen::MatrixXd>* matrix_at_z) {
  if (matrix_at_z) matrix_at_z->reset();
  Eigen::VectorXd F, G(n_ + 1);
  Eigen::MatrixXd A;
  std::string failure;
  int it = 0;
  if (chord && chord->rows() == n_) {
    const JacobianLU lu(*chord, normal);
    if (lu.reciprocal_condition() > 1e-15) {
      const Eigen::VectorXd z_start = z;
      double previous = INFINITY;
      detail::BroydenSteps broyden;
      for (; it <= options_.corrector_max_iterations; ++it) {
        if (!evaluate(z, &F, nullptr, &failure)) break;
        G << F, normal.dot(z - z_predicted);
        const double norm = max_abs_or_nan(G);  // NaN when G holds one (lpNorm would skip it)
        if (!std::isfinite(norm)) break;
        if (norm <= options_.corrector_tolerance) {
          *iterations = it;
          if (by_chord) *by_chord = true;
          return true;
        }
        // Chord iterations contract linearly; slower than this, full Newton is cheaper.
        if (norm > kChordContraction * previous) break;
        previous = norm;
        const std::optional<Eigen::VectorXd> step = broyden.next(-lu.solve(G));
        if (!step) break;
        z += *step;
      }
      if (!z.allFinite()) z = z_start;
    }
  }
  double best = INFINITY, previous = INFINITY;
  std::optional<JacobianLU> lu;  // the matrix of the current (modified) Newton iteration
  for (; it <= 2 * options_.corrector_max_iterations; ++it) {
    bool have_F = false;  // F (and G) at z, evaluated just now
    if (lu) {
      if (!evaluate(z, &F, nullptr, &failure)) {
        last_corrector_failure_ = failure;
        return false;
      }
      G << F, normal.dot(z - z_predicted);
      have_F = true;
      if (!(max_abs_or_nan(G) <= kModifiedNewtonContraction * previous)) lu.reset();
    }
    if (!lu) {
      if (!(have_F ? matrix_alone(z, &A, &failure, march) : evaluate(z, &F, &A, &failure, march))) {
        last_corrector_failure_ = failure;
        return false;
      }
      G << F, normal.dot(z - z_predicted);
    }
    if (!G.allFinite()) {
      last_corrector_failure_ = "the residual is not finite";
      return false;
    }
    const double norm = G.lpNorm<Eigen::Infinity>();
    best = std::min(best, norm);
    if (norm <= options_.corrector_tolerance) {
      *iterations = it;
      // Converged on a matrix evaluated at z itself: the point's own, for its tangent.
      if (matrix_at_z && !lu) *matrix_at_z = std::make_shared<const Eigen::MatrixXd>(std::move(A));
      return true;
    }
    if (!lu) {
      lu.emplace(A, normal);
      if (!(lu->reciprocal_condition() > 1e-15)) {
        std::ostringstream os;
        os << "singular bordered matrix (reciprocal condition " << lu->reciprocal_condition() << ", residual " << norm
           << ")";
        last_corrector_failure_ = os.str();
        return false;
      }
    }
    z -= lu->solve(G);
    previous = norm;
    if (!options_.modified_newton) lu.reset();
  }
  std::ostringstream os;
  os << "no convergence, best residual " << best;
  last_corrector_failure_ = os.str();
  return false;
}

std::optional<ContinuationPoint> Continuation::point_at(const Eigen::VectorXd& z, const Eigen::VectorXd& previous,
                                                        PointType type, int index, double arclength, int iterations,
                                                        std::shared_ptr<const Eigen::MatrixXd> given, bool given_is_own) {
  const bool is_reused = given != nullptr && !given_is_own;
  std::shared_ptr<const Eigen::MatrixXd> A = std::move(given);
  if (!A) {
    Eigen::MatrixXd own;
    std::string failure;
    // The march's matrix at the points it can resume from (restore() evaluates the same one).
    if (!matrix_alone(z, &own, &failure, resumable_type(type))) return std::nullopt;
    A = std::make_shared<const Eigen::MatrixXd>(std::move(own));
  }
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n_ + 1);
  rhs[n_] = 1.0;
  const JacobianLU lu(*A, previous);
  Eigen::VectorXd t = lu.solve(rhs);
  // A located branch point whose bordered matrix is singular to round-off (a pitchfork whose test
  // function is linear in lambda: the secant lands on its zero exactly) has no tangent of its own;
  // the branch followed goes on along the step's. Rods' located branch points stay well above
  // that (their smallest singular value ~1e-12 of the largest).
  if (type == PointType::BranchPoint && !(lu.reciprocal_condition() > std::numeric_limits<double>::epsilon()))
    t = previous;
  if (!t.allFinite() || t.norm() == 0.0) return std::nullopt;
  t.normalize();
  return make_point(z, t, std::move(A), is_reused, type, index, arclength, iterations);
}

ContinuationPoint Continuation::make_point(const Eigen::VectorXd& z, const Eigen::VectorXd& t,
                                           std::shared_ptr<const Eigen::MatrixXd> A, bool reused, PointType type,
                                           int index, double arclength, int iterations) {
  ContinuationPoint p;
  p.index = index;
  p.x = z.head(n_);
  p.parameter = z[n_];
  p.tangent = t;
  p.type = type;
  p.arclength = arclength;
  p.newton_iterations = iterations;
  p.jacobian_reused = reused;
  // The determinant and singular values only serve branch-point detection, and the SVD costs
  // O(n^3) with a large constant: on multiple-shooting problems of several hundred unknowns it
  // was 95 % of a run.
  if (options_.detect_branch_points) {
    Eigen::MatrixXd M(n_ + 1, n_ + 1);
    M << *A, t.transpose();
    p.determinant = JacobianLU(M).determinant();
    const Eigen::VectorXd sv = bordered_singular_values(M);
    p.smallest_singular = sv[n_] / sv[0];
    for (int i = 0; i <= n_; ++i) p.small_count += sv[i] / sv[0] < options_.branch_point_tolerance ? 1 : 0;
  }
  p.jacobian = std::move(A);
  return p;
}

std::optional<ContinuationPoint> Continuation::restore(const ContinuationPoint& saved, bool with_description) {
  if (saved.x.size() != n_ || saved.tangent.size() != n_ + 1) return std::nullopt;
  const Eigen::VectorXd z = join(saved.x, saved.parameter);
  Eigen::MatrixXd A;
  std::string failure;
  if (!matrix_alone(z, &A, &failure, resumable_type(saved.type))) return std::nullopt;
  // The saved tangent, not one solved for again: bordered by another row (the point's own
  // tangent instead of its predecessor's) the solve gives the same direction to round-off only.
  ContinuationPoint p = make_point(z, saved.tangent, std::make_shared<const Eigen::MatrixXd>(std::move(A)), false,
                                   saved.type, saved.index, saved.arclength, saved.newton_iterations);
  p.step = saved.step;
  if (with_description) describe(&p);
  return p;
}

void Continuation::describe(ContinuationPoint* point) {
  if (options_.recorder->describe) options_.recorder->describe(*system_, point);
}

void Continuation::record(ContinuationPoint* point) {
  if (options_.recorder->record) options_.recorder->record(*system_, point);
}

std::optional<ContinuationPoint> Continuation::step_from(const ContinuationPoint& from, double h, PointType type,
                                                         const Eigen::VectorXd* curvature) {
  const Eigen::VectorXd z0 = join(from.x, from.parameter);
  Eigen::VectorXd z_pred = z0 + h * from.tangent;
  if (curvature) z_pred += (0.5 * h * h) * *curvature;
  Eigen::VectorXd z = z_pred;
  int iterations = 0;
  bool by_chord = false;
  // The march's own steps with its matrices; a located point's correctors (and its matrix, in
  // point_at) with the problem's own, as its test functions are.
  const bool march = type == PointType::Regular;
  // The matrix Newton converged on, when it was evaluated at the point itself and is of the
  // kind point_at evaluates for this type (the march's at resumable points, which restore()
  // evaluates again): the point's own, not evaluated a second time.
  std::shared_ptr<const Eigen::MatrixXd> own;
  if (!correct(z, z_pred, from.tangent, &iterations, from.jacobian.get(), &by_chord, march,
               march == resumable_type(type) ? &own : nullptr)) {
    // Where Newton needs the matrix to more digits than the march's (a stiff self-contact
    // barrier, where it stalled at a residual of 2e-8), the step is corrected again with the
    // problem's own before it counts as failed. Its chord iterations on the same matrix from the
    // same prediction would fail again: Newton at once.
    if (!march || !system_->has_approximate_matrices()) return std::nullopt;
    z = z_pred;
    own.reset();
    if (!correct(z, z_pred, from.tangent, &iterations)) return std::nullopt;
  }
  // A march's corrector that moved the point far from its prediction may have converged on another
  // branch lying beside this one, where the tangent does not turn to show it: the simply supported
  // Elastica carried from EI = 1, L = 1 to EI = 0.0145, L = 3 went from its first mode to its third
  // in one step of 1.03 whose corrector moved 0.21 (8 iterations), where the steps before it moved
  // at most 0.024 of theirs. Such a step is taken again, shorter (as a failed corrector is). The
  // quadratic predictor's error is O(h^3), the tangent's ~kappa h^2 / 2, at most ~0.18 h within
  // max_tangent_angle: the bounds below leave both room.
  if (march) {
    const double moved = (z - z_pred).norm(), limit = (curvature ? kMovedQuadratic : kMovedTangent) * std::abs(h);
    if (moved > limit) {
      std::ostringstream why;
      why << "the corrector moved the point " << moved << " from its prediction on a step of " << std::abs(h)
          << " (another branch nearby?)";
      last_corrector_failure_ = why.str();
      return std::nullopt;
    }
  }
  // A corrector that converged quickly on the previous matrix shows that matrix still serves:
  // the new point keeps it for its tangent and the next chord instead of paying for its own.
  // (Not a modified-Newton matrix from an iterate of this corrector: tried at L/2R = 200, its
  // tangents cost three times the run time in harder correctors.)
  const bool reuse =
      by_chord && iterations <= options_.reuse_jacobian_iterations && from.jacobian && from.jacobian->rows() == n_;
  const bool is_own = own != nullptr;
  std::shared_ptr<const Eigen::MatrixXd> given = is_own ? std::move(own) : reuse ? from.jacobian : nullptr;
  auto point = point_at(z, from.tangent, type, from.index + 1, from.arclength + (z - z0).norm(), iterations,
                        std::move(given), is_own);
  if (point) describe(&*point);
  // A corrected point that is not an admissible solution is a failed step, as a corrector that
  // did not converge is: the step shrinks, and the run ends saying why at the smallest step.
  if (point && !point->check_failure.empty()) {
    last_corrector_failure_ = point->check_failure;
    return std::nullopt;
  }
  return point;
}

std::optional<ContinuationPoint> Continuation::at_parameter(const ContinuationPoint& located, double value) {
  const Eigen::VectorXd z0 = join(located.x, located.parameter);
  Eigen::VectorXd z = join(located.x, value), e = Eigen::VectorXd::Zero(n_ + 1);
  e[n_] = 1.0;
  int iterations = 0;
  if (!correct(z, z, e, &iterations, located.jacobian.get())) return std::nullopt;
  auto point = point_at(z, located.tangent, located.type, located.index, located.arclength + (z - z0).norm(),
                        located.newton_iterations);
  if (point) describe(&*point);
  if (point && !point->check_failure.empty()) return std::nullopt;
  return point;
}

std::optional<ContinuationPoint> Continuation::locate(const ContinuationPoint& from, double h_max,
                                                      const std::function<double(const ContinuationPoint&)>& monitor,
                                                      bool minimise, PointType type, const Eigen::VectorXd* curvature) {
  std::optional<ContinuationPoint> best;
  if (minimise) {
    // The trial points kept by h, so that the minimum's point is not corrected a second time.
    std::optional<ContinuationPoint> lowest;
    double lowest_value = INFINITY;
    auto f = [&](double h) {
      auto p = step_from(from, h, type, curvature);
      const double value = p ? monitor(*p) : INFINITY;
      if (value < lowest_value) {
        lowest_value = value;
        lowest = std::move(p);
      }
      return value;
    };
    // The minimum sought is a branch point's kink (kinked_minimum.hpp): bracketed by the step's
    // ends and its middle, where the march's point lies. Brent where the middle is no bracket.
    const detail::MinimumSample a{0.0, monitor(from)}, b{h_max, f(h_max)}, m{0.5 * h_max, f(0.5 * h_max)};
    const auto kinked = detail::minimise_kinked(f, a, m, b, kLocateTolerance * h_max, kLocateIterations);
    if (!kinked.bracketed) boost::math::tools::brent_find_minima(f, 0.0, h_max, 40);
    best = std::move(lowest);
  } else {
    // Illinois (modified regula falsi) on h: brackets the root and converges superlinearly.
    double a = 0.0, fa = monitor(from), b = h_max;
    auto pb = step_from(from, b, type, curvature);
    if (!pb) return std::nullopt;
    double fb = monitor(*pb);
    best = pb;
    // The monitor's values at the bracket's ends (Illinois halves fa and fb), and the trial
    // with the smallest |monitor|.
    double value_a = fa, value_b = fb;
    std::optional<ContinuationPoint> smallest = pb;
    double smallest_value = std::abs(fb);
    int side = 0;
    for (int it = 0; it < kLocateIterations && std::abs(b - a) > kLocateTolerance * h_max; ++it) {
      const double c = (a * fb - b * fa) / (fb - fa);
      auto pc = step_from(from, c, type, curvature);
      if (!pc) break;  // keep the best estimate so far (e.g. at a singular point)
      const double fc = monitor(*pc);
      if (monitor_is_noise(fc, value_a, value_b, b - a, h_max)) {
        best = smallest;
        break;
      }
      best = pc;
      if (std::abs(fc) < smallest_value) {
        smallest = pc;
        smallest_value = std::abs(fc);
      }
      if (fc == 0.0) break;
      if (sign_of(fc) == sign_of(fb)) {
        b = c;
        fb = value_b = fc;
        if (side == -1) fa *= 0.5;
        side = -1;
      } else {
        a = c;
        fa = value_a = fc;
        if (side == +1) fb *= 0.5;
        side = +1;
      }
      if (std::abs(fc) < 1e-15) break;
    }
  }
  if (best) best->type = type;
  return best;
}


ContinuationResult Continuation::run(const Eigen::VectorXd& x0, const PointSink& sink) {
  ContinuationResult result;
  const double lambda0 = system_->parameter();
  // Corrected at fixed lambda by the system's own solve (a rod's: the damped Newton and fallback
  // search of a single solve), then the tangent oriented towards the target.
  const FixedParameterSolve first = system_->solve_at(x0, lambda0, options_.corrector_tolerance);
  if (!first.converged) {
    result.reason = failed_start_reason(options_.deadline);
    result.message = "the starting point does not converge at " + options_.parameter + " = " +
                     std::to_string(lambda0) + ": " + first.report;
    return result;
  }
  Eigen::VectorXd z = join(first.x, lambda0), e = Eigen::VectorXd::Zero(n_ + 1);
  e[n_] = 1.0;
  int iterations = 0;
  const double direction = std::isnan(options_.target) ? sign_of(options_.direction) : sign_of(options_.target - lambda0);
  std::optional<ContinuationPoint> start;
  const bool corrected = correct(z, z, e, &iterations);
  if (corrected) start = point_at(z, direction * e, PointType::Start, 0, 0.0, iterations);
  if (start) describe(&*start);
  if (!start || !start->check_failure.empty()) {
    // Which of the three: the start converged at fixed lambda above, and each says something else.
    const std::string why = start       ? "the starting point fails its checks: " + start->check_failure
                            : corrected ? "the starting point has no tangent (its matrix [F_x F_lambda], bordered, is "
                                          "singular or not finite; parameters or unknowns decades apart make it so: "
                                          "give the case in units that make them of order 1)"
                                        : "the starting point does not converge: " + last_corrector_failure_;
    result.reason = failed_start_reason(options_.deadline);
    result.message = why + " at " + options_.parameter + " = " + std::to_string(lambda0);
    return result;
  }
  start->step = first_step(options_);
  MarchState state;
  state.current = std::move(*start);
  return march(std::move(state), sink);
}

ContinuationResult Continuation::resume(const MarchState& saved, const PointSink& sink) {
  ContinuationResult failed;
  failed.reason = failed_start_reason(options_.deadline);
  MarchState state = saved;
  auto current = restore(saved.current, true);
  if (!current) {
    failed.message = "cannot resume: the saved point cannot be evaluated (or does not fit this problem)";
    return failed;
  }
  state.current = std::move(*current);
  // Recorded as when it was accepted: the index-change detector compares its stability index
  // with the next candidate's.
  if (options_.detect_index_changes) record(&state.current);
  // The point before serves the quadratic predictor (its tangent and arclength, as saved) and,
  // with its test functions evaluated again, minima of the smallest singular value. Dropped, the
  // resumed run's first step was predicted linearly where the uninterrupted one's was quadratic,
  // and on an ill-conditioned leg (the cavity's flat contact) the two runs parted for good.
  if (saved.before && options_.detect_branch_points) {
    auto before = restore(*saved.before, false);
    if (!before) {
      failed.message = "cannot resume: the point before the saved one cannot be evaluated";
      return failed;
    }
    state.before = std::move(*before);
  } else if (state.before) {
    state.before->jacobian.reset();
  }
  // The saved point is already reported; the rest go to the sink as they are found, so that a
  // resumed run killed again keeps what it had computed.
  ContinuationResult r = march(std::move(state), sink, false);
  if (!r.points.empty()) r.points.erase(r.points.begin());
  return r;
}

ContinuationResult Continuation::resume(const ContinuationPoint& last, const PointSink& sink) {
  MarchState state;
  state.current = last;
  if (!(state.current.step > 0)) state.current.step = first_step(options_);
  return resume(state, sink);
}

std::optional<Eigen::VectorXd> Continuation::leaving_tangent(const ContinuationPoint& point, const Eigen::MatrixXd& A) {
  const detail::ResidualAt residual = [this](const Eigen::VectorXd& z, Eigen::VectorXd* F) {
    std::string failure;
    return evaluate(z, F, nullptr, &failure);
  };
  auto crossing = detail::branch_crossing(A, residual, join(point.x, point.parameter), point.tangent,
                                          options_.branch_point_tolerance);
  if (!crossing) return std::nullopt;
  return std::move(crossing->leaving);
}

void Continuation::settle_branch_point_tangent(ContinuationPoint* point, const Eigen::VectorXd& arrival) {
  if (!point->jacobian || point->jacobian->rows() != n_) return;
  // The arrival projected onto the null space, not the crossing's root: that costs a dozen
  // residuals at every branch point, where only a switch needs it (and solves for it then).
  if (const auto t = detail::arrival_in_null_space(*point->jacobian, arrival, options_.branch_point_tolerance))
    point->tangent = *t;
}

Eigen::MatrixXd Continuation::bifurcation_directions(const ContinuationPoint& point, int count) {
  Eigen::VectorXd F;
  Eigen::MatrixXd A;
  std::string failure;
  if (!evaluate(join(point.x, point.parameter), &F, &A, &failure)) throw std::runtime_error(failure);
  if (count == 1)
    if (auto leaving = leaving_tangent(point, A)) return *leaving;
  // A multiple branch point (or a simple one whose crossing cannot be resolved): the null
  // vectors orthogonal to the tangent.
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  // The last count + 1 right singular vectors span the null space (tangent included).
  Eigen::MatrixXd N = svd.matrixV().rightCols(count + 1);
  N -= point.tangent * (point.tangent.transpose() * N);
  Eigen::JacobiSVD<Eigen::MatrixXd> basis(N, Eigen::ComputeThinU);
  return basis.matrixU().leftCols(count);
}

ContinuationResult Continuation::run_along(const Eigen::VectorXd& x, double lambda, const Eigen::VectorXd& direction,
                                           PointType start_type, const PointSink& sink, const PointRecord* known) {
  ContinuationResult result;
  const Eigen::VectorXd z_bp = join(x, lambda);
  const Eigen::VectorXd d = direction.normalized();
  // The branch point itself: its Jacobian is singular, so it gets no tangent of its own; the
  // direction we leave along stands in for it.
  ContinuationPoint origin;
  origin.x = x;
  origin.parameter = lambda;
  origin.tangent = d;
  origin.type = start_type;
  describe(&origin);
  // The first point a step along d, corrected on the plane normal to d; where the corrector
  // fails, the step is halved (kFirstStepHalvings times at most, not below min_step), as a
  // march's would be: the shallow arch's asymmetric branch from its branch point at w = 39.26
  // was reached on one side (--side -1) and not on the other at the first step, 0.05.
  std::optional<ContinuationPoint> first;
  double h = first_step(options_);
  for (int halving = 0; !first && halving <= kFirstStepHalvings && h >= options_.min_step; ++halving, h *= 0.5) {
    const Eigen::VectorXd z_pred = z_bp + h * d;
    Eigen::VectorXd z = z_pred;
    int iterations = 0;
    if (correct(z, z_pred, d, &iterations))
      first = point_at(z, d, PointType::Regular, 1, (z - z_bp).norm(), iterations);
  }
  if (first) describe(&*first);
  if (!first) {
    result.reason = failed_start_reason(options_.deadline);
    result.message = "no solution along the switching direction (the first step halved down to " + std::to_string(2 * h) +
                     "); the other side (--side -1, or side=-1 in Python) may be reachable";
    return result;
  }
  record(&origin);
  // A branch point's own count is on a knife's edge (its crossing eigenvalue is zero): the
  // soft wall's at Delta = 0.029511 counts 2 with a zero mode, 0 with it as its branch settled it.
  if (known && known->stability_index && origin.stability_index) {
    origin.stability_index = known->stability_index;
    origin.zero_modes = known->zero_modes;
  }
  if (sink) sink(origin);
  first->step = first_step(options_);
  MarchState state;
  state.current = std::move(*first);
  state.points = 2;  // the origin, reported, counts against max_points as a run's start does
  result = march(std::move(state), sink);
  result.points.insert(result.points.begin(), origin);
  return result;
}

ContinuationResult Continuation::switch_branch(const ContinuationPoint& bp, const PointSink& sink, double sign) {
  if (sign != 1.0 && sign != -1.0) throw std::invalid_argument("switch_branch: the side must be 1 or -1");
  Eigen::VectorXd d = bifurcation_directions(bp, 1).col(0);
  // Orientation: the first significant component positive for sign = +1 (e.g. theta(0) > 0 on
  // the buckled Euler column), the mirror branch for sign = -1.
  for (int i = 0; i < d.size(); ++i)
    if (std::abs(d[i]) > 1e-8) {
      d *= sign_of(d[i]) * sign_of(sign);
      break;
    }
  return run_along(bp.x, bp.parameter, d, PointType::BranchPoint, sink, &bp);
}

// The march's working state: MarchState's fields, the result so far and the step size. One step
// is a candidate point (next_candidate), the detectors' special points inside it (detect), those
// put on the branch with their actions (take_special), then the candidate itself (advance).
struct Continuation::Marcher {
  Marcher(Continuation& engine, const PointSink& point_sink, MarchState state)
      : c(engine),
        o(engine.options_),
        sink(point_sink),
        current(std::move(state.current)),
        before(std::move(state.before)),
        previous_h(state.previous_step),
        just_reported_branch_point(state.just_reported_branch_point),
        points_before(state.points - 1),
        ds(current.step > 0 ? current.step : first_step(engine.options_)) {
    counters.branch_points_found = state.branch_points_found;
    result.refused_steps = state.refused_steps;
  }

  Continuation& c;
  const ContinuationOptions& o;
  const PointSink& sink;
  ContinuationResult result;
  ContinuationPoint current;
  std::optional<ContinuationPoint> before;  // the point before `current`, for minima
  double previous_h;
  bool just_reported_branch_point;
  detail::MarchCounters counters;
  // Points of this march made before `current` (by the run that a resumed one continues): they
  // count against max_points as if it had not been interrupted.
  int points_before;
  double ds;
  // Only branch points keep their matrix in the branch (for switching); the newest point's moves
  // on to `current`, for the next corrector's chord. A long branch keeping every one would hold
  // n^2 doubles per point.
  std::shared_ptr<const Eigen::MatrixXd> newest_matrix;
  bool candidate_recorded = false;  // the step's candidate was recorded (before detection, or by take_special)

  bool has_room() const { return points_before + static_cast<int>(result.points.size()) < o.max_points; }

  ContinuationResult stop(StopReason reason, std::string message = {}) {
    result.reason = reason;
    result.message = std::move(message);
    return std::move(result);
  }

  // The march's state right after `current` was accepted, for a run to resume from.
  void report_state() {
    if (!o.on_resumable || !resumable_type(current.type)) return;
    MarchState now;
    now.current = result.points.back();
    now.before = before;
    if (now.before) now.before->jacobian.reset();
    now.previous_step = previous_h;
    now.just_reported_branch_point = just_reported_branch_point;
    now.branch_points_found = counters.branch_points_found;
    now.points = points_before + static_cast<int>(result.points.size());
    now.refused_steps = result.refused_steps;
    o.on_resumable(now);
  }

  void start(bool report) {
    if (report) c.record(&current);
    result.points.push_back(current);
    if (current.type != PointType::BranchPoint) result.points.back().jacobian.reset();
    if (!report) return;
    if (sink) sink(current);
    report_state();
  }

  // Puts p on the branch: recorded (unless it was), then reported. A fold or branch point takes
  // its index from its neighbours where its own count disagrees (singular_point_index.hpp): the
  // regular points on either side of it along the branch, `after` being the step's candidate,
  // recorded before it.
  void accept(ContinuationPoint p, bool recorded = false, const ContinuationPoint* after = nullptr) {
    p.index = result.points.back().index + 1;
    p.step = ds;
    newest_matrix = std::move(p.jacobian);
    p.jacobian = p.type == PointType::BranchPoint ? newest_matrix : nullptr;
    if (!recorded) c.record(&p);
    if (after && (p.type == PointType::Fold || p.type == PointType::BranchPoint)) {
      // An even branch point may lie just behind `current` (between `before` and it).
      const bool behind = before && p.arclength < current.arclength;
      if (p.type == PointType::BranchPoint) c.settle_branch_point_tangent(&p, behind ? before->tangent : current.tangent);
      detail::settle_singular_point_index(&p, behind ? *before : current, behind ? current : *after);
    }
    result.points.push_back(std::move(p));
    if (sink) sink(result.points.back());
  }

  // A point that kept an older matrix (reuse_jacobian_iterations) gets its own before the step
  // is shrunk: the stale matrix, not the step, may be what failed the corrector or turned the
  // tangent, and shrinking alone then crawls (seen at L/2R = 500: steps of 1e-6 for 1,400 points).
  bool refresh_current() {
    if (!current.jacobian_reused) return false;
    auto fresh = c.point_at(c.join(current.x, current.parameter), current.tangent, current.type, current.index,
                            current.arclength, current.newton_iterations);
    if (!fresh) return false;
    fresh->step = current.step;
    // Same unknowns and parameter: the same description, not computed again.
    static_cast<PointRecord&>(*fresh) = static_cast<const PointRecord&>(current);
    current = std::move(*fresh);
    return true;
  }

  // The branch's curvature at `current`, d t / d s from the tangents of `before` and `current`
  // and the arclength between them, for the quadratic predictor (StepControl::predictor). None
  // where the two points are not consecutive points of one smooth piece of branch (a start, a
  // resumed state without its predecessor, a tangent turned by more than max_tangent_angle).
  std::optional<Eigen::VectorXd> branch_curvature() const {
    if (o.predictor != StepControl::Predictor::Quadratic || !before) return std::nullopt;
    if (!resumable_type(before->type) || !resumable_type(current.type)) return std::nullopt;
    const double ds_between = current.arclength - before->arclength;
    if (!(ds_between > 0.0) || before->tangent.size() != current.tangent.size()) return std::nullopt;
    if (!(current.tangent.dot(before->tangent) > std::cos(o.max_tangent_angle))) return std::nullopt;
    return Eigen::VectorXd((current.tangent - before->tangent) / ds_between);
  }

  // The corrected point a step ds ahead, if it is taken: a corrector failure, a turn of the
  // tangent beyond max_tangent_angle or a refusal of step_check shortens the step instead (none),
  // down to the minimum step, where the run stops (*stop).
  std::optional<ContinuationPoint> next_candidate(std::optional<detail::Stop>* stop) {
    const std::optional<Eigen::VectorXd> curvature = branch_curvature();
    auto candidate = c.step_from(current, ds, PointType::Regular, curvature ? &*curvature : nullptr);
    if (!candidate) {
      if (refresh_current()) return std::nullopt;
      ds *= kShrink;
      if (ds < o.min_step)
        *stop = {StopReason::StepTooSmall,
                 "the corrector failed down to the minimum step (last failure: " + c.last_corrector_failure_ + ")"};
      return std::nullopt;
    }
    const double angle = std::acos(std::clamp(current.tangent.dot(candidate->tangent), -1.0, 1.0));
    if (angle > o.max_tangent_angle && ds > o.min_step) {
      if (!refresh_current()) ds = std::max(ds * kShrink, o.min_step);
      return std::nullopt;
    }
    const std::string refusal = o.step_check ? o.step_check(current, *candidate) : std::string();
    if (refusal.empty()) return candidate;
    ++result.refused_steps;
    if (ds * kShrink < o.min_step)
      *stop = {StopReason::Inadmissible, refusal + " (refused down to the minimum step)"};
    else
      ds *= kShrink;
    return std::nullopt;
  }

  // Every detector on the step current -> candidate, in order; false: one asks for the step
  // again, shorter.
  bool detect(const std::vector<std::unique_ptr<detail::Detector>>& detectors, const ContinuationPoint& candidate,
              std::vector<detail::Detection>* found) {
    const detail::StepView step{current, candidate, before ? &*before : nullptr, ds, previous_h,
                                just_reported_branch_point, ds * kShrink >= o.min_step,
                                [this](const ContinuationPoint& from, double h_max, const detail::TestFunction& test,
                                       bool minimise, PointType type) {
                                  // From `current`, the march's own predictor: the trial of the
                                  // whole step then starts where the candidate's corrector did.
                                  const bool from_current = from.index == current.index &&
                                                            from.arclength == current.arclength;
                                  const auto curvature = from_current ? branch_curvature() : std::nullopt;
                                  return c.locate(from, h_max, test, minimise, type,
                                                  curvature ? &*curvature : nullptr);
                                },
                                [this](const ContinuationPoint& located, double value) {
                                  return c.at_parameter(located, value);
                                },
                                [this](double h) {
                                  const auto curvature = branch_curvature();
                                  auto p = c.step_from(current, h, PointType::IndexChange,
                                                       curvature ? &*curvature : nullptr);
                                  if (p) c.record(&*p);
                                  return p;
                                }};
    for (const auto& d : detectors)
      if (d->detect(step, found) == detail::Verdict::RetryShorter) return false;
    return true;
  }

  // The special points of a step on the branch, in order along it, each acted on by its detector.
  // A step in which a stopping detector found its point ends the run at its first end point, or
  // with a stopping event at its first event point (the reason of the last such detection).
  std::optional<detail::Stop> take_special(std::vector<detail::Detection> found, ContinuationPoint* candidate) {
    const bool singular = std::any_of(found.begin(), found.end(), [](const detail::Detection& d) {
      return d.point.type == PointType::Fold || d.point.type == PointType::BranchPoint;
    });
    // The candidate is recorded first where the step holds a singular point, whose index its
    // neighbours settle (if detect() has not recorded it already).
    if (singular && !candidate_recorded) {
      c.record(candidate);
      candidate_recorded = true;
    }
    std::optional<StopReason> step_stop;
    for (const auto& d : found)
      if (d.stop) step_stop = d.stop;
    const double s0 = current.arclength;
    std::sort(found.begin(), found.end(), [s0](const detail::Detection& a, const detail::Detection& b) {
      return a.point.arclength - s0 < b.point.arclength - s0;
    });
    just_reported_branch_point = std::any_of(found.begin(), found.end(), [](const detail::Detection& d) {
      return d.point.type == PointType::BranchPoint;
    });
    const ContinuationPoint* after = singular ? settling_neighbour(&found, candidate, step_stop) : nullptr;
    for (auto& d : found) {
      accept(d.point, d.recorded, after);
      const ContinuationPoint& p = result.points.back();
      if (auto s = d.detector->act(p, &counters)) return s;
      // An end point stops with its own reason: a contact leg's stopping event found beyond the
      // target in the same step does not make the target an event.
      if (step_stop && p.type == PointType::Endpoint) return detail::Stop{d.stop.value_or(*step_stop), ""};
      if (step_stop == StopReason::EventStop && p.type == PointType::Event)
        return detail::Stop{StopReason::EventStop, "event " + p.event};
      // A step can hold special points besides its candidate: the run's points are spent at one.
      if (!has_room()) return detail::Stop{StopReason::MaxPoints, ""};
    }
    return std::nullopt;
  }

  // The regular point after the step's singular points that settles their index: the candidate,
  // or the point where the run ends inside the step (its target, a stopping event), recorded
  // here. Beyond that point the candidate is off the reported branch and may lie past more
  // singular points: the Euler column continued in EI to 0.05 settled its branch point at
  // 0.0563 against the candidate at 0.0247, four branch points on, and gave it four zero modes.
  const ContinuationPoint* settling_neighbour(std::vector<detail::Detection>* found, const ContinuationPoint* candidate,
                                             std::optional<StopReason> step_stop) {
    const double s0 = current.arclength;
    double last_singular = -std::numeric_limits<double>::infinity();
    for (const auto& d : *found)
      if (d.point.type == PointType::Fold || d.point.type == PointType::BranchPoint)
        last_singular = std::max(last_singular, d.point.arclength - s0);
    for (auto& d : *found) {
      const bool ends_run =
          d.point.type == PointType::Endpoint || (d.point.type == PointType::Event && step_stop == StopReason::EventStop);
      if (!ends_run || !(d.point.arclength - s0 > last_singular)) continue;
      if (!d.recorded) c.record(&d.point);
      d.recorded = true;
      return &d.point;
    }
    return candidate;
  }

  // The candidate on the branch as the new current point. The next step is decided before the
  // point is reported, so that a run resumed from it takes the same step as the uninterrupted one.
  void advance(ContinuationPoint candidate) {
    const int iterations = candidate.newton_iterations;
    before = std::move(current);
    previous_h = ds;
    if (iterations <= o.grow_iterations) ds = std::min(ds * kGrow, longest_step(o, candidate.x));
    if (iterations >= o.shrink_iterations) ds = std::max(ds * kShrink, o.min_step);
    accept(std::move(candidate), candidate_recorded);
    candidate_recorded = false;
    current = result.points.back();
    current.jacobian = std::move(newest_matrix);
    report_state();
  }
};

ContinuationResult Continuation::march(MarchState state, const PointSink& sink, bool report_start) {
  Marcher m(*this, sink, std::move(state));
  m.start(report_start);
  const auto detectors = detail::make_detectors(options_, n_);
  while (m.has_room()) {
    if (std::chrono::steady_clock::now() >= options_.deadline)
      return m.stop(StopReason::TimeLimit, "the wall-clock limit was reached");
    std::optional<detail::Stop> stop;
    auto candidate = m.next_candidate(&stop);
    if (stop) return m.stop(stop->first, stop->second);
    if (!candidate) continue;
    std::vector<detail::Detection> found;
    // The index-change detector compares the candidate's stability with the current point's.
    if (options_.detect_index_changes) {
      record(&*candidate);
      m.candidate_recorded = true;
    }
    if (!m.detect(detectors, *candidate, &found)) {
      m.candidate_recorded = false;
      m.ds *= kShrink;
      continue;
    }
    if (auto s = m.take_special(std::move(found), &*candidate)) return m.stop(s->first, s->second);
    m.advance(std::move(*candidate));
  }
  return m.stop(StopReason::MaxPoints);
}

}  // namespace kirchhoff

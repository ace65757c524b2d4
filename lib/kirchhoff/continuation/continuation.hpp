// Pseudo-arclength continuation of a parameterised system F(x, lambda) = 0
// (parameterised_system.hpp; a rod's shooting problem is one, shooting_system.hpp), with fold and
// branch-point detection and location, branch switching, events and resumable runs.
//
// The branch is a curve z(sigma) = (x, lambda) of solutions of F(x; lambda) = 0, where x are the
// system's unknowns (a rod's shooting unknowns) and lambda the continued parameter. Each step
// predicts along the tangent t,
// then corrects with Newton on the bordered system
//     [ F_x  F_lambda ] dz = -[ F                  ]
//     [      t^T      ]      [ t.(z - z_predicted) ],
// and the new tangent solves [F_x F_lambda; t_old^T] t = [0; 1]. Along the way:
//   - folds: the lambda component of t changes sign;
//   - simple branch points: det [F_x F_lambda; t^T] changes sign;
//   - branch points of any multiplicity (e.g. the double one of the isotropic twisted rod, where
//     the determinant keeps its sign): a local minimum of the smallest singular value of the
//     bordered matrix that, located, falls below branch_point_tolerance; the number of such small
//     singular values beyond those of the regular point beside it is the multiplicity;
//   - events: a derived quantity crosses a given value.
#pragma once

#include <any>
#include <chrono>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kirchhoff/continuation/parameterised_system.hpp"

namespace kirchhoff {

// A derived quantity crossing a value: recorded as a point, and the run stops when `stop`.
struct ContinuationEvent {
  std::string quantity;  // a name from derived_catalogue()
  double value = 0.0;
  bool stop = true;
  std::string label;     // recorded in the point's `event` (default: "quantity=value")
};

struct ContinuationPoint;
struct MarchState;

// What a run records of a point besides its unknowns, parameter, tangent and counts, supplied by
// the layer that knows what the unknowns mean (BifurcationKit's record_from_solution is the
// model; point_record.hpp is the rod layer's). The hooks get the system followed (a rod's reads its
// problem at the point's parameter through shooting_problem_at) and the point; the engine
// interprets only `derived` (events read their quantities there) and `check_failure` (non-empty:
// the corrected point is not a solution, the step is refused) of what they fill.
struct PointRecorder {
  // At most once per corrected point, before the engine tests it (events, admissibility); a
  // point whose matrix is re-evaluated keeps what it was given. Empty: nothing is described.
  std::function<void(ParameterisedSystem& system, ContinuationPoint* point)> describe;
  // Once per point put on the branch (the start, regular and special points reported), after
  // `describe`: what only the branch's points need (e.g. their stability). Empty: nothing.
  std::function<void(ParameterisedSystem& system, ContinuationPoint* point)> record;
};

// The options of a run, in groups (Ceres's Solver::Options and BifurcationKit's ContParams are the
// models): each group says what it controls and checks itself (validate(): "" or what is wrong);
// ContinuationOptions derives from all of them, so a run's options are still set field by field
// (options.max_step = 1) and a group can be handed on whole (StepControl& step = options).

// Where a run goes and when it stops for reasons of its own.
struct ContinuationRange {
  std::string parameter;                                      // the continued parameter
  double target = std::numeric_limits<double>::quiet_NaN();   // stop on reaching it (NaN: no target)
  double direction = 1.0;           // initial direction of lambda (+1/-1), used when there is no target
  double parameter_min = -std::numeric_limits<double>::infinity();
  double parameter_max = std::numeric_limits<double>::infinity();
  int max_points = 500;
  // No step starts after this instant (a command's wall-clock limit; every point before it is
  // reported and resumable). Stop reason time_limit.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();

  std::string validate() const;
};

// The pseudo-arclength step and how it adapts.
struct StepControl {
  double initial_step = 0.05;       // pseudo-arclength step
  double min_step = 1e-7;           // below this the run stops (step_too_small)
  double max_step = 0.5;
  // > 0: max_step is meant for unknowns of this size (|x|), and where they are larger the bound
  // grows with them, max_step |x| / max_step_reference_size: a path whose unknowns grow by
  // orders of magnitude (a homotopy to a load of 3e4 from 12, or to a stiffness of 2e11 from 1)
  // then takes steps of its own scale, not thousands of the start's. 0: max_step alone.
  double max_step_reference_size = 0.0;
  double max_tangent_angle = 0.35;  // rad; a step turning the tangent more is retried shorter
  // A corrector that needed at most grow_iterations lets the step grow, at least
  // shrink_iterations shrink it (chord iterations contract linearly, so a good step takes three
  // or four). Where a point's Jacobian and derived quantities cost many residual evaluations
  // (long multiple-shooting rods), more chord iterations on longer steps are cheaper per unit of
  // branch: raise both.
  int grow_iterations = 4;
  int shrink_iterations = 7;
  // The predictor: the tangent alone (z + h t), or with the branch's curvature estimated from
  // the tangents of the last two points (z + h t + h^2/2 dt/ds), an error of O(h^3) instead of
  // O(h^2): along the Euler column's and the twisted rod's branches it lands 26 and 79 times
  // closer to the corrected point (continuation_benchmark --once euler-predictor). The first
  // step from a start, a branch point or a resumed state without its previous point is
  // predicted along the tangent.
  enum class Predictor { Tangent, Quadratic };
  Predictor predictor = Predictor::Quadratic;

  std::string validate() const;
};

// The corrector: chord (or modified Newton) iterations on the bordered system, and the matrices
// they use.
struct CorrectorOptions {
  int corrector_max_iterations = 8;
  // A point whose corrector converged by at most this many chord iterations on the previous
  // point's matrix keeps that matrix (for its tangent and the next chord) instead of evaluating
  // its own - the variational equations are most of a point's cost on long multiple-shooting
  // rods. -1: every point evaluates its own (needed for branch points and exact tangents).
  int reuse_jacobian_iterations = -1;
  // Modified Newton in the corrector: a matrix, once evaluated, is kept for the following
  // iterations while each reduces the residual by half, instead of one matrix per iteration.
  // Where the matrix costs tens of residuals (the variational equations of long multiple-shooting
  // rods) this is far cheaper per point.
  bool modified_newton = false;
  // On max |F| and |arclength condition|; NaN: 1e-10, or the problem's Newton residual tolerance
  // (a case's [solver] tolerance) when that is looser - rods with large forces need it.
  double corrector_tolerance = std::numeric_limits<double>::quiet_NaN();

  std::string validate() const;
};

// The special points a run looks for, and which of them stop it.
struct DetectionOptions {
  bool detect_folds = true;
  bool detect_branch_points = true;
  // Located branch point: smallest singular value of the bordered matrix below this times the
  // largest one. Away from branch points it is O(1e-2) or more on rod problems; located
  // points reach ~1e-12.
  double branch_point_tolerance = 1e-7;
  std::vector<ContinuationEvent> events;
  int stop_at_branch_point = 0;       // > 0: stop once this many branch points have been found
  bool stop_at_fold = false;          // stop at the first fold (a homotopy that must not turn back)
  // Where the recorder gives the stability index (PointRecord::stability_index), a change of it
  // inside a step with no fold or branch point there is located (PointType::IndexChange): a
  // bifurcation this problem's Jacobian does not see, such as one breaking the symmetry of a
  // problem posed on half a rod (BifurcationKit's detection by the count of unstable
  // eigenvalues). Each step's candidate is then recorded before the detectors look at it.
  bool detect_index_changes = true;

  std::string validate() const;
};

// What a run records at each point.
struct RecordOptions {
  // Quantities the recorder computes at every point by name (derived, available to events; the
  // events' own quantities are added to them).
  std::vector<std::string> derived;
  // What is recorded at each point; nullopt: the default of the layer that built the system (a
  // rod's: rod_point_recorder, point_record.hpp; none for a plain system).
  std::optional<PointRecorder> recorder;

  std::string validate() const;
};

struct ContinuationOptions : ContinuationRange, StepControl, CorrectorOptions, DetectionOptions, RecordOptions {
  // A check of each step that a converged corrector cannot make (that the rod did not pass
  // through itself: SelfPassageGuard): a non-empty answer refuses the step, which is retried
  // shorter; refused at the minimum step, the run stops as Inadmissible with that answer.
  std::function<std::string(const ContinuationPoint& from, const ContinuationPoint& to)> step_check;
  // Called right after the point sink with every point a run can resume from (start and regular
  // points), with the march's whole state there: saved, it lets Continuation::resume take the
  // same steps as the uninterrupted run (see MarchState). Contact continuations report through
  // their own ContactStateSink instead (it adds the leg's state) and replace this one.
  std::function<void(const MarchState&)> on_resumable;

  // Every group's validate(), then the rules between groups.
  std::string validate() const;
};

enum class PointType { Start, Regular, Fold, BranchPoint, Event, Endpoint, IndexChange };
const char* to_string(PointType type);

// What the recorder (PointRecorder) fills; the engine computes none of it. The rod layer's
// default fills every field (rod_point_recorder).
struct PointRecord {
  std::map<std::string, double> derived;  // named quantities (events read theirs here)
  // With compute_stability: the index (empty where it is not defined) and the zero modes.
  std::optional<int> stability_index;
  int zero_modes = 0;
  std::string stability_reason;  // why stability_index is empty (with compute_stability), else empty
  // Why the point failed the checks of a solution (verification.hpp: a profile with NaN, a rod
  // beyond its soft wall), "" when it passed. Such a point is never put on a branch.
  std::string check_failure;
  // Whatever else the recorder keeps of the point, which the engine carries without reading: a
  // rod's invariants and the flatness of its H (analysis/point_record.hpp: invariants_of, H_is_flat).
  std::any extra;
};

struct ContinuationPoint : PointRecord {
  int index = 0;
  double parameter = 0.0;
  double arclength = 0.0;
  Eigen::VectorXd x;        // shooting unknowns
  Eigen::VectorXd tangent;  // (dx, dlambda), unit
  PointType type = PointType::Regular;
  int multiplicity = 0;     // branch points: small singular values beyond a regular neighbour's
  int newton_iterations = 0;
  bool jacobian_reused = false;  // its matrix is the previous point's (reuse_jacobian_iterations)
  std::string event;        // events: the quantity that crossed
  int event_index = -1;     // events: which of the options' events crossed (its index there)
  double step = 0.0;        // step size after this point
  // Test functions: det [F_x F_lambda; t^T], and the smallest singular value of that matrix
  // over its largest, with the count of singular values below branch_point_tolerance (both left
  // at 0 when the run does not detect branch points).
  double determinant = 0.0;
  double smallest_singular = 0.0;
  int small_count = 0;
  // [F_x F_lambda] at this point: the next corrector starts with chord iterations on it. Shared:
  // a point that keeps the previous point's matrix (reuse_jacobian_iterations) shares it rather
  // than copying tens of megabytes on long rods. Empty once a point is recorded in a branch
  // (branch points keep theirs, for switching).
  std::shared_ptr<const Eigen::MatrixXd> jacobian;
};

// Everything the march's next step depends on besides the problem and the options, as it stands
// right after the march has reported `current`. Re-deriving any of it on resume changed results:
// the tangent recomputed from a bordering row other than the previous tangent differs in its
// last bits (and with it every later step on ill-conditioned legs), a run without the point
// before `current` cannot see a minimum of the smallest singular value that spans the resume,
// and the counts (points against max_points, branch points against stop_at_branch_point) were
// re-derived from the CSV with off-by-one differences. Restored instead, a resumed march repeats
// the uninterrupted one bit for bit: the matrices, test functions and derived quantities of both
// points are recomputed from their x and parameter, which are deterministic functions of them.
struct MarchState {
  // x, parameter, tangent (its own, as computed when the point was accepted), arclength, index,
  // type, newton_iterations and step (the size of the next step).
  ContinuationPoint current;
  // The point before `current` (same fields) and the step between them: a branch point of even
  // multiplicity is a minimum over these two steps. Empty at the start of a march.
  std::optional<ContinuationPoint> before;
  double previous_step = 0.0;
  bool just_reported_branch_point = false;  // the step that found `current` found a branch point too
  int branch_points_found = 0;              // for stop_at_branch_point
  int points = 1;                           // the march's points so far, `current` included (max_points)
  int refused_steps = 0;
};

// Inadmissible: a contact continuation reached a point that penetrates an obstacle or has a
// pulling contact with no event located before it (reported, not followed).
enum class StopReason { ReachedTarget, MaxPoints, ParameterBounds, StepTooSmall, EventStop, BranchPointStop, StartFailed,
                        Inadmissible, TimeLimit, FoldStop };
const char* to_string(StopReason reason);
// Why a start that did not converge stopped the run: time_limit where the wall-clock limit had
// passed by then (its Newton stopped by the limit, say), which a driver resumes; else start_failed.
StopReason failed_start_reason(std::chrono::steady_clock::time_point deadline);

struct ContinuationResult {
  std::vector<ContinuationPoint> points;
  StopReason reason = StopReason::MaxPoints;
  std::string message;
  int refused_steps = 0;  // steps the options' step_check refused (each retried shorter)
};

// Called for every accepted point, in order, as soon as it is known (CSV writers, progress).
using PointSink = std::function<void(const ContinuationPoint&)>;

class Continuation {
 public:
  // Any system F(x, lambda) = 0, starting at its parameter(). Without a recorder in the options
  // its points carry what the engine computes (x, parameter, tangent, test functions) only.
  Continuation(std::unique_ptr<ParameterisedSystem> system, ContinuationOptions options);
  // (A rod's shooting problem: RodContinuation, rod_continuation.hpp.)
  virtual ~Continuation() = default;

  // Starts from unknowns x0 (corrected at fixed lambda first).
  ContinuationResult run(const Eigen::VectorXd& x0, const PointSink& sink = {});
  // Resumes a march from its state at one of its points (reported by options.on_resumable),
  // taking the same steps as the uninterrupted run. The state's `current` is not reported again.
  // (With reuse_jacobian_iterations the uninterrupted run's matrix at `current` may be an older
  // point's; the resumed one evaluates its own, so the steps after it agree to the corrector's
  // tolerance, not bit for bit.)
  ContinuationResult resume(const MarchState& state, const PointSink& sink = {});
  // Resumes from a point alone (its x, parameter, tangent, step, index, arclength), as a march
  // that starts there: what the point does not record (see MarchState) starts afresh.
  ContinuationResult resume(const ContinuationPoint& last, const PointSink& sink = {});
  // Starts on the branch crossing the one of `branch_point` (a located simple branch point):
  // direction from the null space of [F_x F_lambda] orthogonal to the old tangent, oriented so
  // that its first significant component is positive (sign = +1) or negative (sign = -1).
  ContinuationResult switch_branch(const ContinuationPoint& branch_point, const PointSink& sink = {},
                                   double sign = 1.0);
  // Starts at z = (x, lambda) (a branch point of another formulation, say) along the unit
  // direction d: the first point is reached by a step of initial_step along d, corrected on the
  // hyperplane normal to d. The start point itself is reported with the given type, and with the
  // stability of `known` where that has an index (the branch point switched at, as its own
  // branch settled it from both neighbours: singular_point_index.hpp).
  ContinuationResult run_along(const Eigen::VectorXd& x, double lambda, const Eigen::VectorXd& direction,
                               PointType start_type, const PointSink& sink = {},
                               const PointRecord* known = nullptr);

  // Directions leaving a branch point along the branches that bifurcate there, unit vectors.
  // count = 1, a simple branch point: the other branch's tangent, from the algebraic bifurcation
  // equation (detail/branch_crossing.hpp), the point's tangent being the arriving branch's. Where
  // that equation cannot be resolved, and for count > 1: null vectors of [F_x F_lambda],
  // orthonormal, orthogonal to the point's tangent.
  Eigen::MatrixXd bifurcation_directions(const ContinuationPoint& point, int count);

  const ParameterisedSystem& system() const { return *system_; }
  const ContinuationOptions& options() const { return options_; }
  // Evaluations of F alone and of F with its matrix [F_x F_lambda] (the variational equations)
  // so far: the cost of a branch on long rods, where a matrix costs tens of residuals.
  struct EvaluationCount {
    long residuals = 0;
    long matrices = 0;
  };
  const EvaluationCount& evaluations() const { return evaluations_; }

 protected:
  // As the public constructor, with the recorder used when the options give none, made from the
  // options as configured (their derived list completed with the events' quantities).
  using DefaultRecorder = std::function<PointRecorder(const ContinuationOptions& configured)>;
  Continuation(std::unique_ptr<ParameterisedSystem> system, ContinuationOptions options,
               const DefaultRecorder& default_recorder);

 private:
  // F at z = (x, lambda), with A = [F_x F_lambda] when A is given; with `march` the matrix may be
  // the system's approximate one (ParameterisedSystem::has_approximate_matrices).
  bool evaluate(const Eigen::VectorXd& z, Eigen::VectorXd* F, Eigen::MatrixXd* A, std::string* failure,
                bool march = false);
  // A at z alone, where F is known there or not needed: the march's approximate matrix without
  // F's evaluation (ParameterisedSystem::approximate_matrix), else evaluate's, F thrown away.
  bool matrix_alone(const Eigen::VectorXd& z, Eigen::MatrixXd* A, std::string* failure, bool march);
  // The tangent of the branch crossing the point's own at a simple branch point whose matrix is
  // A, the point's tangent telling the arriving root (detail/branch_crossing.hpp); empty where not
  // resolved.
  std::optional<Eigen::VectorXd> leaving_tangent(const ContinuationPoint& point, const Eigen::MatrixXd& A);
  // A located branch point's bordered tangent solves a singular system: its component along the
  // second null vector is noise over a vanishing singular value, of order one. Replaced, where the
  // null space is two-dimensional, by `arrival` (the tangent of the regular point before it)
  // projected onto it, by which the switch tells the arriving branch's root from the other.
  void settle_branch_point_tangent(ContinuationPoint* point, const Eigen::VectorXd& arrival);
  // Newton on [F; normal.(z - z_predicted)] = 0. With `chord` (the Jacobian at a nearby point)
  // it first iterates with that fixed matrix, one integration without sensitivities per
  // iteration, and turns to (modified, with options_.modified_newton) Newton only if those
  // iterations stop contracting. With `march` its matrices are the march's (the system's
  // approximate ones, where it has them).
  // Where it converges on a matrix evaluated at the final z (Newton's last iteration), that
  // matrix goes to *matrix_at_z, else it is left empty.
  bool correct(Eigen::VectorXd& z, const Eigen::VectorXd& z_predicted, const Eigen::VectorXd& normal,
               int* iterations, const Eigen::MatrixXd* chord = nullptr, bool* by_chord = nullptr,
               bool march = false, std::shared_ptr<const Eigen::MatrixXd>* matrix_at_z = nullptr);
  // Tangent at z oriented by `previous`, with the test functions, as a point (not described).
  // With `given`, that matrix stands for [F_x F_lambda] at z (no evaluation): the previous
  // point's, kept (reuse_jacobian_iterations), or with given_is_own one evaluated at z.
  std::optional<ContinuationPoint> point_at(const Eigen::VectorXd& z, const Eigen::VectorXd& previous, PointType type,
                                            int index, double arclength, int iterations,
                                            std::shared_ptr<const Eigen::MatrixXd> given = nullptr,
                                            bool given_is_own = false);
  // The matrix and test functions of a saved point, its tangent kept, and its description when
  // asked for.
  std::optional<ContinuationPoint> restore(const ContinuationPoint& saved, bool with_description);
  // The point at z with tangent t and matrix A = [F_x F_lambda] there: the test functions.
  ContinuationPoint make_point(const Eigen::VectorXd& z, const Eigen::VectorXd& t,
                               std::shared_ptr<const Eigen::MatrixXd> A, bool reused, PointType type, int index,
                               double arclength, int iterations);
  // Marches on from `state` (its `current` reported to the sink first when report_start): the
  // steps, and the special points the detectors (continuation_detectors.hpp) find inside them.
  ContinuationResult march(MarchState state, const PointSink& sink, bool report_start = true);
  struct Marcher;  // the march's working state and its parts (continuation.cpp)
  // Locates where `monitor` (of the point reached from `from` by a step h, predicted with the
  // curvature where given) vanishes or is minimal, by the secant method or Brent on h in
  // (0, h_max].
  std::optional<ContinuationPoint> locate(const ContinuationPoint& from, double h_max,
                                          const std::function<double(const ContinuationPoint&)>& monitor,
                                          bool minimise, PointType type, const Eigen::VectorXd* curvature = nullptr);
  // The recorder's description of a corrected point (its x and parameter set), and what it
  // records of a point put on the branch.
  void describe(ContinuationPoint* point);
  void record(ContinuationPoint* point);
  // The point corrected from the predictor z + h t (+ h^2/2 curvature, where given) on the
  // hyperplane through it normal to from's tangent.
  std::optional<ContinuationPoint> step_from(const ContinuationPoint& from, double h, PointType type,
                                             const Eigen::VectorXd* curvature = nullptr);
  // `located` (a point found by locate) corrected again at the parameter `value` exactly, with
  // the problem's own matrices: a run's end lies on its target, not within the location's
  // tolerance of it. Empty if that corrector fails.
  std::optional<ContinuationPoint> at_parameter(const ContinuationPoint& located, double value);
  Eigen::VectorXd join(const Eigen::VectorXd& x, double lambda) const;
  // What the constructor does once the system is there: the corrector's default tolerance, the
  // events' quantities among the derived ones, the size.
  void configure();

  std::unique_ptr<ParameterisedSystem> system_;
  ContinuationOptions options_;
  int n_ = 0;  // number of unknowns x
  EvaluationCount evaluations_;
  std::string last_corrector_failure_;  // why the last failed corrector failed, for the stop message
};

}  // namespace kirchhoff

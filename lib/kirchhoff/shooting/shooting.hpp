// Shooting for rod equilibria: single or multiple shooting on the rod equations, with boundary
// conditions at both ends and unknown parameters balanced by extra conditions.
//
// Unknowns x = [y(s_0), ..., y(s_{M-1}), p_unknown] for M segments s_0 = 0 < ... < s_M = L.
// Residuals, in order: the equations' gauge conditions at s = 0, the start conditions, the
// continuity y(s_{i+1}^-) - y(s_{i+1}) for interior nodes, the end conditions. Extra conditions
// sit with the conditions of their end. The Jacobian comes from the variational equations
// (state-transition matrices); parameters that enter the rod model are differentiated by
// central differences of the flow (the unfolding couple of the axial phase condition from the
// flows' own sensitivity where the equations carry it: SegmentFlow::dy_dunfolding), those that
// enter only the boundary conditions by central differences of the (closed-form) conditions.
#pragma once

#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "kirchhoff/equations/integrator.hpp"
#include "kirchhoff/equations/rod_equations.hpp"
#include "kirchhoff/model/obstacle.hpp"
#include "kirchhoff/model/parameters.hpp"
#include "kirchhoff/shooting/boundary_conditions.hpp"
#include "kirchhoff/shooting/newton.hpp"
#include "kirchhoff/shooting/shooting_workspace.hpp"

namespace kirchhoff {

enum class RodKind { Spatial, Planar };

// A point of the active contact set: the rod touches obstacle `obstacle` at arclength s and
// receives the force `force` * nu there, nu the obstacle's unit normal at the contact
// (0 <= g perp force >= 0). Both s and force are unknowns of the problem; these are their guesses,
// or their values once solved. At the contact the centreline is on the obstacle (g = 0) and
// tangent to it (g' = 0); n jumps by -force * nu.
struct PointContact {
  int obstacle = 0;
  double s = 0.0;
  double force = 0.0;
  // Extended contact: the rod lies on the obstacle over [s, s_end], held by the
  // forces `force` at s and `force_end` at s_end. On a plane it is straight and free of moment,
  // and a flat wall carries no distributed force there (n_y' = 0 and m = 0 on the interval). On a
  // disc (a cylinder along e_z) it wraps around it: curvature 1/radius, constant moment, n along
  // the tangent with a constant tension N, pressing on the disc with p = N / radius (admissible
  // while N >= 0). At s: g = 0, tangency, the obstacle's curvature (m = B2 (kappa - u_hat2)) and
  // no normal force just after s; s_end and force_end are set by the rest. A spatial rod on a
  // cylinder lies on it with the pressure that keeps it there (rod_on_cylinder.hpp): at s it is
  // on the cylinder with g = g' = g'' = 0 and g''' = 0 after the edge force.
  bool extended = false;
  double s_end = 0.0;
  double force_end = 0.0;
  int unknowns() const { return extended ? 4 : 2; }
};

// Why an extended contact on this obstacle is not modelled for this rod, or "" when it is: planes
// for planar rods; discs for uniform, inextensible planar rods without an external field, where
// the wrapped part is known in closed form (the section turns rigidly about the disc's centre);
// cylinders for the spatial rods rod_on_cylinder.hpp models (isotropic, uniform, naturally
// straight Kirchhoff rods), whose wrapped part is integrated with the cylinder's pressure (by
// multiple shooting; the planar wraps by single shooting). A tapered or extensible rod around a
// disc would need the constrained equations on the interval, as the spatial rod has them.
std::string extended_contact_unsupported(const RodEquations& equations, const Obstacle& obstacle);

using ModelFunction = std::function<RodModel(const Parameters&)>;

struct ShootingOptions {
  int segments = 1;  // multiple shooting when > 1 (long or strongly loaded rods)
  // Threads integrating the segments of multiple shooting (they are independent): 0 takes the
  // machine's hardware concurrency. Used from 8 segments on; each extra thread has its own copy
  // of the equations (material profiles evaluate muParser expressions, which are not reentrant).
  int threads = 0;
  IntegratorOptions integrator;
  NewtonOptions newton;
  std::string validate() const;
};

// A command's wall-clock limit: every solve made with these options stops with time_limit
// `seconds` from now (0: no limit). What `solve` uses unless told otherwise: long enough for the
// slowest shipped case from its guess (seconds), short enough that a user never waits on a hang.
void limit_wall_clock(ShootingOptions& options, double seconds);
constexpr double kDefaultSolveSeconds = 120.0;

// Everything needed to state a problem; ShootingProblem checks it on construction.
struct ProblemDefinition {
  RodKind kind = RodKind::Spatial;
  ModelFunction model;                     // the rod for given parameter values
  std::set<std::string> model_parameters;  // parameters the model depends on
  EndCondition start, end;
  Parameters parameters;                   // current values (guesses for the unknown ones)
  // Parameters computed from the others (parameters.hpp), recomputed wherever the problem uses
  // its parameters; one the model or an obstacle depends on makes the parameters it uses do too.
  std::vector<DependentParameter> dependent_parameters;
  std::vector<std::string> unknown_parameters;
  ShootingOptions options;
  std::vector<Obstacle> obstacles;       // what the rod may touch (see solve_with_contacts)
  // When set, the obstacles for given parameter values: obstacles that move with parameters
  // (an indenter's depth followed by continuation, or solved for). It overrides `obstacles`,
  // which ShootingProblem keeps as its value at the current parameters (so a caller replacing
  // `obstacles` clears this too); obstacle_parameters names the parameters it depends on.
  std::function<std::vector<Obstacle>(const Parameters&)> moving_obstacles;
  std::set<std::string> obstacle_parameters;
  std::vector<PointContact> contacts;    // the active set: point contacts solved for
  // Multiple shooting with contacts (segments > 1): the contacts' arclengths (both ends of an
  // extended one) split the rod into pieces, and each piece is shot over this many segments of
  // equal length that move with its ends (so no node is ever crossed by a contact). Empty: the
  // segments shared out in proportion to the pieces' lengths at the contacts' guesses, at least
  // one each. A spatial rod lying on a cylinder (an extended contact on a cylinder,
  // rod_on_cylinder.hpp) is solved this way; planar extended contacts need single shooting.
  std::vector<int> piece_segments;
};

class ShootingProblem final : public NonlinearSystem {
 public:
  // Throws std::invalid_argument with the reason for an inconsistent definition (bad options,
  // incomplete or doubly imposed boundary conditions, unknown parameters without extra
  // conditions, non-physical model).
  explicit ShootingProblem(ProblemDefinition definition);

  int size() const override;
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                std::string* failure) const override;
  // Newton's step matrices (NewtonOptions::step_matrix_tolerance): the variational equations
  // integrated to `tolerance` for this call only (IntegratorOptions::sensitivity_tol), the state,
  // hence F, to the problem's own. Offered where `tolerance` is looser than the problem's own
  // sensitivity_tol and abs_tol, and not with obstacles or contacts (their active-set decisions
  // and events follow Newton's last iterates, which stay exactly as they were).
  bool has_step_matrices(double tolerance) const override;
  bool evaluate_for_step(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, double tolerance,
                         std::string* failure) const override;
  // Newton's coarse evaluations (NewtonOptions::coarse_tolerance): the state and the variational
  // equations integrated to `tolerance` (absolute and relative) for this call only. Offered where
  // `tolerance` is looser than the problem's own, and not with obstacles or contacts (as above).
  bool has_coarse_evaluations(double tolerance) const override;
  bool evaluate_coarse(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, double tolerance,
                       std::string* failure) const override;
  // Their matrices alone: the state and the variational equations in the one pass at the
  // matrices' tolerance, without the state's own pass at the tighter one (the end conditions'
  // rows then read the end state to the matrices' tolerance too). Where the problem offers no
  // such matrices, the exact one (with F evaluated and thrown away).
  bool step_matrix(const Eigen::VectorXd& x, Eigen::MatrixXd* J, double tolerance,
                   std::string* failure) const override;
  bool coarse_matrix(const Eigen::VectorXd& x, Eigen::MatrixXd* J, double tolerance,
                     std::string* failure) const override;
  // The matrix alone with the variational equations at this problem's own sensitivity_tol (where
  // it is looser than abs_tol, as the continuation's march problem: ShootingSystem), in one pass;
  // the end state is left in *y_end (to that tolerance) for the parameter columns.
  bool matrix_at_sensitivity_tolerance(const Eigen::VectorXd& x, Eigen::MatrixXd* J, Eigen::VectorXd* y_end,
                                       std::string* failure) const;

  // Unknown vector from a state guess at s = 0 (completed with the start conditions) by
  // integrating across the segments; throws IntegrationError when that integration fails.
  Eigen::VectorXd initial_unknowns(const RodPoint& start_guess) const;

  // Parameters with the unknown ones taken from x.
  Parameters parameters_at(const Eigen::VectorXd& x) const;
  void set_parameter(const std::string& name, double value);
  const Parameters& parameters() const { return definition_.parameters; }
  const ProblemDefinition& definition() const { return definition_; }

  // The parameters with the dependent ones recomputed from the others.
  Parameters completed(Parameters p) const;

  // Equations for the given parameters (rebuilt when a model parameter changes).
  std::shared_ptr<const RodEquations> equations(const Parameters& p) const;
  double length(const Parameters& p) const { return equations(p)->model().length; }
  int state_size() const { return state_size_; }
  int segments() const { return definition_.options.segments; }
  // State at s = 0 stored in x.
  Eigen::VectorXd start_state(const Eigen::VectorXd& x) const { return x.head(state_size_); }
  // Solution sampled at the given arclengths (sorted, within [0, L]), integrated with the case's
  // integrator options or, given, with `integrator` (a looser one where the samples serve as
  // scales only: the stability index's field rate).
  std::vector<RodPoint> sample(const Eigen::VectorXd& x, const std::vector<double>& s,
                               const IntegratorOptions* integrator = nullptr) const;

  long rhs_evaluations() const { return workspace_.rhs_evaluations(); }
  // The obstacles at these parameter values.
  std::vector<Obstacle> obstacles(const Parameters& p) const;
  // The active contacts with their arclengths and forces taken from x.
  std::vector<PointContact> contacts_at(const Eigen::VectorXd& x) const;
  // g'' at a point contact: how the rod curves away from the obstacle there (0: it flattens onto
  // a plane, or starts to wrap around a curved obstacle). g'' = grad g . r'' + r'^T Hess g r',
  // with r'' = R (u x v) for an unshearable, inextensible rod.
  double contact_bending(const Eigen::VectorXd& x, const PointContact& contact) const;
  // For an extended contact of length l: 4 pi^2 B2 / l^2 - P_flat, with P_flat = -n.d3 the
  // compression of the flat part. The flat part is a strut clamped by the obstacle at both ends;
  // its first mode 1 - cos(2 pi (s - s1) / l) leaves the obstacle, so it buckles (a hanging fold
  // forms) where this margin reaches 0. NaN for a point contact or a flat part of zero length.
  double flat_contact_margin(const Eigen::VectorXd& x, const PointContact& contact) const;
  // Tension n.d3 in the middle of an extended contact on a disc: the wrapped part presses on the
  // disc with tension / radius, so it must not be negative. NaN for a point contact, a flat one
  // (whose tension is the flat_contact_margin's business) or a spatial rod on a cylinder.
  double wrap_tension(const Eigen::VectorXd& x, const PointContact& contact) const;
  // The smallest pressure (force per length) of the wrapped part of an extended contact on a
  // curved obstacle, over `samples` equally spaced points of it (ends included): tension / radius
  // on a disc, the cylinder's pressure for a spatial rod (rod_on_cylinder.hpp). Complementarity
  // wants it >= 0. NaN for a point contact or a flat one. `contact` as solved (contacts_at(x)).
  double smallest_wrap_pressure(const Eigen::VectorXd& x, const PointContact& contact, int samples = 65) const;

  // Multiple shooting with contacts: segments per piece (see ProblemDefinition::piece_segments),
  // empty without contacts or with single shooting.
  const std::vector<int>& piece_segments() const { return piece_segments_; }
  // Where each segment starts (node i of the unknowns), for the contact arclengths in x, or for
  // the definition's contact guesses.
  std::vector<double> node_arclengths(const Eigen::VectorXd& x) const;
  std::vector<double> node_arclengths() const { return node_arclengths(unknowns_without_states()); }
  // Unknowns with node i's state from nodes[i] (a solution of another formulation sampled at
  // node_arclengths(), say), the turn angle from its turn_angle, and the definition's parameters
  // and contacts.
  Eigen::VectorXd unknowns_from(const std::vector<RodPoint>& nodes) const;

  // dF/d(parameter) at x, for a known (not solved-for) parameter: from the closed-form boundary
  // conditions when the parameter does not enter the rod model, else by central differences of
  // the flow. y_end, when given, is the state at s = L for x (saves an integration).
  bool parameter_derivative(const Eigen::VectorXd& x, const std::string& name, Eigen::VectorXd* dF,
                            std::string* failure, const Eigen::VectorXd* y_end = nullptr) const;
  // Residual, Jacobian and the state at s = L in one integration.
  bool evaluate_with_end(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, Eigen::VectorXd* y_end,
                         std::string* failure) const;
  // No obstacle (fixed or moving) and no contact: where Newton's step and coarse evaluations are
  // offered (an active-set decision or an event follows every iterate, which they leave as they
  // were), where flows may be closed form, and where a homotopy's steps may grow.
  bool without_obstacles() const;

 private:
  // `integrator`: the options of the flows without contacts (null: the definition's).
  bool residual(const Eigen::VectorXd& x, const Parameters& p, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                std::string* failure, Eigen::VectorXd* y_end = nullptr,
                const IntegratorOptions* integrator = nullptr) const;
  // evaluate_with_end with the flows of x itself integrated with `integrator`.
  bool evaluate_with(const Eigen::VectorXd& x, Eigen::VectorXd* F, Eigen::MatrixXd* J, Eigen::VectorXd* y_end,
                     const IntegratorOptions& integrator, std::string* failure) const;
  // J alone from one pass of the state with the variational equations at `tolerance`.
  bool matrix_in_one_pass(const Eigen::VectorXd& x, Eigen::MatrixXd* J, double tolerance, Eigen::VectorXd* y_end,
                          std::string* failure) const;
  // Sizes F (and J) and fills the gauge and start-condition rows; returns the next row.
  int start_rows(const RodEquations& eq, const Eigen::VectorXd& y0, const Parameters& p, Eigen::VectorXd* F,
                 Eigen::MatrixXd* J) const;
  // An end's condition values and, with_jacobian, their Jacobian rows, into the workspace's
  // buffers (start_values / start_jacobian or end_values / end_jacobian), which it returns.
  const ShootingWorkspace::Buffers& condition_rows_at(const RodEquations& eq, bool at_start, const Eigen::VectorXd& y,
                                                      const Parameters& p, bool with_jacobian) const;
  // Fills the end-condition rows from `row` on (the last rows), with S = dy(L)/dx for their Jacobian.
  void end_rows(const RodEquations& eq, const Eigen::VectorXd& y_end, const Parameters& p, const Eigen::MatrixXd* S,
                Eigen::VectorXd* F, Eigen::MatrixXd* J, int row) const;
  // The rows of F that come from the boundary conditions, at fixed end states, into *rows (its
  // storage reused).
  void condition_rows_into(const Eigen::VectorXd& y0, const Eigen::VectorXd& y_end, const Parameters& p,
                           std::vector<double>* rows) const;
  // A parameter's column of the Jacobian where it enters the end conditions only: their rows'
  // central difference between `plus` and `minus` (the parameter moved by +h and -h, the end
  // states held), zero elsewhere.
  void condition_column(const Eigen::VectorXd& x, const Eigen::VectorXd& y_end, const Parameters& plus,
                        const Parameters& minus, double h, Eigen::Ref<Eigen::VectorXd> column) const;
  // condition_column of the `unknown`-th unknown parameter at x (its step kParameterStep (1 + |value|)).
  void unknown_condition_column(const Eigen::VectorXd& x, const Eigen::VectorXd& y_end, int unknown,
                                Eigen::Ref<Eigen::VectorXd> column) const;
  // Whether an unknown parameter enters the rod model or moves an obstacle (its column then needs
  // whole residuals, not only the boundary-condition rows).
  bool moves_beyond_conditions(int unknown) const;
  // The unfolding couple's column of J from the last integration's flows, where each carries
  // its sensitivity to it (SegmentFlow::dy_dunfolding) and the rod has no contacts: returns the
  // unknown's index, or -1 where the column must be differenced.
  int unfolding_column_from_flows(const Eigen::VectorXd& x, const Parameters& p, const Eigen::VectorXd& y_end,
                                  Eigen::MatrixXd* J) const;
  int contact_offset() const { return segments() * state_size_ + static_cast<int>(unknown_index_.size()); }
  int contact_column(size_t k) const;  // first unknown of contact k
  std::vector<int> contact_columns() const;
  // Single shooting through the contact points: the state jumps in n at each of them.
  bool residual_with_contacts(const Eigen::VectorXd& x, const Parameters& p, Eigen::VectorXd* F,
                              Eigen::MatrixXd* J, std::string* failure, Eigen::VectorXd* y_end) const;
  // Multiple shooting with contacts: the segments of each piece between contacts move with its
  // ends; the jumps sit between a piece's last segment and the next piece's first node.
  bool residual_pieces(const Eigen::VectorXd& x, const Parameters& p, Eigen::VectorXd* F, Eigen::MatrixXd* J,
                       std::string* failure, Eigen::VectorXd* y_end) const;
  // The equations of each piece between the breakpoints of x: the rod's, or on a cylinder.
  std::vector<std::shared_ptr<const RodEquations>> piece_equations(const Eigen::VectorXd& x, const Parameters& p) const;
  void set_piece_segments();
  // The unknown parameters' and contacts' entries of x from the definition, the states zero.
  Eigen::VectorXd unknowns_without_states() const;

  ProblemDefinition definition_;
  int state_size_ = 0;
  int residual_count_ = 0;
  int start_condition_count_ = 0;
  int gauge_count_ = 0;
  std::vector<int> unknown_index_;
  std::vector<int> piece_segments_;  // multiple shooting with contacts: segments per piece  // index of each unknown parameter in Parameters
  // A new equations object for these parameters (uncached; a thread's own copy).
  std::shared_ptr<const RodEquations> build_equations(const Parameters& p) const;
  // Checks the dependent parameters, extends the model's and obstacles' parameters by those they
  // use, and computes their values.
  void adopt_dependent_parameters();
  // Calls work(i, equations) for every segment i of multiple shooting, in parallel (see
  // ShootingOptions::threads); each thread has its own equations. Rethrows the first exception.
  // (Serially when `parallel` is false: starting threads costs more than a few samples.)
  void for_each_segment(const Parameters& p, const std::function<void(int, const RodEquations&)>& work,
                        bool parallel = true) const;
  // The flows of all segments.
  // parameters_at, into *p; with moved >= 0 that unknown parameter's value moved by `by` (as
  // parameters_at of x with x[its column] += by).
  void parameters_into(const Eigen::VectorXd& x, Parameters* p, int moved = -1, double by = 0.0) const;
  bool integrate_segments(const Eigen::VectorXd& x, const Parameters& p, bool sensitivities,
                          const IntegratorOptions& integrator, std::vector<SegmentFlow>* flows,
                          std::string* failure) const;

  // What evaluating changes (shooting_workspace.hpp): the equations' cache and the rhs count.
  mutable ShootingWorkspace workspace_;
};

// Breaks the rotational symmetry of an isotropic (B1 = B2) spatial rod whose ends both lie on
// the e3 axis with d3 = e3 there (e.g. the twisted clamped rod). Rotating a solution about e3
// while turning its cross-sections back about d3 gives another solution, so buckled solutions
// come in circles and Newton's matrix is singular along them. We add
//   - a phase condition m(0).e2 = 0 that picks one solution on each circle, and
//   - an unknown unfolding parameter mu (named "unfolding") entering as a distributed couple
//     l = mu (e3 - d3), which changes the first integral J = (m + r x n).e3 - m.d3 at the rate
//     J' = -mu |e3 - d3|^2. The end conditions give J(0) = J(L) = 0, so every solution that is
//     not straight has mu = 0. (On the straight rod the circle of solutions shrinks to a point
//     and the phase condition is degenerate: solve the straight rod without it.)
void add_axial_phase_condition(ProblemDefinition& definition);

// The name of add_axial_phase_condition's unknown. It is zero at every equilibrium and only
// selects one solution on each circle, so analyses that ask what an unknown parameter does (an
// end load, a sliding length) pass over it.
inline constexpr const char* kUnfoldingParameter = "unfolding";
inline bool is_unfolding_parameter(const std::string& name) { return name == kUnfoldingParameter; }

// |mu| above this at a converged point means the unfolded system was solved with a non-zero
// couple (an artefact, not an equilibrium). At true solutions mu is zero to the Newton
// tolerance times the conditioning, far below this.
constexpr double kUnfoldingTolerance = 1e-7;

// Why the parameters of a converged point are not an equilibrium (its unfolding above
// kUnfoldingTolerance), or "" (no unfolding parameter, or it is zero).
std::string unfolding_failure(const Parameters& parameters);

// A solved problem: the unknowns, how the solve went, and the parameters at the solution.
struct ShootingResult {
  Eigen::VectorXd x;
  NewtonSummary summary;
  Parameters parameters;
};

// Newton (with the NLopt fallback when enabled) from the unknowns x0. A failure adds
// turn_count_hint() to the message where it applies; a single segment that is singular to the
// solver, or whose line search fails, adds single_segment_hint().
ShootingResult solve(const ShootingProblem& problem, const Eigen::VectorXd& x0);

// What a failure on one shooting segment adds: more segments condition an ill-conditioned shooting.
std::string single_segment_hint();
// What to do where a case's length or bending stiffness lies decades from 1 at x (its units make
// the absolute residual tolerance mean something else); "" for a case of unit scale.
std::string scale_hint(const ShootingProblem& problem, const Eigen::VectorXd& x);
// Where an end counts whole turns about e3 (track_turns) and the rod's tangent at x comes within a
// few degrees of -e3 - a ring closed on itself - what to do: the counted turn is undefined there
// (turn_count_hint.cpp); "" otherwise.
std::string turn_count_hint(const ShootingProblem& problem, const Eigen::VectorXd& x);

}  // namespace kirchhoff

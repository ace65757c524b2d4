// Frictionless unilateral contact with rigid obstacles, by complementarity in the shooting core.
//
// The active set is a list of point contacts, each with an unknown arclength and force (see
// PointContact). An active-set loop solves the problem with the current set, then
//   - releases the contact with the most negative force, if any (the obstacle would pull), or
//   - adds a contact where the rod penetrates an obstacle most (refined by Brent's method),
// until 0 <= g(r(s)) everywhere and every force is >= 0: 0 <= g perp force >= 0.
// Point contacts and, for planar rods on planes and discs, extended contacts (the rod lying on
// the obstacle over an interval; see PointContact).
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/continuation/rod_continuation.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct ContactOptions {
  int max_rounds = 12;                    // solves of the active-set loop
  double penetration_tolerance = 1e-9;    // g below -this is a penetration
  double force_tolerance = 1e-9;          // a force below -this is a pull, and is released
  int samples = 401;                      // where penetration is looked for (then refined)
};

struct ContactSolveResult {
  ShootingResult result;
  ProblemDefinition definition;           // with the final active set
  std::vector<std::string> log;           // one line per change of the active set
  // One line per contact of the starting set that moved or was released (stated_contact_outcomes);
  // solve_definition's contact_log carries them after the log.
  std::vector<std::string> stated_moves;
  bool complementarity = false;           // the final solution satisfies 0 <= g perp force >= 0
  std::string message;
};

// Thrown when an end of the rod is imposed inside an obstacle: no admissible equilibrium exists.
struct InfeasibleContact : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Why no admissible equilibrium exists because an end's imposed position lies inside an obstacle
// (its gap below -penetration_tolerance), or "" where none does: what solve_with_contacts throws
// as InfeasibleContact, for the callers that check a definition before they start (a homotopy to
// requested values, `check`, the equilibria search).
std::string imposed_end_inside_obstacle(const ProblemDefinition& definition, double penetration_tolerance = 1e-9);

// Whether an active set has an extended contact, and a hanging fold: two neighbouring point
// contacts on the same obstacle (the rod leaves it between them).
bool has_extended_contact(const std::vector<PointContact>& contacts);
bool has_hanging_fold(const std::vector<PointContact>& contacts);

// Solves from `guess` (the state at s = 0, completed by the start conditions) starting with the
// definition's contacts as the active set. Non-convergence of a solve ends the loop with that
// status (the summary's message says with how many contacts, and why when an extended contact on
// a plane stalls at round-off); a loop that does not settle within max_rounds reports
// complementarity = false. Once settled, two neighbouring point contacts on a plane with the rod
// lying on it between them are reported as the extended contact they are (re-solved as such;
// kept as point contacts, with a log line, where that does not converge), and stated_moves says
// where each stated contact that moved went, or that it was released (stated_contact_outcomes).
// Throws InfeasibleContact when an imposed end position lies inside an obstacle.
ContactSolveResult solve_with_contacts(ProblemDefinition definition, const RodPoint& guess,
                                       const ContactOptions& options = {});

// A contact of a stated starting set (a case's [[guess.contacts]]) and where a solve left it: the
// solved contact on the same obstacle nearest to it (each taken once), or none - released.
struct StatedContactOutcome {
  PointContact stated;
  bool released = false;
  PointContact solved;   // when not released
  bool moved = false;    // an end moved by more than 1e-6 of the rod's length, or its kind changed
  std::string message;   // "the contact with obstacle 0 ('wall') stated at s = 0.5 converged at s = 0.557"
};
std::vector<StatedContactOutcome> stated_contact_outcomes(const std::vector<PointContact>& stated,
                                                          const std::vector<PointContact>& solved,
                                                          const std::vector<Obstacle>& obstacles, double length);

// Solves a definition from a guess: plain shooting, or the active-set loop when it has obstacles
// (a loop that does not settle is reported as max_iterations with its message). `problem` is the
// problem the result's unknowns belong to. Throws IntegrationError when the guess cannot be
// integrated and InfeasibleContact when an end is imposed inside an obstacle.
struct DefinitionSolve {
  std::unique_ptr<ShootingProblem> problem;
  ShootingResult result;
  std::vector<std::string> contact_log;
};
DefinitionSolve solve_definition(const ProblemDefinition& definition, const RodPoint& guess);
// Newton on one active set (solve, verification.hpp), as the active-set loop runs it: a solve that
// stalls on the singular Jacobian of a flat contact on a plane (an end clamped parallel to it)
// within 10 x the tolerance is converged at round-off, "step at round-off", and *note (if given)
// says why; where it is not, *note is left as it was.
ShootingResult solve_on_active_set(const ShootingProblem& problem, const Eigen::VectorXd& x, std::string* note);
// An active-set loop's result as such a solve (a loop that did not settle: max_iterations).
DefinitionSolve as_definition_solve(ContactSolveResult contact);

// Continuation through changes of the active contact set. Each leg is an ordinary Continuation
// with the set fixed and stopping events, at which the set changes, the change is recorded as an
// event point (its `event` says what changed) and the next leg starts there:
//   - obstacle_reached: min_gap crosses 0, a point contact appears where the rod touches;
//   - contact_lifts_off: min_contact_force crosses 0, that contact is released;
//   - contact_flattens (planar): a point contact's curvature away from the obstacle vanishes, it
//     becomes an extended contact of zero length that then spreads (flat on a plane, wrapped
//     around a disc - a disc only where the rod is in tension there, see PointContact);
//   - contact_shrinks_to_a_point: a wrap's length reaches 0, it becomes a point contact carrying
//     both edge forces (flat contacts are not followed below zero length, so a shrinking flat
//     contact ends its run with the step too small);
//   - wrap_tension_vanishes: a wrapped part would pull on its disc; the run stops (not modelled);
//   - flat_contact_buckles: an extended contact's flat part reaches its clamped-clamped Euler
//     load, P l^2 = 4 pi^2 EI; it becomes a hanging fold, point contacts at its two ends with a
//     blister between them, and the next leg leaves the (now unstable) flat branch along the
//     strut's first mode, away from the obstacle.
struct ContactContinuationResult {
  ContinuationResult result;          // all legs' points, in order
  std::vector<std::string> changes;   // one line per change of the active set
  ProblemDefinition definition;       // the active set at the end
};
// Called when a leg starts, with its active set (the points that follow belong to it): lets a
// caller save it beside the points to resume later.
using ActiveSetSink = std::function<void(const std::vector<PointContact>&)>;

// Where a contact continuation stands at a point it can resume from: the leg's march (MarchState)
// and what the leg itself was started with, which a resume cannot re-derive from the point.
struct ContactMarchState {
  MarchState march;
  std::vector<PointContact> contacts;  // the leg's active set
  // The value contact_flattens is armed at: 0, or after contact_shrinks_to_a_point the contact's
  // g'' where the leg started (re-armed at 0, the resumed leg would see a crossing that is none).
  double contact_bending_event = 0.0;
  int leg_max_points = 0;  // the leg's share of max_points (the legs share the run's budget)
  int reported = 0;        // points the run has handed to its sink so far, over all legs
  bool first_leg = true;   // the run's first leg (a later leg starts on the previous leg's event point)
  int branch_points_before = 0;  // found by the run's earlier legs (stop_at_branch_point counts the run's)
};
// Called right after the point sink with every point such a run can resume from.
using ContactStateSink = std::function<void(const ContactMarchState&)>;

ContactContinuationResult continue_with_contacts(ProblemDefinition definition, const RodPoint& guess,
                                                 RodContinuationOptions options, const PointSink& sink = {},
                                                 const ContactOptions& contact = {},
                                                 const ActiveSetSink& active_set_sink = {},
                                                 const ContactStateSink& state_sink = {});
// Starts such a run from unknowns x of the definition's problem, its contacts being x's active set
// (a point another run wrote, continued now in another parameter, say). Like Continuation::run,
// x is corrected at the definition's parameter values first; a start that breaks
// complementarity ends the run as Inadmissible.
ContactContinuationResult continue_with_contacts_from(ProblemDefinition definition, const Eigen::VectorXd& x,
                                                      RodContinuationOptions options, const PointSink& sink = {},
                                                      const ContactOptions& contact = {},
                                                      const ActiveSetSink& active_set_sink = {},
                                                      const ContactStateSink& state_sink = {});
// Follows the branch bifurcating at `branch_point`, a located simple branch point on a leg of such
// a run whose active set is the definition's contacts (the run stops there with
// options.stop_at_branch_point, which counts the branch points of all its legs), through the
// changes of the active set as above. The first leg leaves along the null vector of
// [F_x F_lambda] orthogonal to the old tangent (Continuation::switch_branch, `side` +1 or -1) and
// reports the branch point again as its start; the options are bifurcating_branch_options'. A
// double branch point of a spatial rod is refused (std::invalid_argument): its switch needs the
// axial phase condition, not implemented with contacts.
ContactContinuationResult switch_branch_with_contacts(ProblemDefinition definition,
                                                      const ContinuationPoint& branch_point, double side,
                                                      RodContinuationOptions options, const PointSink& sink = {},
                                                      const ContactOptions& contact = {},
                                                      const ActiveSetSink& active_set_sink = {},
                                                      const ContactStateSink& state_sink = {});
// Resumes such a run from a state its state_sink was given (the definition's contacts are
// replaced by the state's), taking the same steps and active-set changes as the uninterrupted
// run with the same options. The state's point is not reported again.
ContactContinuationResult resume_with_contacts(ProblemDefinition definition, const ContactMarchState& state,
                                               RodContinuationOptions options, const PointSink& sink = {},
                                               const ContactOptions& contact = {},
                                               const ActiveSetSink& active_set_sink = {},
                                               const ContactStateSink& state_sink = {});

}  // namespace kirchhoff

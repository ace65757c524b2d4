#include "kirchhoff/contact/contact.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <tuple>

#include "kirchhoff/contact/closest_approach.hpp"
#include "kirchhoff/shooting/link.hpp"
#include "kirchhoff/shooting/verification.hpp"

namespace kirchhoff {
namespace {

// Unknowns before the contacts' (state and unknown parameters).
int non_contact_unknowns(const ShootingProblem& problem) {
  int n = problem.size();
  for (const auto& c : problem.definition().contacts) n -= c.unknowns();
  return n;
}

// The unknowns of the new active set from the solved ones of the old: state and parameters
// are kept, contacts take their solved values, new contacts their guesses.
Eigen::VectorXd carry_over(const ShootingProblem& old_problem, const Eigen::VectorXd& x,
                           const ShootingProblem& new_problem) {
  Eigen::VectorXd y = new_problem.initial_unknowns(RodPoint{});
  const int keep = non_contact_unknowns(old_problem);
  y.head(keep) = x.head(keep);
  return y;
}

// How far the rod may stand off a plane between two point contacts and still be lying on it. The
// contacts themselves hold the gap to the residual tolerance (<= 1e-10); a hanging fold's blister
// stands off by far more except within a relative 1e-6 of its onset, where the two are the same
// configuration anyway.
constexpr double kFlatBetweenTolerance = 1e-8;
// Samples of the gap between two contacts (a blister is one smooth wave between them).
constexpr int kFlatBetweenSamples = 16;

// Whether the rod lies on `o` all the way over (a, b).
bool lies_on(const ShootingProblem& problem, const Eigen::VectorXd& x, const Obstacle& o, double a, double b) {
  std::vector<double> s;
  for (int i = 1; i < kFlatBetweenSamples; ++i) s.push_back(a + (b - a) * i / kFlatBetweenSamples);
  for (const RodPoint& p : problem.sample(x, s))
    if (!(std::abs(o.gap(p.r)) <= kFlatBetweenTolerance)) return false;
  return true;
}

// The solved active set with each pair of neighbouring point contacts on the same plane that has
// the rod lying on it between them made one extended contact over [s1, s2] with the end forces
// f1, f2 - what they are: the rod flat on the wall, free of moment and normal force in between
// (the reverse of continuation's split into a hanging fold). The unknowns keep their layout
// ([s1, f1], [s2, f2] become [s, force, s_end, force_end]), so x solves the merged problem too.
// One line per merge in *log; the set unchanged when there is nothing to merge.
std::vector<PointContact> merge_flat_pairs(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                           std::vector<PointContact> contacts, std::vector<std::string>* log) {
  const Parameters parameters = problem.parameters_at(x);
  const std::vector<Obstacle> obstacles = problem.obstacles(parameters);
  const auto equations = problem.equations(parameters);
  for (size_t k = 0; k + 1 < contacts.size(); ++k) {
    const PointContact &a = contacts[k], &b = contacts[k + 1];
    if (a.extended || b.extended || a.obstacle != b.obstacle || !(b.s > a.s)) continue;
    const Obstacle& o = obstacles[a.obstacle];
    if (!o.is_flat() || !extended_contact_unsupported(*equations, o).empty()) continue;
    if (!lies_on(problem, x, o, a.s, b.s)) continue;
    std::ostringstream line;
    line << "the point contacts at s = " << a.s << " and " << b.s << " have the rod flat on obstacle " << a.obstacle
         << " between them: one extended contact over [" << a.s << ", " << b.s << "]";
    log->push_back(line.str());
    PointContact flat = a;
    flat.extended = true;
    flat.s_end = b.s;
    flat.force_end = b.force;
    contacts[k] = flat;
    contacts.erase(contacts.begin() + k + 1);
  }
  return contacts;
}

// Newton's tolerance on max |F| for a definition.
double residual_tolerance(const ProblemDefinition& d) { return d.options.newton.residual_tolerance; }

// Why a solve with an extended contact on a plane may stall just above the tolerance: with the
// rod flat on the plane H = -P there, so wherever else it is parallel to the plane - at an end
// clamped parallel to it - its curvature is zero too, as a double root (see run_legs): the
// Jacobian is singular, Newton converges only linearly and stops at the integrator's round-off.
std::string stalled_flat_contact_reason(const ProblemDefinition& d, const NewtonSummary& summary) {
  const bool on_plane = std::any_of(d.contacts.begin(), d.contacts.end(),
                                    [&](const auto& c) { return c.extended && d.obstacles[c.obstacle].is_flat(); });
  // 1e3 x the tolerance: Newton's own bound for a step stalled at round-off (newton.hpp).
  if (!on_plane || !(summary.residual_norm <= 1e3 * residual_tolerance(d))) return "";
  std::ostringstream why;
  why << "the residual stalled at " << summary.residual_norm << " against the tolerance " << residual_tolerance(d)
      << ": with the rod flat on a plane, H = -P there, so at an end clamped parallel to the plane the curvature "
         "is a double root and the Jacobian is singular; Newton converges only linearly and stops at the "
         "integrator's round-off, which this tolerance leaves no room for (loosen [solver] tolerance by a decade, "
         "or state a point contact and let the solver flatten it by continuation)";
  return why.str();
}

// How far above the tolerance a stalled flat-contact solve may end and still be at round-off: the
// integrator runs at 1e-12 relative, so residuals of ~1e-12 are its noise (the same configuration
// gives 4.8e-13 with the variational equations integrated beside it and 1.09e-12 without, on
// wall.toml at Delta = 0.04); ten times the tolerance is within that noise for tolerances near
// it, and a real failure (a wrong active set, a bad guess) stalls orders of magnitude higher.
constexpr double kRoundOffFactor = 10.0;

// A solve that stalled on the singular Jacobian of a flat contact (stalled_flat_contact_reason)
// is converged at round-off when Newton could decrease the residual no further and it is within
// kRoundOffFactor x the tolerance. Newton accepts an iterate within 1e3 x the tolerance when its
// step is at round-off (newton.hpp); here its full step runs along the null direction and is
// not small, so Newton cannot see it. The summary then says "step at round-off" as Newton's does
// (verification holds it to Newton's bound), and the caller logs why.
bool converged_at_round_off(const ShootingProblem& problem, ShootingResult* r) {
  const double tolerance = problem.definition().options.newton.residual_tolerance;
  const SolverStatus status = r->summary.status;
  if (status != SolverStatus::LineSearchFailed && status != SolverStatus::SingularJacobian) return false;
  if (stalled_flat_contact_reason(problem.definition(), r->summary).empty()) return false;
  if (!(r->summary.residual_norm <= kRoundOffFactor * tolerance)) return false;
  r->summary.status = SolverStatus::Converged;
  r->summary.message = "step at round-off";
  return true;
}

// "s = 0.5" or "over [0.45, 0.55]".
std::string where(const PointContact& c) {
  std::ostringstream os;
  if (c.extended)
    os << "over [" << c.s << ", " << c.s_end << "]";
  else
    os << "at s = " << c.s;
  return os.str();
}

// A contact moved when an end moved by more than this fraction of the rod's length: far above
// the residual tolerance's effect on s, far below any change a reader would care about.
constexpr double kMovedFraction = 1e-6;

}  // namespace

std::vector<StatedContactOutcome> stated_contact_outcomes(const std::vector<PointContact>& stated,
                                                          const std::vector<PointContact>& solved,
                                                          const std::vector<Obstacle>& obstacles, double length) {
  // Pairs on the same obstacle, nearest first, each contact used once: a stated contact is
  // matched with the solved one nearest to it unless another stated contact is nearer still.
  std::vector<std::tuple<double, size_t, size_t>> pairs;
  for (size_t i = 0; i < stated.size(); ++i)
    for (size_t k = 0; k < solved.size(); ++k)
      if (solved[k].obstacle == stated[i].obstacle) pairs.emplace_back(std::abs(solved[k].s - stated[i].s), i, k);
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> match(stated.size(), -1);
  std::vector<bool> taken(solved.size(), false);
  for (const auto& [distance, i, k] : pairs)
    if (match[i] < 0 && !taken[k]) {
      match[i] = static_cast<int>(k);
      taken[k] = true;
    }
  std::vector<StatedContactOutcome> out;
  for (size_t i = 0; i < stated.size(); ++i) {
    const PointContact& c = stated[i];
    StatedContactOutcome o;
    o.stated = c;
    std::ostringstream message;
    message << "the contact with obstacle " << c.obstacle;
    if (c.obstacle >= 0 && static_cast<size_t>(c.obstacle) < obstacles.size() && !obstacles[c.obstacle].name.empty())
      message << " ('" << obstacles[c.obstacle].name << "')";
    message << " stated " << where(c);
    if (match[i] < 0) {
      o.released = true;
      message << " is not in the solution: the active-set loop released it (it would have pulled)";
    } else {
      o.solved = solved[match[i]];
      const double end_stated = c.extended ? c.s_end : c.s, end_solved = o.solved.extended ? o.solved.s_end : o.solved.s;
      o.moved = c.extended != o.solved.extended || std::abs(o.solved.s - c.s) > kMovedFraction * length ||
                std::abs(end_solved - end_stated) > kMovedFraction * length;
      message << (o.moved ? " converged " + where(o.solved) : " stayed there");
    }
    o.message = message.str();
    out.push_back(o);
  }
  return out;
}

bool has_extended_contact(const std::vector<PointContact>& contacts) {
  return std::any_of(contacts.begin(), contacts.end(), [](const auto& c) { return c.extended; });
}

bool has_hanging_fold(const std::vector<PointContact>& contacts) {
  for (size_t k = 0; k + 1 < contacts.size(); ++k)
    if (!contacts[k].extended && !contacts[k + 1].extended && contacts[k].obstacle == contacts[k + 1].obstacle)
      return true;
  return false;
}

namespace {

// Appends `what` to a failed solve's message (once: the summary may already say it).
void append_once_to_message(NewtonSummary* summary, const std::string& what) {
  if (summary->message.find(what) != std::string::npos) return;
  summary->append_to_message(what);
}

// The log line of a solve accepted by converged_at_round_off.
std::string round_off_note(const NewtonSummary& summary, const ProblemDefinition& d) {
  std::ostringstream note;
  note << "converged at round-off: the residual stalled at " << summary.residual_norm << " (tolerance "
       << residual_tolerance(d) << ") on the singular Jacobian of a flat contact (an end clamped parallel to the "
       << "plane has a double root in its curvature); within " << kRoundOffFactor
       << " x the tolerance, the integrator's noise";
  return note.str();
}

// After the loop has settled: pairs of point contacts with the rod flat on a plane between them
// become the extended contact they are (merge_flat_pairs), re-solved as such so that the result
// belongs to that active set. If the extended problem does not converge from the same
// configuration (its Jacobian can be singular, see stalled_flat_contact_reason), the point
// contacts are kept, and the log says so.
void report_flat_pairs_as_extended(std::unique_ptr<ShootingProblem>* problem, ProblemDefinition* d,
                                   ContactSolveResult* out) {
  std::vector<std::string> merges;
  ProblemDefinition merged = *d;
  merged.contacts = merge_flat_pairs(**problem, out->result.x, d->contacts, &merges);
  if (merges.empty()) return;
  auto flat = std::make_unique<ShootingProblem>(merged);
  ShootingResult r = solve(*flat, out->result.x);
  if (!r.summary.converged() && converged_at_round_off(*flat, &r)) merges.push_back(round_off_note(r.summary, merged));
  if (!r.summary.converged()) {
    out->log.push_back("kept as point contacts: " + merges.front() + " does not converge as such (" +
                       r.summary.brief_report() + ")");
    return;
  }
  merged.contacts = flat->contacts_at(r.x);
  for (const auto& line : merges) out->log.push_back(line);
  *d = merged;
  out->definition = merged;
  out->result = std::move(r);
  *problem = std::move(flat);
}

}  // namespace

ShootingResult solve_on_active_set(const ShootingProblem& problem, const Eigen::VectorXd& x, std::string* note) {
  ShootingResult r = solve(problem, x);
  if (!r.summary.converged() && converged_at_round_off(problem, &r) && note)
    *note = round_off_note(r.summary, problem.definition());
  return r;
}

std::string imposed_end_inside_obstacle(const ProblemDefinition& d, double penetration_tolerance) {
  if (d.obstacles.empty()) return "";
  const ShootingProblem problem(d);
  for (bool at_start : {true, false}) {
    const EndCondition& end = at_start ? d.start : d.end;
    for (const auto& condition : end.conditions()) {
      if (condition.slot != Slot::Position || condition.directions != Directions::All || condition.extra) continue;
      const Vec3 r = condition.value(d.parameters);
      for (const auto& o : problem.obstacles(d.parameters))
        if (o.gap(r) < -penetration_tolerance) {
          std::ostringstream why;  // (%g: a gap of -1e-7 is not "-0.000000")
          why << "the rod's " << (at_start ? "start" : "end") << " is imposed inside obstacle '" << o.name << "' (gap "
              << o.gap(r) << "): no admissible equilibrium";
          return why.str();
        }
    }
  }
  return "";
}

ContactSolveResult solve_with_contacts(ProblemDefinition d, const RodPoint& guess, const ContactOptions& options) {
  ContactSolveResult out;
  std::sort(d.contacts.begin(), d.contacts.end(), [](const auto& a, const auto& b) { return a.s < b.s; });
  auto problem = std::make_unique<ShootingProblem>(d);
  // Imposed end positions must be admissible (other positions are what the loop corrects).
  if (const std::string why = imposed_end_inside_obstacle(d, options.penetration_tolerance); !why.empty())
    throw InfeasibleContact(why);
  const std::vector<PointContact> stated = d.contacts;
  Eigen::VectorXd x = problem->initial_unknowns(guess);
  for (int round = 0; round < options.max_rounds; ++round) {
    std::string round_off;
    out.result = solve_on_active_set(*problem, x, &round_off);
    out.definition = d;
    if (!round_off.empty()) out.log.push_back(round_off);
    if (!out.result.summary.converged()) {
      out.message = "solve with " + std::to_string(d.contacts.size()) + " contact(s) did not converge";
      if (const std::string why = stalled_flat_contact_reason(d, out.result.summary); !why.empty()) out.message += ": " + why;
      if (round > 0) out.message += " (round " + std::to_string(round + 1) + " of the active-set loop)";
      append_once_to_message(&out.result.summary, out.message);
      return out;
    }
    const auto solved = problem->contacts_at(out.result.x);
    for (size_t k = 0; k < solved.size(); ++k) d.contacts[k] = solved[k];
    out.definition = d;

    // A pulling contact is released (the most negative first).
    auto weakest = std::min_element(solved.begin(), solved.end(),
                                    [](const auto& a, const auto& b) { return a.force < b.force; });
    std::ostringstream change;
    if (weakest != solved.end() && weakest->force < -options.force_tolerance) {
      change << "release the contact at s = " << weakest->s << " (force " << weakest->force << ")";
      d.contacts.erase(d.contacts.begin() + (weakest - solved.begin()));
    } else {
      // The deepest penetration of any obstacle, refined between samples.
      const ClosestApproach deepest = closest_approach(*problem, out.result.x, options.samples);
      if (!(deepest.gap < -options.penetration_tolerance)) {
        out.complementarity = true;
        report_flat_pairs_as_extended(&problem, &d, &out);
        const double length = problem->length(out.result.parameters);
        for (const auto& o : stated_contact_outcomes(stated, out.definition.contacts, problem->obstacles(out.result.parameters), length))
          if (o.released || o.moved) out.stated_moves.push_back(o.message);
        return out;
      }
      const int which = deepest.obstacle;
      const double where = deepest.s;
      change << "add a contact with obstacle " << which << " at s = " << where << " (gap " << deepest.gap << ")";
      d.contacts.push_back({which, where, 0.0});
      std::sort(d.contacts.begin(), d.contacts.end(), [](const auto& a, const auto& b) { return a.s < b.s; });
    }
    out.log.push_back(change.str());
    auto next = std::make_unique<ShootingProblem>(d);
    Eigen::VectorXd y = carry_over(*problem, out.result.x, *next);
    problem = std::move(next);
    x = y;
  }
  out.message = "the active set did not settle in " + std::to_string(options.max_rounds) + " solves";
  return out;
}

DefinitionSolve solve_definition(const ProblemDefinition& definition, const RodPoint& guess) {
  DefinitionSolve out;
  if (definition.obstacles.empty()) {
    out.problem = std::make_unique<ShootingProblem>(definition);
    out.result = solve(*out.problem, out.problem->initial_unknowns(guess));
    // A solve from a guess can land a whole turn away from an imposed end rotation (link.hpp);
    // a continuation cannot, so only here is the link checked.
    if (out.result.summary.converged()) mark_check_failure(&out.result, link_failure(*out.problem, out.result.x));
    return out;
  }
  return as_definition_solve(solve_with_contacts(definition, guess));
}

DefinitionSolve as_definition_solve(ContactSolveResult contact) {
  DefinitionSolve out;
  out.problem = std::make_unique<ShootingProblem>(contact.definition);
  out.result = std::move(contact.result);
  out.contact_log = std::move(contact.log);
  out.contact_log.insert(out.contact_log.end(), contact.stated_moves.begin(), contact.stated_moves.end());
  if (out.result.summary.converged() && !contact.complementarity) {
    out.result.summary.status = SolverStatus::MaxIterations;
    out.result.summary.message = contact.message;
  }
  return out;
}

namespace {

bool has_wrap(const ProblemDefinition& d) {
  return std::any_of(d.contacts.begin(), d.contacts.end(),
                     [&](const auto& c) { return c.extended && !d.obstacles[c.obstacle].is_flat(); });
}

// Which extended contact buckles at a flat_contact_buckles event: the one with the smallest margin.
size_t buckling_flat_contact(const ShootingProblem& problem, const Eigen::VectorXd& x,
                             const std::vector<PointContact>& contacts) {
  size_t which = 0;
  double smallest = INFINITY;
  for (size_t k = 0; k < contacts.size(); ++k) {
    const double margin = problem.flat_contact_margin(x, contacts[k]);
    if (std::isfinite(margin) && margin < smallest) {
      smallest = margin;
      which = k;
    }
  }
  return which;
}

// The hanging fold: the flat contact `which` is replaced by point contacts at its two ends, with
// the same arclengths and forces. The unknowns keep their layout ([s, force, s_end, force_end]
// become [s1, f1], [s2, f2]), so the flat configuration's x solves the new problem as well.
std::vector<PointContact> split_into_fold(std::vector<PointContact> contacts, size_t which) {
  const PointContact flat = contacts[which];
  PointContact first{flat.obstacle, flat.s, flat.force}, second{flat.obstacle, flat.s_end, flat.force_end};
  contacts[which] = first;
  contacts.insert(contacts.begin() + which + 1, second);
  return contacts;
}

// The quantities that pick the fold's direction at (x, lambda): the blister's gap at mid-way
// between contacts k and k + 1, and where its middle is (s_k + s_k+1) / 2.
Eigen::Vector2d blister_gap_and_centre(ShootingProblem problem, const std::string& parameter, const Eigen::VectorXd& z,
                                       size_t k) {
  const Eigen::VectorXd x = z.head(z.size() - 1);
  problem.set_parameter(parameter, z[z.size() - 1]);
  const auto contacts = problem.contacts_at(x);
  const Obstacle obstacle = problem.obstacles(problem.parameters_at(x))[contacts[k].obstacle];
  const double centre = 0.5 * (contacts[k].s + contacts[k + 1].s);
  return {obstacle.gap(problem.sample(x, {centre}).front().r), centre};
}

// With the ends of a flat contact as two point contacts, the flat configuration solves the
// problem at every Delta (the flat branch), and the hanging fold bifurcates from it where the flat
// part of length l reaches its Euler load, along the clamped-clamped strut's first mode between
// the contacts, g(s) = eps (1 - cos(2 pi (s - s1) / l)), with the response of the rest of the rod.
// That direction is sought among the null vectors of [F_x F_lambda] orthogonal to the flat
// branch's tangent: there are two, not one, because an end clamped parallel to the obstacle
// makes the flat branch degenerate (see run_legs on branch points): the outer arc can slide
// along itself, which moves a contact and leaves the blister flat. Of the combinations we take
// the one whose blister leaves the obstacle (gap at mid-blister 2 eps > 0) and stays centred on
// the flat part it replaces (d(s1 + s2) = 0); with some sliding in it, the predictor lands on an
// asymmetric fold instead, another branch through the same point.
struct FoldStart {
  Eigen::VectorXd direction;  // unit, in (x, lambda)
  double step = 0.0;          // the first step along it
};
FoldStart fold_direction(RodContinuation& flat, const ContinuationPoint& onset, size_t k) {
  const ShootingProblem& problem = flat.problem();
  const std::string& parameter = flat.options().parameter;
  const Eigen::MatrixXd N = flat.bifurcation_directions(onset, 2);
  Eigen::VectorXd z(onset.x.size() + 1);
  z << onset.x, onset.parameter;
  // Directional derivatives by central differences (the functions are smooth in z; h balances
  // the truncation error ~h^2 and the integrator's ~1e-12 noise / h).
  Eigen::Matrix2d D;
  for (int j = 0; j < 2; ++j) {
    const double h = 1e-5 / N.col(j).lpNorm<Eigen::Infinity>();
    D.col(j) = (blister_gap_and_centre(problem, parameter, z + h * N.col(j), k) -
                blister_gap_and_centre(problem, parameter, z - h * N.col(j), k)) /
               (2 * h);
  }
  // Where only one null vector moves the blister (no sliding mode: the second is not a null
  // vector at all), the blister's own direction is the one with the larger gap derivative.
  const Eigen::FullPivLU<Eigen::Matrix2d> lu(D);
  const int own = std::abs(D(0, 0)) >= std::abs(D(0, 1)) ? 0 : 1;
  const Eigen::VectorXd v = lu.rank() == 2 ? Eigen::VectorXd(N * lu.solve(Eigen::Vector2d(2.0, 0.0)))
                                           : Eigen::VectorXd(N.col(own) * (2.0 / D(0, own)));
  // First step: a blister 1e-3 l deep (deeper first steps leave the corrector's reach; the
  // contacts move ~100 times faster than the blister deepens near the onset).
  const auto contacts = problem.contacts_at(onset.x);
  const double l = contacts[k + 1].s - contacts[k].s;
  return {v.normalized(), 1e-3 * l * v.norm() / 2.0};
}

ContinuationResult leave_flat_branch(const ShootingProblem& problem, RodContinuationOptions leg,
                                     const ContinuationPoint& onset, size_t first_contact, const PointSink& sink) {
  RodContinuation flat(problem, leg);
  const FoldStart start = fold_direction(flat, onset, first_contact);
  leg.initial_step = std::min(leg.initial_step, start.step);
  ContinuationResult r = RodContinuation(problem, leg).run_along(onset.x, onset.parameter, start.direction,
                                                                PointType::Event, sink);
  if (r.reason == StopReason::StartFailed) r.message = "the hanging fold could not be started: " + r.message;
  return r;
}

// What is wrong with a point of a contact branch, or "" when 0 <= gap perp force >= 0 holds to
// 1e3 times the active-set loop's tolerances (events are located far closer than that).
std::string complementarity_violation(const ContinuationPoint& p, const ContactOptions& contact) {
  const auto value = [&](const char* name) { return p.derived.count(name) ? p.derived.at(name) : NAN; };
  std::ostringstream what;
  if (value("min_gap") < -1e3 * contact.penetration_tolerance)
    what << "the rod penetrates an obstacle (min_gap " << value("min_gap") << ")";
  else if (value("min_contact_force") < -1e3 * contact.force_tolerance)
    what << "a contact pulls (force " << value("min_contact_force") << ")";
  else if (value("min_wrap_tension") < -1e3 * contact.force_tolerance)
    what << "a wrapped part pulls on its disc (tension " << value("min_wrap_tension") << ")";
  else
    return "";
  what << " at " << p.parameter;
  return what.str();
}

// The changes of the active set a contact leg stops at (contact.hpp says what each does), each a
// stopping event of the leg on a derived quantity.
enum class ContactChange {
  ObstacleReached,
  ContactLiftsOff,
  FlatContactBuckles,
  ContactShrinksToAPoint,
  ContactFlattens,
  WrapTensionVanishes,
};

// What the handler of a change works on, the leg's event point, and what it leaves for the next leg.
struct ChangeAt {
  const ShootingProblem& here;                // the leg's problem at the event's parameter
  const ContinuationPoint& at;
  const std::vector<PointContact>& contacts;  // the leg's active set, solved at `at`
  const ContactOptions& contact;
  std::ostringstream& change;                 // what changed, for the log
  std::vector<PointContact> next = {};        // the next leg's active set
  std::optional<ContinuationPoint> fold_onset = {};  // the next leg leaves the flat branch here...
  size_t fold_contact = 0;                           // ...along the fold after this contact
  std::optional<size_t> unwound_contact = {};        // a contact that has just shrunk to a point
};
// A change after which the run ends instead of starting a leg: why, and whether the point is
// inadmissible (a change that is not modelled) rather than a plain stop.
struct RunEnd {
  std::string message;
  bool inadmissible = true;
};
using ChangeHandler = std::optional<RunEnd> (*)(ChangeAt&);

std::optional<RunEnd> wrap_tension_vanishes(ChangeAt&) {
  return RunEnd{"the tension of a wrapped part vanishes: beyond, it would pull on the disc and lift off inside the "
                "wrap, which is not modelled"};
}

// The reverse of contact_flattens: the extended contact becomes a point contact carrying both edge
// forces (at zero length they act at the same point, along the same normal).
std::optional<RunEnd> contact_shrinks_to_a_point(ChangeAt& c) {
  c.next = c.contacts;
  const auto shortest = std::min_element(c.next.begin(), c.next.end(), [](const auto& a, const auto& b) {
    return (a.extended ? a.s_end - a.s : INFINITY) < (b.extended ? b.s_end - b.s : INFINITY);
  });
  c.change << "the extended contact at s = " << shortest->s << " shrinks to a point contact";
  shortest->extended = false;
  shortest->force += shortest->force_end;
  shortest->s_end = shortest->s;
  shortest->force_end = 0.0;
  c.unwound_contact = static_cast<size_t>(shortest - c.next.begin());
  return std::nullopt;
}

// Beyond, the flat branch is unstable: the flat part buckles away from the obstacle into a hanging
// fold, two point contacts with a blister between them.
std::optional<RunEnd> flat_contact_buckles(ChangeAt& c) {
  const size_t which = buckling_flat_contact(c.here, c.at.x, c.contacts);
  c.change << "the flat contact over [" << c.contacts[which].s << ", " << c.contacts[which].s_end
           << "] buckles away from the obstacle: a hanging fold";
  c.next = split_into_fold(c.contacts, which);
  c.fold_onset = c.at;
  c.fold_contact = which;
  return std::nullopt;
}

// The point contact whose curvature away from the obstacle vanished becomes an extended contact of
// zero length there; it grows along the obstacle from the next leg on.
std::optional<RunEnd> contact_flattens(ChangeAt& c) {
  const ShootingProblem& here = c.here;
  const ContinuationPoint& at = c.at;
  c.next = c.contacts;
  double smallest = INFINITY;
  size_t which = 0;
  for (size_t k = 0; k < c.contacts.size(); ++k) {
    if (c.contacts[k].extended) continue;
    const double g2 = here.contact_bending(at.x, c.contacts[k]);
    if (g2 < smallest) {
      smallest = g2;
      which = k;
    }
  }
  PointContact& p = c.next[which];
  const Obstacle o = here.obstacles(here.parameters_at(at.x))[p.obstacle];
  // The rod's curvature has reached the obstacle's: beyond, it would lie on it over an interval.
  if (const std::string e = extended_contact_unsupported(*here.equations(here.parameters_at(at.x)), o); !e.empty())
    return RunEnd{"the contact at s = " + std::to_string(p.s) + " starts to wrap around " + o.describe() + ": " + e};
  if (!here.equations(here.parameters_at(at.x))->is_planar())
    return RunEnd{"the contact at s = " + std::to_string(p.s) + " starts to wrap around " + o.describe() +
                  ": a spatial rod lying on a cylinder is solved by multiple shooting (rod_on_cylinder.hpp), "
                  "and contact continuation is single shooting - following the wrap here is not implemented"};
  if (!o.is_flat()) {
    // A wrap presses on the disc with its tension / radius: in compression the rod cannot lie
    // on the disc, it would touch it at two points either side instead.
    const RodPoint r = here.sample(at.x, {p.s}).front();
    const double tension = r.n.dot(r.R.col(2));
    if (tension < -c.contact.force_tolerance)
      return RunEnd{"the contact at s = " + std::to_string(p.s) + " reaches the curvature of " + o.describe() +
                    " in compression (n.t = " + std::to_string(tension) +
                    "): it would touch the disc at two points either side, which is not implemented"};
  }
  p.extended = true;
  p.s_end = p.s;
  p.force_end = 0.5 * p.force;
  p.force *= 0.5;
  c.change << "the contact at s = " << p.s
           << (o.is_flat() ? " flattens into an extended contact" : " starts to wrap around the obstacle");
  return std::nullopt;
}

std::optional<RunEnd> contact_lifts_off(ChangeAt& c) {
  const auto weakest = std::min_element(c.contacts.begin(), c.contacts.end(),
                                        [](const auto& a, const auto& b) { return a.force < b.force; });
  c.change << "the contact at s = " << weakest->s << " lifts off";
  c.next = c.contacts;
  c.next.erase(c.next.begin() + (weakest - c.contacts.begin()));
  return std::nullopt;
}

// Where the rod reaches an obstacle: the smallest gap, refined between samples.
std::optional<RunEnd> obstacle_reached(ChangeAt& c) {
  const ClosestApproach reached = sampled_closest_approach(c.here, c.at.x, c.contact.samples);
  const int which = reached.obstacle;
  const double margin = 2.0 * reached.spacing;
  for (const auto& a : c.contacts)
    if (a.obstacle == which && reached.s > a.s - margin && reached.s < (a.extended ? a.s_end : a.s) + margin)
      return RunEnd{"the rod penetrates the obstacle next to an active contact at s = " + std::to_string(reached.s) +
                        " (a curved obstacle or a lift-off pattern not modelled): the run stops here",
                    false};
  const double where = closest_approach(c.here, c.at.x, c.contact.samples).s;
  c.change << "a contact appears with obstacle " << which << " at s = " << where;
  c.next = c.contacts;
  c.next.push_back({which, where, 0.0});
  std::sort(c.next.begin(), c.next.end(), [](const auto& a, const auto& b) { return a.s < b.s; });
  return std::nullopt;
}

// The table of changes, in the order of ContactChange: the derived quantity each one's event
// watches, the event's label (the point's `event` until the change is logged) and its handler.
struct ContactChangeKind {
  ContactChange change;
  const char* quantity;
  const char* label;
  ChangeHandler handle;
};
const ContactChangeKind kContactChanges[] = {
    {ContactChange::ObstacleReached, "min_gap", "obstacle_reached", obstacle_reached},
    {ContactChange::ContactLiftsOff, "min_contact_force", "contact_lifts_off", contact_lifts_off},
    {ContactChange::FlatContactBuckles, "flat_contact_margin", "flat_contact_buckles", flat_contact_buckles},
    {ContactChange::ContactShrinksToAPoint, "min_contact_length", "contact_shrinks_to_a_point",
     contact_shrinks_to_a_point},
    {ContactChange::ContactFlattens, "contact_bending", "contact_flattens", contact_flattens},
    {ContactChange::WrapTensionVanishes, "min_wrap_tension", "wrap_tension_vanishes", wrap_tension_vanishes},
};
const ContactChangeKind& kind_of(ContactChange change) { return kContactChanges[static_cast<int>(change)]; }

// A leg's options: the run's, with a stopping event for each change its active set d can undergo
// after the caller's events (`changes` says which change each of those is, in order), and its
// share of the run's max_points and branch points. bending_event: where contact_flattens is armed.
RodContinuationOptions leg_options(const RodContinuationOptions& options, const ProblemDefinition& d,
                                const ContactOptions& contact, double bending_event,
                                std::vector<ContactChange>* changes) {
  RodContinuationOptions leg = options;
  changes->clear();
  const auto add = [&](ContactChange change, double value) {
    leg.events.push_back({kind_of(change).quantity, value, true, kind_of(change).label});
    changes->push_back(change);
  };
  // The gap event sits at -penetration_tolerance: an active contact touches with a gap of 0 up to
  // round-off, whose sign must not count as a crossing.
  add(ContactChange::ObstacleReached, -contact.penetration_tolerance);
  leg.samples = std::max(leg.samples, contact.samples);
  if (!d.contacts.empty()) add(ContactChange::ContactLiftsOff, 0.0);
  const bool has_point = std::any_of(d.contacts.begin(), d.contacts.end(), [](const auto& c) { return !c.extended; });
  // With an extended contact the Jacobian is singular all along the branch (smallest singular
  // value ~1e-9 of the largest on wall.toml), so the bordered determinant's sign is noise.
  // Cause: H is invariant and equals -P on the flat part (theta = 0, kappa = 0), so wherever
  // else the rod is parallel to the obstacle - at an end clamped parallel to it - the curvature
  // vanishes too. That end's moment m0 is then a double root (H = EI kappa0^2 / 2 - P = -P),
  // and to first order the arc between the clamp and the flat part can slide along itself
  // (m0 and s change together, the tangency rows do not see it): the null vector of F_x is
  // (dm0, ds) = (1, 1 / n_y). The solution is isolated only at second order. Branch points
  // are not looked for rather than reported falsely; removing the degeneracy would need the
  // double root replaced by its square root (kappa0 = 0 imposed at such an end).
  if (has_extended_contact(d.contacts)) {
    leg.detect_branch_points = false;
    add(ContactChange::FlatContactBuckles, 0.0);
    add(ContactChange::ContactShrinksToAPoint, 0.0);
  }
  // After a contact shrank to a point its g'' starts at ~0 (to the event's location, not
  // exactly): the event is armed at that start value, so the start is not a crossing.
  if (has_point && d.kind == RodKind::Planar) add(ContactChange::ContactFlattens, bending_event);
  // A wrapped part presses on its disc with tension / radius: where the tension would turn to
  // compression the rod leaves the disc inside the wrap.
  if (has_wrap(d)) add(ContactChange::WrapTensionVanishes, 0.0);
  return leg;
}

// The legs of a contact continuation, one continuation per active set, each ending at the event
// where the set changes; from unknowns x (a new run) or from a saved state (a resume).
class LegMarch {
 public:
  LegMarch(ProblemDefinition d, Eigen::VectorXd x, const ContactMarchState* resume_from, RodContinuationOptions options,
           const PointSink& sink, const ContactOptions& contact, const ActiveSetSink& active_set_sink,
           const ContactStateSink& state_sink, const ContinuationPoint* switch_at, double side)
      : d_(std::move(d)),
        x_(std::move(x)),
        resume_from_(resume_from),
        options_(std::move(options)),
        sink_(sink),
        contact_(contact),
        active_set_sink_(active_set_sink),
        state_sink_(state_sink),
        switch_at_(switch_at),
        side_(side),
        reported_(resume_from ? resume_from->reported : 0),
        run_first_leg_(resume_from ? resume_from->first_leg : true),
        branch_points_before_(resume_from ? resume_from->branch_points_before : 0) {}

  ContactContinuationResult run(ContactContinuationResult out) {
    while (true) {
      const ShootingProblem problem(d_);
      const ContinuationResult r = follow_leg(problem);
      out.result.points.insert(out.result.points.end(), r.points.begin(), r.points.end());
      out.result.reason = r.reason;
      out.result.message = r.message;
      out.definition = d_;
      first_leg_ = false;
      run_first_leg_ = false;
      if (r.reason != StopReason::EventStop || r.points.empty()) return out;
      if (!change_active_set(problem, r.points.back(), &out)) return out;
      // The leg ended on its event with the run's points spent: the next leg would have none
      // beyond its start (the event point, reported).
      if (reported_ >= options_.max_points) {
        out.result.reason = StopReason::MaxPoints;
        out.result.message.clear();
        return out;
      }
    }
  }

 private:
  // One leg on the present active set, to its first stopping event; its points without its
  // start where that is the previous leg's last point, and without a point that violates
  // complementarity or any after it (the run then stops as inadmissible).
  ContinuationResult follow_leg(const ShootingProblem& problem) {
    const bool resuming = first_leg_ && resume_from_;
    // After a contact shrank to a point, contact_flattens is armed at its g'' there.
    const double bending_event = resuming ? resume_from_->contact_bending_event : unwound_bending_.value_or(0.0);
    unwound_bending_.reset();
    RodContinuationOptions leg = leg_options(options_, d_, contact_, bending_event, &changes_);
    // (A later leg's start is the last point of the previous one, counted there.)
    leg.max_points =
        resuming ? resume_from_->leg_max_points : options_.max_points - reported_ + (run_first_leg_ ? 0 : 1);
    if (options_.stop_at_branch_point > 0)
      leg.stop_at_branch_point = options_.stop_at_branch_point - branch_points_before_;
    if (active_set_sink_) active_set_sink_(d_.contacts);
    // A leg starts on the previous leg's last point, which is already reported. A point that
    // violates complementarity (an event missed, e.g. a leg started where two changes coincide)
    // ends the run there: it and the points after it are not reported.
    bool skip = !first_leg_;
    std::string violation;
    auto leg_sink = [&](const ContinuationPoint& p) {
      if (skip) {
        skip = false;
        return;
      }
      if (violation.empty()) violation = complementarity_violation(p, contact_);
      if (violation.empty()) {
        ++reported_;
        if (sink_) sink_(p);
      }
    };
    // The state to resume from at each resumable point of the leg, the leg's start included: a
    // later leg's start (not reported: it is the previous leg's event point) is where a run
    // killed before the leg's first new point resumes, without redoing the change of active set.
    leg.on_resumable = nullptr;
    if (state_sink_)
      leg.on_resumable = [&, leg_max_points = leg.max_points, bending_event](const MarchState& m) {
        if (violation.empty())
          state_sink_({m, d_.contacts, bending_event, leg_max_points, reported_, run_first_leg_, branch_points_before_});
      };
    const bool switching = first_leg_ && switch_at_ && !resuming;
    ContinuationResult r = resuming    ? RodContinuation(problem, leg).resume(resume_from_->march, leg_sink)
                           : switching ? RodContinuation(problem, leg).switch_branch(*switch_at_, leg_sink, side_)
                           : fold_onset_ ? leave_flat_branch(problem, leg, *fold_onset_, fold_contact_, leg_sink)
                                         : RodContinuation(problem, leg).run(x_, leg_sink);
    fold_onset_.reset();
    if (!first_leg_ && !r.points.empty()) r.points.erase(r.points.begin());
    // (The switched leg's start is the branch point switched at, not one found on this branch.)
    branch_points_before_ += static_cast<int>(
        std::count_if(r.points.begin() + (switching && !r.points.empty() ? 1 : 0), r.points.end(),
                      [](const ContinuationPoint& p) { return p.type == PointType::BranchPoint; }));
    if (!violation.empty()) {
      const auto bad = std::find_if(r.points.begin(), r.points.end(), [&](const ContinuationPoint& p) {
        return !complementarity_violation(p, contact_).empty();
      });
      r.points.erase(bad, r.points.end());
      r.reason = StopReason::Inadmissible;
      r.message = "the branch leaves the admissible set: " + violation + " (no event located before it)";
    }
    return r;
  }

  // The active set changed at the leg's event point `at`: the next leg's set and starting
  // unknowns, and the change logged in *out; false where the run ends there (a stopping event of
  // the caller's, or a change that is not modelled or not admissible).
  bool change_active_set(const ShootingProblem& problem, const ContinuationPoint& at, ContactContinuationResult* out) {
    ShootingProblem here = problem;
    here.set_parameter(options_.parameter, at.parameter);
    std::ostringstream change;
    change << options_.parameter << " = " << at.parameter << ": ";
    const auto contacts = here.contacts_at(at.x);
    // A stopping event of the caller's ends the run there; the leg's own change the active set.
    const int own = at.event_index - static_cast<int>(options_.events.size());
    if (own < 0) return false;
    ChangeAt c{here, at, contacts, contact_, change};
    if (const auto end = kind_of(changes_[own]).handle(c)) {
      if (end->inadmissible) out->result.reason = StopReason::Inadmissible;
      out->result.message = end->inadmissible ? end->message + "; the run stops here" : end->message;
      out->changes.push_back(change.str() + out->result.message);
      return false;
    }
    d_.contacts = std::move(c.next);
    if (c.fold_onset) fold_onset_ = std::move(c.fold_onset);
    fold_contact_ = c.fold_contact;
    out->changes.push_back(change.str());
    out->result.points.back().event = change.str();
    // The next leg starts from the same configuration with the new set.
    ProblemDefinition next_definition = d_;
    next_definition.parameters.set(options_.parameter, at.parameter);
    const ShootingProblem next(next_definition);
    x_ = carry_over(problem, at.x, next);
    if (c.unwound_contact) unwound_bending_ = next.contact_bending(x_, next.contacts_at(x_)[*c.unwound_contact]);
    d_ = next_definition;
    return true;
  }

  ProblemDefinition d_;  // the present leg's, with its active set
  Eigen::VectorXd x_;    // its starting unknowns
  const ContactMarchState* resume_from_;
  const RodContinuationOptions options_;
  const PointSink& sink_;
  const ContactOptions& contact_;
  const ActiveSetSink& active_set_sink_;
  const ContactStateSink& state_sink_;
  const ContinuationPoint* switch_at_;
  double side_;
  bool first_leg_ = true;  // the first leg of this call (its start is not a point reported before)
  // The run's points reported so far and whether the leg is the run's first: with a resume they
  // continue those of the interrupted run, so that the legs' shares of max_points are the same.
  int reported_;
  bool run_first_leg_;
  // Branch points found by earlier legs: stop_at_branch_point counts the run's, not one leg's.
  int branch_points_before_;
  std::vector<ContactChange> changes_;  // of the present leg's events after the caller's
  // Set when a flat contact has just buckled: the next leg leaves the flat branch along the fold.
  std::optional<ContinuationPoint> fold_onset_;
  size_t fold_contact_ = 0;  // the first of the fold's two contacts
  std::optional<double> unwound_bending_;  // g'' of a contact that has just shrunk to a point
};

ContactContinuationResult run_legs(ProblemDefinition d, Eigen::VectorXd x, const ContactMarchState* resume_from,
                                   RodContinuationOptions options, const PointSink& sink, const ContactOptions& contact,
                                   const ActiveSetSink& active_set_sink, const ContactStateSink& state_sink,
                                   ContactContinuationResult out, const ContinuationPoint* switch_at = nullptr,
                                   double side = 1.0) {
  LegMarch legs(std::move(d), std::move(x), resume_from, std::move(options), sink, contact, active_set_sink,
                state_sink, switch_at, side);
  return legs.run(std::move(out));
}

}  // namespace

ContactContinuationResult continue_with_contacts(ProblemDefinition d, const RodPoint& guess, RodContinuationOptions options,
                                                 const PointSink& sink, const ContactOptions& contact,
                                                 const ActiveSetSink& active_set_sink,
                                                 const ContactStateSink& state_sink) {
  ContactContinuationResult out;
  ContactSolveResult start = solve_with_contacts(d, guess, contact);
  if (!start.result.summary.converged() || !start.complementarity) {
    out.result.reason = failed_start_reason(options.deadline);
    out.result.message = "no admissible starting point: " + start.message;
    return out;
  }
  for (const auto& line : start.log) out.changes.push_back("start: " + line);
  return run_legs(start.definition, start.result.x, nullptr, std::move(options), sink, contact, active_set_sink,
                  state_sink, std::move(out));
}

ContactContinuationResult continue_with_contacts_from(ProblemDefinition d, const Eigen::VectorXd& x,
                                                      RodContinuationOptions options, const PointSink& sink,
                                                      const ContactOptions& contact,
                                                      const ActiveSetSink& active_set_sink,
                                                      const ContactStateSink& state_sink) {
  return run_legs(std::move(d), x, nullptr, std::move(options), sink, contact, active_set_sink, state_sink, {});
}

ContactContinuationResult switch_branch_with_contacts(ProblemDefinition d, const ContinuationPoint& branch_point,
                                                      double side, RodContinuationOptions options, const PointSink& sink,
                                                      const ContactOptions& contact,
                                                      const ActiveSetSink& active_set_sink,
                                                      const ContactStateSink& state_sink) {
  if (branch_point.multiplicity == 2 && d.kind == RodKind::Spatial)
    throw std::invalid_argument("a double branch point of a spatial rod with obstacles: switching there needs the "
                                "axial phase condition, which is not implemented for contact runs");
  d.parameters.set(options.parameter, branch_point.parameter);
  return run_legs(std::move(d), branch_point.x, nullptr, bifurcating_branch_options(std::move(options)), sink,
                  contact, active_set_sink, state_sink, {}, &branch_point, side);
}

ContactContinuationResult resume_with_contacts(ProblemDefinition d, const ContactMarchState& state,
                                               RodContinuationOptions options, const PointSink& sink,
                                               const ContactOptions& contact, const ActiveSetSink& active_set_sink,
                                               const ContactStateSink& state_sink) {
  d.contacts = state.contacts;
  d.parameters.set(options.parameter, state.march.current.parameter);
  return run_legs(std::move(d), state.march.current.x, &state, std::move(options), sink, contact, active_set_sink,
                  state_sink, {});
}

}  // namespace kirchhoff

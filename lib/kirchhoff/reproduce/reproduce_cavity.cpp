// `reproduce`'s Section 7.2 / Fig. 5 (reproduce_steps.hpp): the Elastica in a cavity, continued in
// the end shortening through point contact, extended contact and hanging fold to where the fold's
// contacts lift off together, each event against an elliptic solution, and the invariants across
// its contacts. The lower wall is never reached on this branch, so the same run is wall.toml's as
// well.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

constexpr double kWallHeight = 0.1;  // a of cases/cavity.toml

struct CavityPoint {
  ContinuationPoint point;
  std::shared_ptr<ShootingProblem> problem;  // with the active set the point was solved in
};

std::vector<CavityPoint> follow_cavity(const fs::path& cases) {
  const Case c = load_case((cases / "cavity.toml").string());
  RodContinuationOptions o = report_continuation(
      "Delta", 0.2, 2.0, ReportPoints::Followed,
      {"P", "H", "contact_length", "contact_count", "kappa_contact", "contact_s", "min_gap", "min_contact_force"});
  o.max_points = 6000;  // the whole branch, through its contact changes to lift-off
  std::vector<CavityPoint> points;
  ProblemDefinition leg = c.definition;
  auto on_leg = [&](const std::vector<PointContact>& active) { leg.contacts = active; };
  auto on_point = [&](const ContinuationPoint& p) {
    auto problem = std::make_shared<ShootingProblem>(leg);
    problem->set_parameter("Delta", p.parameter);
    points.push_back({p, problem});
  };
  const ContactContinuationResult result = continue_with_contacts(c.definition, c.start_guess, o, on_point, {}, on_leg);
  // Where the fold's forces vanish the admissible branch turns back (the free rod would
  // penetrate the wall): that is where this run must end, as "inadmissible".
  if (result.result.reason != StopReason::Inadmissible || points.size() != result.result.points.size())
    throw std::runtime_error("cavity: the continuation stopped early (" + std::string(to_string(result.result.reason)) +
                             ": " + result.result.message + ")");
  for (size_t i = 0; i < points.size(); ++i) points[i].point.event = result.result.points[i].event;
  return points;
}

// A text field for a CSV file read by numpy (no quoting): commas become semicolons.
std::string without_commas(std::string text) {
  std::replace(text.begin(), text.end(), ',', ';');
  return text;
}

// The state of the rod at a point, for the figure: free, point, flat or fold.
std::string contact_state(const std::vector<PointContact>& contacts) {
  if (contacts.empty()) return "free";
  if (has_extended_contact(contacts)) return has_hanging_fold(contacts) ? "flat+fold" : "flat";
  return has_hanging_fold(contacts) ? "fold" : "point";
}

// 1.-3. The free arch touches the upper wall, the contact flattens, the flat part buckles.
void first_events(const Step& step, const std::vector<const CavityPoint*>& events) {
  auto* rows = step.rows;
  const double a = kWallHeight;
  // One clamped-clamped arch of length L is half of the two arches of a rod 2L long
  // (second_mode_arches). The event is located where the crest is the active-set loop's
  // tolerance, 1e-9, past the wall.
  const double touch = 0.5 * analytic::second_mode_arches(2.0, 1.0, a + ContactOptions{}.penetration_tolerance).Delta;
  rows->push_back({"Sec. 7.2 / Fig. 5, cavity", "Delta where the free arch touches the wall", {}, touch,
                   events[0]->point.parameter, touch, 1e-8, "elliptic arch of height a + 1e-9 (event min_gap = -1e-9)"});
  // Flattening and the fold's onset: where H = -P the clamps' curvature is a double root and the
  // Jacobian singular, so residuals of 1e-10 give ~1e-6 (see contact.cpp).
  const auto flattening = analytic::contact_flattening(1.0, 1.0, a);
  rows->push_back({"Sec. 7.2 / Fig. 5, cavity", "Delta where the point contact flattens (kappa_c = 0)", {},
                   flattening.Delta, events[1]->point.parameter, flattening.Delta, 5e-6,
                   "outer arcs: full inflectional waves (H = -P); singular Jacobian there"});
  const auto onset = analytic::flat_contact_buckling(1.0, 1.0, a);
  const auto& buckle = events[2]->point;
  const double l = buckle.derived.at("contact_length");
  rows->push_back({"Sec. 7.2, hanging fold onset (also wall.toml)", "Delta where P l^2 = 4 pi^2 EI", {}, onset.Delta,
                   buckle.parameter, onset.Delta, 5e-6, "elliptic: arcs of H = -P around a flat part at its Euler load"});
  rows->push_back({"Sec. 7.2, hanging fold onset (also wall.toml)", "P there", {}, onset.P, buckle.derived.at("P"),
                   onset.P, 5e-6, "flat length " + format_short(l) + " (elliptic " + format_short(onset.flat_length) + ")"});
  rows->push_back({"Sec. 7.2, hanging fold onset (also wall.toml)", "P l^2 / (4 pi^2 EI) at the located event", {}, 1.0,
                   buckle.derived.at("P") * l * l / (4.0 * M_PI * M_PI), 1.0, 1e-8, "event flat_contact_buckles"});
}

// 4. The fold branch turns back first (subcritical), then the contacts lift off together where
// the rod is the free second mode with its crests on the wall.
void fold_events(const Step& step, const std::vector<CavityPoint>& points, const CavityPoint& lift_off) {
  auto* rows = step.rows;
  for (const auto& p : points)
    if (p.point.type == PointType::Fold && contact_state(p.problem->contacts_at(p.point.x)) == "fold") {
      rows->push_back({"Sec. 7.2, hanging fold", "Delta at the fold branch's turning point (subcritical onset)", {}, {},
                       p.point.parameter, 1.0, 0.0, "the flat contact snaps into the fold"});
      break;
    }
  const auto arches = analytic::second_mode_arches(1.0, 1.0, kWallHeight);
  rows->push_back({"Sec. 7.2 / Fig. 5, cavity", "Delta where the fold's contacts lift off (second mode touches)", {},
                   arches.Delta, lift_off.point.parameter, arches.Delta, 1e-8,
                   "at s = " + format_short(lift_off.point.derived.at("contact_s")) + " and 3/4; beyond, inadmissible"});
  rows->push_back({"Sec. 7.2 / Fig. 5, cavity", "P there", {}, arches.P, lift_off.point.derived.at("P"), arches.P,
                   1e-8, "elliptic: two arches of length L/2"});
}

// 5. Invariants: H across every contact, H = -P on flat contacts, and the two never coexist.
void contact_invariants(const Step& step, const std::vector<CavityPoint>& points) {
  double jump = 0.0, flat_H = 0.0, fold_margin = INFINITY;
  int both = 0;
  for (const auto& p : points) {
    const auto contacts = p.problem->contacts_at(p.point.x);
    const RodModel& model = p.problem->equations(p.problem->parameters_at(p.point.x))->model();
    const double P = p.point.derived.at("P"), H = p.point.derived.at("H");
    for (const auto& c : contacts)
      for (double s : {c.s, c.extended ? c.s_end : c.s}) {
        const auto pair = p.problem->sample(p.point.x, {s - 1e-9, s + 1e-9});
        jump = std::max(jump, std::abs(hamiltonian(model, pair[1]) - hamiltonian(model, pair[0])) / std::abs(H));
      }
    const std::string state = contact_state(contacts);
    if (state == "flat" && contacts.front().s_end > contacts.front().s) flat_H = std::max(flat_H, std::abs(H + P) / P);
    if (state == "fold") fold_margin = std::min(fold_margin, (H + P) / P);
    both += state == "flat+fold" ? 1 : 0;
  }
  auto* rows = step.rows;
  rows->push_back({"Sec. 7.2, H across contacts", "max abs(H+ - H-) / abs(H) over all contacts of " +
                       std::to_string(points.size()) + " points", {}, 0.0, jump, 1.0, 1e-9, "frictionless contact adds nothing to H"});
  rows->push_back({"Sec. 7.2, extended contact", "max abs(H + P) / P on flat contacts", {}, 0.0, flat_H, 1.0, 1e-9,
                   "theta = 0, kappa = 0 on the flat part: H = -P"});
  rows->push_back({"Sec. 7.2, hanging fold", "min (H + P) / P on folds (= EI kappa_c^2 / 2P > 0)", {}, {}, fold_margin,
                   1.0, 0.0, "so a flat contact and a fold never share a rod; points with both: " + std::to_string(both)});
}

// fig5_cavity_branch.csv: one row per point with its contact state and event.
void write_branch(const fs::path& file, const std::vector<CavityPoint>& points) {
  std::ofstream branch(file);
  branch.precision(15);
  branch << "Delta,P,H,contact_count,contact_length,state,type,event\n";
  for (const auto& p : points)
    branch << p.point.parameter << ',' << p.point.derived.at("P") << ',' << p.point.derived.at("H") << ','
           << p.point.derived.at("contact_count") << ',' << p.point.derived.at("contact_length") << ','
           << contact_state(p.problem->contacts_at(p.point.x)) << ',' << to_string(p.point.type) << ','
           << without_commas(p.point.event) << '\n';
}

// fig5_cavity_profiles.csv: profiles at increasing Delta, one of each state and the events.
void write_profiles(const fs::path& file, const std::vector<CavityPoint>& points) {
  std::ofstream profiles(file);
  profiles.precision(15);
  profiles << "Delta,state,s,x,y\n";
  std::vector<double> s(201);
  for (size_t i = 0; i < s.size(); ++i) s[i] = i / 200.0;
  for (double target : {0.015, 0.028, 0.040, 0.060, 0.085, 1.0}) {
    const CavityPoint* p = &points.front();
    for (const auto& q : points)
      if (std::abs(q.point.parameter - target) < std::abs(p->point.parameter - target)) p = &q;
    const std::string state = contact_state(p->problem->contacts_at(p->point.x));
    for (const auto& q : p->problem->sample(p->point.x, s))
      profiles << p->point.parameter << ',' << state << ',' << q.s << ',' << q.r.x() << ',' << q.r.y() << '\n';
  }
}

}  // namespace

void cavity(const Step& step) {
  const std::vector<CavityPoint> points = follow_cavity(step.cases);
  std::vector<const CavityPoint*> events;
  for (const auto& p : points)
    if (p.point.type == PointType::Event) events.push_back(&p);
  if (events.size() < 4) throw std::runtime_error("cavity: fewer events than expected");
  first_events(step, events);
  fold_events(step, points, *events[3]);
  contact_invariants(step, points);
  write_branch(step.out / "fig5_cavity_branch.csv", points);
  write_profiles(step.out / "fig5_cavity_profiles.csv", points);
}

}  // namespace kirchhoff::reproduce_steps

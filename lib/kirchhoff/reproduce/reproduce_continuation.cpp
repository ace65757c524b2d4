// `reproduce`'s continuation results (reproduce_steps.hpp): the Euler column's branch points, its
// first buckled branch against the elliptic solution, the twisted rod's double branch point and
// Michell's ring's.
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

// The straight column continued in P to 100: its first three branch points against (k pi)^2.
std::vector<ContinuationPoint> column_branch_points(const ShootingProblem& problem, const Case& column,
                                                    const RodContinuationOptions& o, std::vector<ReportRow>* rows) {
  RodContinuation straight(problem, o);
  const ContinuationResult r = straight.run(problem.initial_unknowns(column.start_guess));
  std::vector<ContinuationPoint> bps;
  for (const auto& p : r.points)
    if (p.type == PointType::BranchPoint) bps.push_back(p);
  for (int k = 1; k <= 3 && k <= static_cast<int>(bps.size()); ++k) {
    const double exact = analytic::euler_critical_load(analytic::EulerEnds::PinnedPinned, 1.0, 1.0, k);
    rows->push_back({"Euler column, branch point " + std::to_string(k), "P = (k pi)^2 EI/L^2", {}, exact,
                     bps[k - 1].parameter, exact, 1e-8, "located by the sign of the bordered determinant"});
  }
  if (bps.empty()) throw std::runtime_error("no branch point on the straight Euler column");
  return bps;
}

// The first buckled branch, switched onto at the first branch point, to theta0 = 3: P(theta0)
// against 4K(k)^2 at every regular point, into euler_buckled_branch.csv.
void buckled_column(const Step& step, const ShootingProblem& problem, const ContinuationPoint& first) {
  RodContinuationOptions b = report_continuation("P", NAN, 1.0, ReportPoints::Located, {"theta0"});
  b.initial_step = 0.05;
  b.events = {{"theta0", 3.0, true, ""}};
  b.compute_stability = true;  // make_figures.py draws stable parts solid, unstable ones dashed
  RodContinuation buckled(problem, b);
  const ContinuationResult branch = buckled.switch_branch(first);
  std::ofstream csv(step.out / "euler_buckled_branch.csv");
  csv.precision(15);
  csv << "P,theta0,P_elliptic,type,stability_index\n";
  double worst = 0.0;
  for (const auto& p : branch.points) {
    const double theta0 = p.derived.at("theta0");
    const double exact = theta0 > 1e-6 ? analytic::PinnedElastica{1.0, 1.0, theta0}.load() : M_PI * M_PI;
    csv << p.parameter << ',' << theta0 << ',' << exact << ',' << to_string(p.type) << ','
        << (p.stability_index ? *p.stability_index : -1) << '\n';
    if (p.type == PointType::Regular && theta0 > 1e-3) worst = std::max(worst, std::abs(p.parameter / exact - 1.0));
  }
  step.rows->push_back({"Fig. 3 branch, P(theta0) to theta0 = 3",
                        "max abs(P / 4K(k)^2 - 1) over " + std::to_string(branch.points.size()) + " points", {}, 0.0,
                        worst, 1.0, 1e-8,
                        "pseudo-arclength from the first branch point; the singular touching-ends point excluded"});
}

// A twisted rod's first double branch point along `parameter` (from `from` towards `to`), against
// the closed form `exact`: a row labelled `id` and `quantity`.
struct TwistedBranchPoint {
  const char* file;
  const char* parameter;
  double from, to, max_step, exact;
  const char* id;
  const char* quantity;
};

void first_branch_point_row(const Step& step, const TwistedBranchPoint& t) {
  const Case c = load_case((step.cases / t.file).string(), {{t.parameter, t.from}});
  const ShootingProblem rod(c.definition);
  RodContinuation twist(rod, report_continuation(t.parameter, t.to, t.max_step, ReportPoints::Located));
  const ContinuationResult tr = twist.run(rod.initial_unknowns(c.start_guess));
  for (const auto& p : tr.points)
    if (p.type == PointType::BranchPoint) {
      step.rows->push_back({t.id, t.quantity, {}, t.exact, p.parameter, t.exact, 1e-6,
                            "multiplicity " + std::to_string(p.multiplicity) + ", seen by the singular values"});
      return;
    }
}

// The twisted clamped rod continued in phi against Greenhill's; Michell's ring continued in its
// twist against C tau R = sqrt(3) B.
void twisted_branch_points(const Step& step) {
  const double C = 0.769230769230769;  // both cases' twist stiffness, B / 1.3
  first_branch_point_row(step, {"twisted_clamped.toml", "phi", 6.0, 15.0, 1.0,
                                analytic::clamped_twisted_critical_moment(1.0, 0.0, 1.0) / C,
                                "Twisted clamped rod (Greenhill)", "phi at the double branch point (M L/B = 8.9868)"});
  first_branch_point_row(step, {"michell_ring.toml", "tau", 1.0, 3.0, 0.2,
                                analytic::michell_ring_critical_twist(1.0, C, 1.0), "Michell's twisted ring",
                                "tau at the double branch point (C tau R / B = sqrt(3))"});
}

}  // namespace

void continuation(const Step& step) {
  const Case column = load_case((step.cases / "euler_column.toml").string(), {{"P", 1.0}, {"theta_guess", 0.0}});
  const ShootingProblem problem(column.definition);
  const RodContinuationOptions o = report_continuation("P", 100.0, 5.0, ReportPoints::Located, {"theta0"});
  const std::vector<ContinuationPoint> bps = column_branch_points(problem, column, o, step.rows);
  buckled_column(step, problem, bps[0]);
  twisted_branch_points(step);
}

}  // namespace kirchhoff::reproduce_steps

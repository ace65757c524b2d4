// `reproduce`'s continuation results (reproduce_steps.hpp): the Euler column's branch points, its
// first buckled branch against the elliptic solution, and the twisted rod's double branch point.
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

// The twisted clamped rod continued in phi: its first branch point against Greenhill's.
void twisted_branch_point(const Step& step) {
  const Case twisted = load_case((step.cases / "twisted_clamped.toml").string(), {{"phi", 6.0}});
  const ShootingProblem rod(twisted.definition);
  RodContinuation twist(rod, report_continuation("phi", 15.0, 1.0, ReportPoints::Located));
  const ContinuationResult tr = twist.run(rod.initial_unknowns(twisted.start_guess));
  for (const auto& p : tr.points)
    if (p.type == PointType::BranchPoint) {
      const double exact = analytic::clamped_twisted_critical_moment(1.0, 0.0, 1.0) / 0.769230769230769;
      step.rows->push_back({"Twisted clamped rod (Greenhill)", "phi at the double branch point (M L/B = 8.9868)", {},
                            exact, p.parameter, exact, 1e-6,
                            "multiplicity " + std::to_string(p.multiplicity) + ", seen by the singular values"});
      break;
    }
}

}  // namespace

void continuation(const Step& step) {
  const Case column = load_case((step.cases / "euler_column.toml").string(), {{"P", 1.0}, {"theta_guess", 0.0}});
  const ShootingProblem problem(column.definition);
  const RodContinuationOptions o = report_continuation("P", 100.0, 5.0, ReportPoints::Located, {"theta0"});
  const std::vector<ContinuationPoint> bps = column_branch_points(problem, column, o, step.rows);
  buckled_column(step, problem, bps[0]);
  twisted_branch_point(step);
}

}  // namespace kirchhoff::reproduce_steps

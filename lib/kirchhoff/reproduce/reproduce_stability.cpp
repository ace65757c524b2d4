// `reproduce`'s stability indices (reproduce_steps.hpp, stability.hpp) of classical equilibria,
// against what is known of them independently (Euler's loads, the modes of the clamped rod,
// Greenhill, Michell's ring). A row passes when the index is the expected integer.
#include <cmath>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

ReportRow index_row(const std::string& id, const std::string& quantity, int expected, const Solved& s,
                    const std::string& note) {
  const StabilityReport r = analyse_stability(*s.problem, s.solution.result.x);
  ReportRow row{id, quantity, {}, static_cast<double>(expected), r.index ? *r.index : NAN, 1.0, 0.0, note};
  row.stability = describe(r);
  return row;
}

void euler_column_indices(const Step& step) {
  auto* rows = step.rows;
  const fs::path column = step.cases / "euler_column.toml";
  for (double P : {5.0, 20.0, 50.0})
    rows->push_back(index_row("Stability: straight Euler column, P = " + format_short(P), "index = #{(k pi)^2 < P}",
                              static_cast<int>(std::floor(std::sqrt(P) / M_PI)),
                              solve_for_report(column, {{"P", P}, {"theta_guess", 0.0}}, 41), "dead load, roller end"));
  rows->push_back(index_row("Stability: Euler column, first mode, P = 20", "index", 0,
                            solve_for_report(column, {{"P", 20.0}, {"theta_guess", 2.0}}, 41), "before the ends meet"));
  rows->push_back(index_row("Stability: Euler column, first mode, P = 50", "index", 1,
                            solve_for_report(column, {{"P", 50.0}, {"theta_guess", 2.8}}, 41),
                            "ends crossed (theta0 > 2.2813): the rod turns about the pin; a 400-element energy "
                            "Hessian gives -0.68"));
  rows->push_back(index_row("Stability: Euler column, second mode, P = 50", "index", 1,
                            solve_for_report(column, {{"P", 50.0}, {"theta_guess", 1.0}}, 41), ""));
}

}  // namespace

void stability(const Step& step) {
  auto* rows = step.rows;
  euler_column_indices(step);
  const fs::path clamped = step.cases / "clamped_clamped.toml";
  rows->push_back(index_row("Stability: clamped-clamped, D = 0.9, symmetric mode", "index", 0,
                            solve_for_report(clamped, {}, 41), "end shortening imposed"));
  rows->push_back(index_row("Stability: clamped-clamped, D = 0.9, S-shaped mode", "index", 1,
                            solve_for_report(clamped, {{"s_mode", 1.0}}, 41), "end shortening imposed"));
  const double phi_c = analytic::clamped_twisted_critical_moment(1.0, 0.0, 1.0) / 0.769230769230769;
  const fs::path twisted = step.cases / "twisted_clamped.toml";
  rows->push_back(index_row("Stability: twisted straight rod below the Greenhill point", "index", 0,
                            solve_for_report(twisted, {{"phi", phi_c - 0.5}}, 41), ""));
  rows->push_back(index_row("Stability: twisted straight rod above the Greenhill point", "index", 2,
                            solve_for_report(twisted, {{"phi", phi_c + 0.5}}, 41), "double branch point"));
  const double tau_c = analytic::michell_ring_critical_twist(1.0, 0.769230769230769, 1.0);
  const fs::path ring = step.cases / "michell_ring.toml";
  rows->push_back(index_row("Stability: Michell's twisted ring below C tau R = sqrt(3) B", "index", 0,
                            solve_for_report(ring, {{"tau", 0.97 * tau_c}}, 41), "tau = 0.97 of Michell's"));
  rows->push_back(index_row("Stability: Michell's twisted ring above C tau R = sqrt(3) B", "index", 2,
                            solve_for_report(ring, {{"tau", 1.03 * tau_c}}, 41),
                            "tau = 1.03 of Michell's; two out-of-plane modes at once"));
}

}  // namespace kirchhoff::reproduce_steps

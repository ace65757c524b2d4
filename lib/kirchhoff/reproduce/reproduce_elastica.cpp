// `reproduce`'s single-solve results of the planar and straight rods (reproduce_steps.hpp): Fig. 3
// and eq. (54), Fig. 9 and eq. (57), the invariants of Section 5, and Figs. 6-8.
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

// The numeric profile with the elliptic-function shape beside it.
void write_fig3_profile(const fs::path& file, const Solved& s, const analytic::PinnedElastica& exact) {
  std::ofstream csv(file);
  csv.precision(15);
  csv << "s,x,y,theta,kappa,H,x_analytic,y_analytic,theta_analytic\n";
  const RodModel& model = s.problem->equations(s.solution.result.parameters)->model();
  for (const auto& p : s.solution.profile)
    csv << p.s << ',' << p.r.x() << ',' << p.r.y() << ',' << p.turn_angle << ',' << p.u[1] << ','
        << hamiltonian(model, p) << ',' << exact.x(p.s) << ',' << exact.y(p.s) << ',' << exact.theta(p.s) << '\n';
}

}  // namespace

// Fig. 3 and eq. (54): the simply supported Elastica for several end slopes.
void simply_supported(const Step& step) {
  auto* rows = step.rows;
  // Newton to 1e-10 on residuals integrated at 1e-12: 1e-9 relative on P, 1e-8 on the shape.
  for (double theta0 : {0.5, 1.0, 2.0, 2.8}) {
    const analytic::PinnedElastica exact{1.0, 1.0, theta0};
    const Solved s =
        solve_for_report(step.cases / "simply_supported.toml", {{"theta0", theta0}, {"P", 1.1 * exact.load()}}, 201);
    const auto& d = s.solution.derived;
    std::ostringstream label;
    label << std::fixed << std::setprecision(1) << theta0;
    const std::string id = "Fig. 3, theta0 = " + label.str(), eq54 = "eq. (54), theta0 = " + label.str();
    const double P = d.at("P");
    const double kappa_M = analytic::eq54_kappa_max(P, 1.0, theta0), y_M = analytic::eq54_y_max(P, 1.0, theta0);
    rows->push_back({id, "P (4 K(k)^2 EI/L^2)", {}, exact.load(), P, exact.load(), 1e-9, ""});
    rows->push_back({eq54, "kappa_M", {}, kappa_M, d.at("kappa_max"), kappa_M, 1e-8, ""});
    rows->push_back({eq54, "y_M", {}, y_M, d.at("y_max"), y_M, 1e-8, ""});
    rows->push_back({id, "H spread / scale (eq. 53 invariant)", {}, 0.0, s.solution.invariants.H.spread,
                     s.solution.invariants.H.scale, 1e-9, "H = EI kappa^2/2 + n3 flat along the rod"});
    state_stability(rows, 4, s.stability);
    write_fig3_profile(step.out / ("fig3_theta0_" + label.str() + ".csv"), s, exact);
  }
}

// Fig. 9 and eq. (57): the tapered rod, where H varies as H' = -EI'(s) theta'^2 / 2.
void tapered(const Step& step) {
  const Solved s = solve_for_report(step.cases / "tapered.toml", {}, 201);
  const RodModel& model = s.problem->equations(s.solution.result.parameters)->model();
  std::ofstream csv(step.out / "fig9_tapered.csv");
  csv.precision(15);
  csv << "s,x,y,theta,kappa,EI,H,dH_ds_numeric,dH_ds_eq57\n";
  // H' by central differences of H at s +- h (error ~1e-8); eq. (57) from the state.
  const double h = 1e-4;
  double worst = 0.0;
  for (const auto& p : s.solution.profile) {
    double dH = NAN;
    if (p.s - h >= 0 && p.s + h <= model.length) {
      const auto pair = s.problem->sample(s.solution.result.x, {p.s - h, p.s + h});
      dH = (hamiltonian(model, pair[1]) - hamiltonian(model, pair[0])) / (2 * h);
    }
    const double eq57 = -0.5 * model.B[1].derivative(p.s) * p.u[1] * p.u[1];
    if (std::isfinite(dH)) worst = std::max(worst, std::abs(dH - eq57));
    csv << p.s << ',' << p.r.x() << ',' << p.r.y() << ',' << p.turn_angle << ',' << p.u[1] << ',' << model.B[1](p.s)
        << ',' << hamiltonian(model, p) << ',' << dH << ',' << eq57 << '\n';
  }
  const double scale = s.solution.invariants.H.scale;
  step.rows->push_back({"Fig. 9, eq. (57)", "max abs(H'(s) + EI'(s) theta'^2/2) / scale of H", {}, 0.0, worst, scale,
                        1e-7, "H' by central differences (h = 1e-4, error ~1e-8)"});
  step.rows->push_back({"Fig. 9", "H spread / scale (not invariant: explicit s)", {}, {},
                        s.solution.invariants.H.relative_spread(), 1.0, 0.0, "non-zero, as section 7.5 explains"});
  state_stability(step.rows, 2, s.stability);
}

// Section 5: the straight twisted rod and the heavy rod's field term.
void invariants(const Step& step) {
  auto* rows = step.rows;
  const Solved t = solve_for_report(step.cases / "twisted_clamped.toml", {{"phi", 6.0}, {"tension", 0.7}}, 101);
  const analytic::StraightTwistedRod exact{1.0, 1.0 / 1.3, 1.0, 6.0, 0.7};
  rows->push_back({"eq. (48)", "m3 of the straight twisted rod (C phi / L)", {}, exact.twisting_moment(),
                   t.solution.invariants.m3.mean, exact.twisting_moment(), 1e-10, ""});
  rows->push_back({"eq. (33)", "H of the straight twisted rod (m3^2/2C + T)", {}, exact.hamiltonian(),
                   t.solution.invariants.H.mean, exact.hamiltonian(), 1e-10, ""});
  state_stability(rows, 2, t.stability);
  const Solved g = solve_for_report(step.cases / "heavy_cantilever.toml", {}, 201);
  rows->push_back({"eq. (29) with W_ext", "H spread / scale, heavy cantilever", {}, 0.0, g.solution.invariants.H.spread,
                   g.solution.invariants.H.scale, 1e-9, "H includes -W_ext = -w y"});
  rows->back().stability = g.stability;
}

// Figs. 6-8: the sliding sleeve (eq. 55) and the arm scale (horizontal tangent at the load).
void sleeves(const Step& step) {
  auto* rows = step.rows;
  const Solved sleeve = solve_for_report(step.cases / "sleeve.toml", {}, 201);
  const auto& d = sleeve.solution.derived;
  const auto& parameters = sleeve.solution.result.parameters;
  const double P = parameters["P"], P_prime = parameters["P_prime"];
  const double kB = d.at("kappa_end");
  rows->push_back({"eq. (55)", "P + EI kappa_B^2 / 2 (= P')", {}, P_prime, P + 0.5 * kB * kB, P_prime, 1e-9,
                   "length outside the sleeve solved for: " + format_short(parameters["ell"])});
  rows->push_back({"Fig. 7", "H_out at the exit (= H_in = -P)", {}, -P, d.at("H_end"), P, 1e-9, ""});
  state_stability(rows, 2, sleeve.stability);
  const Solved arm = solve_for_report(step.cases / "arm_scale.toml", {}, 201);
  rows->push_back({"Fig. 8", "theta_C, tangent at the weight (horizontal)", 0.0, 0.0,
                   arm.solution.derived.at("theta_end"), 1.0, 1e-9, "H_A = 0 = H_C = -W sin(theta_C)"});
  rows->back().stability = arm.stability;
  for (const auto& [name, s] : {std::pair{"fig6_sleeve.csv", &sleeve}, std::pair{"fig8_arm_scale.csv", &arm}}) {
    std::ofstream csv(step.out / name);
    csv.precision(15);
    csv << "s,x,y\n";
    for (const auto& p : s->solution.profile) csv << p.s << ',' << p.r.x() << ',' << p.r.y() << '\n';
  }
}

}  // namespace kirchhoff::reproduce_steps

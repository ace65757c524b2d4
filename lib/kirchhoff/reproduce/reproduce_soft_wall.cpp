// `reproduce`'s soft wall of Fig. 12 a-d (reproduce_steps.hpp): the barrier b / (a - y) swept in
// b down to 1e-6 from a solution reached by continuation in the end shortening; H flat and h not
// (eq. 67), E_wall ~ b^(2/3), and the approach to the hard wall's values.
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <stdexcept>

#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

// The solutions at b = 1e-1 ... 1e-6, keyed by the exponent of b, and the problem at Delta = 0.026.
struct SoftWallSolutions {
  std::unique_ptr<ShootingProblem> problem;
  std::map<int, Solution> by_log_b;
};

// Continuation in Delta at b = 1e-4 from a small arch, then in log10 b up to -1 and down to -6.
SoftWallSolutions follow_soft_wall(const Step& step) {
  const Case c = load_case((step.cases / "soft_wall.toml").string(),
                           {{"log_b", -4.0}, {"Delta", 0.005}, {"P_guess", 40.0}, {"m_guess", 0.9}});
  SoftWallSolutions out{std::make_unique<ShootingProblem>(c.definition), {}};
  ShootingProblem& problem = *out.problem;
  ContinuationResult shortening = RodContinuation(problem, report_continuation("Delta", 0.026, 2.0, ReportPoints::Followed))
                                      .run(problem.initial_unknowns(c.start_guess));
  if (shortening.reason != StopReason::ReachedTarget) throw std::runtime_error("soft wall: continuation in Delta failed");
  problem.set_parameter("Delta", 0.026);
  auto record = [&](const ContinuationPoint& p) {
    ShootingProblem at = problem;
    at.set_parameter("log_b", p.parameter);
    ShootingResult r;
    r.x = p.x;
    r.parameters = at.parameters_at(p.x);
    out.by_log_b[static_cast<int>(std::lround(p.parameter))] =
        make_solution(at, r, 401, {"P", "E_wall", "gap", "ny_jump", "kappa_mid", "H", "h_spread"});
  };
  for (const std::vector<double>& targets : {std::vector<double>{-3, -2, -1}, std::vector<double>{-5, -6}}) {
    Eigen::VectorXd x = shortening.points.back().x;
    double from = -4.0;
    for (double target : targets) {
      problem.set_parameter("log_b", from);
      const ContinuationResult r =
          RodContinuation(problem, report_continuation("log_b", target, 0.5, ReportPoints::Followed)).run(x);
      if (r.reason != StopReason::ReachedTarget) throw std::runtime_error("soft wall: continuation in b failed");
      if (from == -4.0) record(r.points.front());
      record(r.points.back());
      x = r.points.back().x;
      from = target;
    }
  }
  return out;
}

// fig12_soft_wall.csv (one row per b) with H flat at each b as a row.
void soft_wall_rows(const Step& step, const SoftWallSolutions& soft) {
  std::ofstream csv(step.out / "fig12_soft_wall.csv");
  csv.precision(15);
  csv << "b,E_wall,gap,P,ny_jump,kappa_mid,H,h_spread,H_relative_spread\n";
  for (const auto& [lb, sol] : soft.by_log_b) {
    const auto& v = sol.derived;
    csv << std::pow(10.0, lb) << ',' << v.at("E_wall") << ',' << v.at("gap") << ',' << v.at("P") << ','
        << v.at("ny_jump") << ',' << v.at("kappa_mid") << ',' << v.at("H") << ',' << v.at("h_spread") << ','
        << sol.invariants.H.relative_spread() << '\n';
    step.rows->push_back({"Fig. 12 c-d, b = 1e" + std::to_string(lb),
                          "H spread / scale (eq. 67; h spreads " + format_short(v.at("h_spread")) + ")", {}, 0.0,
                          sol.invariants.H.spread, sol.invariants.H.scale, 1e-9, "H = h - W_ext flat, h is not"});
  }
}

// Profiles of Fig. 12 c-d: H (invariant) and h = H + W_ext (not) along the rod.
void soft_wall_profiles(const Step& step, const SoftWallSolutions& soft) {
  for (int lb : {-1, -4}) {
    const Solution& sol = soft.by_log_b.at(lb);
    ShootingProblem at = *soft.problem;
    at.set_parameter("log_b", lb);
    const RodModel& model = at.equations(sol.result.parameters)->model();
    std::ofstream profile(step.out / ("fig12_soft_wall_b1e" + std::to_string(lb) + ".csv"));
    profile.precision(15);
    profile << "s,x,y,H,h\n";
    for (const auto& p : sol.profile)
      profile << p.s << ',' << p.r.x() << ',' << p.r.y() << ',' << hamiltonian(model, p) << ','
              << hamiltonian_without_field(model, p) << '\n';
  }
}

// Least-squares slope of log E_wall against log b over the three smallest b (the asymptotic regime).
double wall_energy_exponent(const std::map<int, Solution>& by_log_b) {
  std::vector<double> xs, ys;
  for (const auto& [lb, sol] : by_log_b)
    if (lb <= -4) {
      xs.push_back(lb * std::log(10.0));
      ys.push_back(std::log(sol.derived.at("E_wall")));
    }
  const double xm = std::accumulate(xs.begin(), xs.end(), 0.0) / xs.size();
  const double ym = std::accumulate(ys.begin(), ys.end(), 0.0) / ys.size();
  double sxy = 0.0, sxx = 0.0;
  for (size_t i = 0; i < xs.size(); ++i) {
    sxy += (xs[i] - xm) * (ys[i] - ym);
    sxx += (xs[i] - xm) * (xs[i] - xm);
  }
  return sxy / sxx;
}

}  // namespace

void soft_wall(const Step& step, const HardWall& hard) {
  const SoftWallSolutions soft = follow_soft_wall(step);
  soft_wall_rows(step, soft);
  soft_wall_profiles(step, soft);
  auto* rows = step.rows;
  rows->push_back({"Fig. 12 b", "exponent of E_wall ~ b^e, fitted on b = 1e-4..1e-6", {}, 2.0 / 3.0,
                   wall_energy_exponent(soft.by_log_b), 2.0 / 3.0, 0.02, "scaling argument of section 7.7"});
  const auto& finest = soft.by_log_b.begin()->second.derived;
  rows->push_back({"Fig. 12, b = 1e-6", "H (tends to the hard wall's " + format_short(hard.H) + ")", -73.7, {},
                   finest.at("H"), 1.0, 0.0, "soft wall, converging as b -> 0"});
  rows->push_back({"Fig. 12, b = 1e-6", "n_y jump (tends to F_c = " + format_short(hard.contact_force) + ", eq. 66)",
                   18.1, {}, finest.at("ny_jump"), 1.0, 0.0, ""});
  rows->push_back({"Fig. 12, b = 1e-6", "kappa at mid-span (tends to " + format_short(hard.kappa_c) + ")", -1.54, {},
                   finest.at("kappa_mid"), 1.0, 0.0, ""});
}

}  // namespace kirchhoff::reproduce_steps

// `reproduce`'s hard wall of Fig. 12 (reproduce_steps.hpp): the symmetric half rod against the
// elliptic solution, the same found by complementarity on the whole rod, and Ipopt on the
// discretised energy with its Richardson extrapolation.
#include <cmath>
#include <fstream>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/discrete_elastica.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

// wall.toml: the contact found (not imposed) from the free arch; its whole-rod stability (the
// sliding point contact; wall_symmetric's half rod is not the whole rod's problem) is stated on
// the hard-wall rows.
void complementarity(const Step& step, const analytic::WallContactElastica& exact) {
  const Case general = load_case((step.cases / "wall.toml").string());
  const ContactSolveResult contact = solve_with_contacts(general.definition, general.start_guess);
  const ShootingProblem p(contact.definition);
  const Solution sol = make_solution(p, contact.result, 101, {"P", "contact_force", "contact_s"});
  step.rows->push_back({"Fig. 12, hard wall (wall.toml)", "contact force, active set from the free arch", 18.1,
                        exact.contact_force, sol.derived.at("contact_force"), exact.contact_force, 1e-8,
                        "contact found at s = " + format_short(sol.derived.at("contact_s"))});
  state_stability(step.rows, 4, describe(analyse_stability(p, contact.result.x)));
}

// Ipopt on the discretised energy: its error falls as 1/N^2 and its Richardson extrapolation
// meets the others.
void discretised(const Step& step, const analytic::WallContactElastica& exact) {
  const std::vector<Obstacle> plane{Obstacle::plane(Vec3(0, 0.1, 0), Vec3(0, -1, 0), "wall")};
  // A solve that fails its own KKT check gives NaN, which fails its rows (never a wrong P).
  auto ipopt_P = [&](int N) {
    const DiscreteElasticaResult d = solve_discrete_clamped_elastica(1.0, 1.0, 0.026, plane, N);
    return d.converged ? d.P : NAN;
  };
  const double P200 = ipopt_P(200), P400 = ipopt_P(400);
  step.rows->push_back({"Fig. 12, hard wall, Ipopt", "error ratio in P, N = 200 -> 400 (second order: 4)", {}, 4.0,
                        (P200 - exact.P) / (P400 - exact.P), 4.0, 0.05, "midpoint-rule energy, exact Hessian"});
  step.rows->push_back({"Fig. 12, hard wall, Ipopt", "P, Richardson-extrapolated from N = 200, 400", {}, exact.P,
                        (4.0 * P400 - P200) / 3.0, exact.P, 1e-6, "h^4 remainder ~3e-8"});
}

}  // namespace

// Hard wall by the symmetric half rod (single point contact at mid-span), against the
// elliptic-function solution of the same half rod (no ODE solver).
HardWall hard_wall(const Step& step) {
  const Solved hard = solve_for_report(step.cases / "wall_symmetric.toml", {}, 201);
  const auto& d = hard.solution.derived;
  const HardWall values{d.at("H"), -2.0 * d.at("n_y"), d.at("kappa_end")};
  const auto exact = analytic::wall_contact_elastica(1.0, 1.0, 0.026, 0.1);
  const std::string sensitivity =
      "shooting vs Jacobi elliptic functions; dH/dDelta = -3.2e4, so the paper's -73.7 is Delta = 0.025994";
  auto* rows = step.rows;
  rows->push_back({"Fig. 12, hard wall", "H", -73.7, exact.H, values.H, std::abs(exact.H), 1e-8, sensitivity});
  rows->push_back({"Fig. 12, hard wall", "kappa_c (curvature at the contact)", -1.54, exact.kappa_c, values.kappa_c,
                   std::abs(exact.kappa_c), 1e-8, "rounds to the paper's value"});
  rows->push_back({"Fig. 12, hard wall", "F_c = n_y jump at the contact (eq. 63)", 18.1, exact.contact_force,
                   values.contact_force, exact.contact_force, 1e-8,
                   "dF_c/dDelta = 1.6e4: 18.1 is Delta = 0.025994 as well"});
  complementarity(step, exact);
  discretised(step, exact);
  std::ofstream profile(step.out / "fig12_hard_wall_half.csv");
  profile.precision(15);
  profile << "s,x,y\n";
  for (const auto& p : hard.solution.profile) profile << p.s << ',' << p.r.x() << ',' << p.r.y() << '\n';
  return values;
}

void wall(const Step& step) { soft_wall(step, hard_wall(step)); }

}  // namespace kirchhoff::reproduce_steps

// Every shipped case's default solve (cases/*.toml, no overrides, as `kirchhoff solve CASE` does
// it) gives the equilibrium its description names. Each case is checked against a quantity that
// identifies that equilibrium and is known independently of the shooting solution: a closed form
// (analytic.hpp), an equation of the reference paper, or the qualitative identifier the
// description states (the contact set, the side of the deflection, the mode's shape). A new case
// without a check here fails EveryCaseHasACheck.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <filesystem>
#include <functional>
#include <map>
#include <set>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;
const double kSupportSlope = -35.0 * kPi / 180.0;  // indenter.toml and wrapped_indenter.toml

struct Shipped {
  Case c;
  DefinitionSolve solved;
  Solution sol;
  double derived(const std::string& name) const { return sol.derived.at(name); }
};

// The CLI's default solve: the case's guess, the active-set loop when it has obstacles.
Shipped solve_shipped(const std::string& name, const ParameterOverrides& overrides = {}) {
  Shipped out;
  out.c = load_case(testing::case_path(name), overrides);
  out.solved = solve_definition(out.c.definition, out.c.start_guess);
  EXPECT_TRUE(out.solved.result.summary.converged()) << name << ": " << out.solved.result.summary.brief_report();
  out.sol = make_solution(*out.solved.problem, out.solved.result, out.c.samples, out.c.derived);
  EXPECT_TRUE(out.sol.result.summary.converged()) << name << ": " << out.sol.result.summary.brief_report();
  return out;
}

// y(s) = y(L - s) on the sampled profile (odd sample count: the samples pair up exactly).
double asymmetry(const std::vector<RodPoint>& profile) {
  double worst = 0.0;
  for (size_t i = 0; i < profile.size(); ++i)
    worst = std::max(worst, std::abs(profile[i].r.y() - profile[profile.size() - 1 - i].r.y()));
  return worst;
}

// Where y is largest on the profile.
const RodPoint& highest(const std::vector<RodPoint>& profile) {
  return *std::max_element(profile.begin(), profile.end(),
                           [](const RodPoint& a, const RodPoint& b) { return a.r.y() < b.r.y(); });
}

// The compressive end load of a planar rod, P = -n_x (n is constant along a rod without a field).
double compression(const Shipped& s) { return -s.sol.profile.front().n.x(); }

// Residual tolerances of the cases are 1e-10..1e-12 on max |F|; the quantities below are smooth
// functions of the unknowns with derivatives O(1..1e2), so 1e-8 relative leaves a margin of 100 or
// more, and a wrong equilibrium differs at the 1e-1 level.
constexpr double kClosedForm = 1e-8;

void arm_scale(const Shipped& s) {
  // Fig. 8: H = 0 inside the sleeve and kappa_C = 0 give theta_C = 0 (horizontal tangent at C).
  EXPECT_NEAR(s.derived("theta_end"), 0.0, 1e-9);
  EXPECT_NEAR(s.derived("H_start"), 0.0, 1e-9);
  EXPECT_GT(s.derived("tip_x"), 0.0);  // the arm leaves the sleeve forwards
}

void cavity(const Shipped& s) {
  // At Delta = 0.005 the free symmetric arch, touching neither wall.
  EXPECT_EQ(s.derived("contact_count"), 0.0);
  EXPECT_GT(s.derived("min_gap"), 0.0);
  const double P = analytic::clamped_clamped_elastica_load(1.0, 1.0, 1.0 - 0.005);
  EXPECT_NEAR(s.derived("P") / P, 1.0, kClosedForm);
  EXPECT_GT(highest(s.sol.profile).r.y(), 0.0);  // towards the upper wall
}

void clamped_clamped(const Shipped& s) {
  // s_mode = 0: the symmetric first mode, P = 16 K(k)^2 EI / L^2 with D/L = 2E/K - 1.
  EXPECT_NEAR(compression(s) / analytic::clamped_clamped_elastica_load(1.0, 1.0, 0.9), 1.0, kClosedForm);
  EXPECT_LT(asymmetry(s.sol.profile), 1e-8);
  EXPECT_GT(s.derived("y_max"), 0.0);  // side = +1: up
}

void euler_column(const Shipped& s) {
  // The buckled Elastica (theta_guess = 1), not the straight column: its load is Love's for the
  // end slope it converged to.
  const double theta0 = s.derived("theta0");
  ASSERT_GT(theta0, 0.1);
  const analytic::PinnedElastica love{1.0, 1.0, theta0};
  EXPECT_NEAR(love.load() / 12.0, 1.0, kClosedForm);
  EXPECT_NEAR(s.derived("y_max") / love.y_max(), 1.0, kClosedForm);
}

void heavy_cantilever(const Shipped& s) {
  // Sagging under its weight: the tip below the clamp, and the clamp's moment is the weight's
  // moment about it, w int_0^L x ds (trapezoid rule on the profile: error ~ h^2 / 12 ~ 1e-6).
  EXPECT_LT(s.derived("tip_y"), 0.0);
  const auto& p = s.sol.profile;
  double moment = 0.0;
  for (size_t i = 1; i < p.size(); ++i) moment += 0.5 * (p[i].r.x() + p[i - 1].r.x()) * (p[i].s - p[i - 1].s);
  moment *= 3.0;  // w
  EXPECT_NEAR(std::abs(s.derived("m_start")) / moment, 1.0, 1e-5);
}

void michell_ring(const Shipped& s) {
  // tau = 1.5 on the unit ring: the twisted circle (closed, m3 = C tau, |m| = sqrt(B^2 + (C tau)^2)),
  // below Michell's twist sqrt(3) B / (C R) = 2.2517, so the stable ring the description names.
  const double C = 0.769230769230769, tau = 1.5;
  EXPECT_NEAR(s.derived("end_to_end"), 0.0, 1e-10);
  EXPECT_NEAR(s.derived("m_start"), std::hypot(1.0, C * tau), 1e-10);
  EXPECT_NEAR(s.sol.invariants.m3.mean, C * tau, 1e-10);
  EXPECT_LT(tau, analytic::michell_ring_critical_twist(1.0, C, 1.0));
}

void indenter(const Shipped& s) {
  const auto exact = analytic::three_point_bending(1.0, 1.0, kSupportSlope);
  ASSERT_EQ(s.sol.contacts.size(), 1u);
  EXPECT_FALSE(s.sol.contacts[0].extended);
  EXPECT_NEAR(s.sol.contacts[0].s, 0.5, 1e-9);
  EXPECT_NEAR(s.derived("contact_force") / exact.force, 1.0, kClosedForm);
}

void plectoneme(const Shipped& s) {
  // turns = 0: the planar clamped-clamped Elastica with its clamps 0.5 L apart, T_ext = -P.
  EXPECT_NEAR(-s.derived("T_ext") / analytic::clamped_clamped_elastica_load(1.0, 1.0, 0.5), 1.0, 1e-7);
  EXPECT_NEAR(s.derived("m3"), 0.0, 1e-9);
  EXPECT_GT(s.derived("self_distance"), 1.0 / 100.0);  // the strands apart (2R = L/100)
}

void reissner(const Shipped& s) {
  // The equilibrium the description names is the loaded rod on the branch of its natural shape:
  // followed in F from F = 0 the branch reaches the default solve's tip.
  Case start = load_case(testing::case_path("reissner.toml"), {{"F", 0.0}});
  ShootingProblem problem(start.definition);
  const ShootingResult at_zero = solve(problem, problem.initial_unknowns(start.start_guess));
  ASSERT_TRUE(at_zero.summary.converged());
  RodContinuationOptions o;
  o.parameter = "F";
  o.target = 2.0;
  o.compute_invariants = false;
  o.detect_branch_points = false;
  const ContinuationResult r = RodContinuation(problem, o).run(at_zero.x);
  ASSERT_EQ(r.reason, StopReason::ReachedTarget) << r.message;
  ShootingProblem at_two = problem;
  at_two.set_parameter("F", 2.0);
  const Vec3 tip = at_two.sample(r.points.back().x, {1.0}).front().r;
  EXPECT_LT((tip - s.sol.profile.back().r).norm(), 1e-8);
  EXPECT_LT(s.sol.invariants.H.relative_spread(), 1e-9);  // eq. (30c)
}

void shallow_arch(const Shipped& s) {
  // w = 0: the unloaded natural arc of curvature -1 between its chord's ends.
  EXPECT_NEAR(s.derived("y_max"), 1.0 - std::cos(0.5), 1e-10);
  EXPECT_NEAR(s.derived("tip_x"), 2.0 * std::sin(0.5), 1e-10);
  EXPECT_NEAR(s.derived("n_x"), 0.0, 1e-9);
}

void simply_supported(const Shipped& s) {
  // Fig. 3 at theta0 = 1: Love's Elastica, and eq. (54) for y_M and kappa_M.
  const analytic::PinnedElastica love{1.0, 1.0, 1.0};
  EXPECT_NEAR(s.derived("P") / love.load(), 1.0, kClosedForm);
  EXPECT_NEAR(s.derived("y_max") / analytic::eq54_y_max(love.load(), 1.0, 1.0), 1.0, kClosedForm);
  EXPECT_NEAR(s.derived("kappa_max") / analytic::eq54_kappa_max(love.load(), 1.0, 1.0), 1.0, kClosedForm);
}

void sleeve(const Shipped& s) {
  // Eq. (55): P' = P + EI kappa_B^2 / 2, so |kappa_B| = sqrt(2 (30 - 10)); H = -P throughout.
  EXPECT_NEAR(std::abs(s.derived("kappa_end")), std::sqrt(40.0), 1e-8);
  EXPECT_NEAR(s.derived("H_start"), -10.0, 1e-8);
  EXPECT_GT(s.derived("y_max"), 0.0);
}

void soft_wall(const Shipped& s) {
  // Fig. 12c (b = 0.1): the symmetric single arch with its crest at mid-span below the wall.
  EXPECT_LT(asymmetry(s.sol.profile), 1e-8);
  const RodPoint& top = highest(s.sol.profile);
  EXPECT_NEAR(top.s, 0.5, 1e-12);
  EXPECT_LT(s.derived("kappa_mid"), 0.0);
  EXPECT_GT(s.derived("gap"), 0.0);
  EXPECT_GT(s.derived("h_spread"), 1e-2);  // h of eq. (67) is not invariant, H is
  EXPECT_LT(s.sol.invariants.H.relative_spread(), 1e-9);
  // It is Fig. 12's branch: followed to b = 1e-6 it closes in on the hard-wall solution, whose
  // contact force the elliptic solution gives; the remaining gap is O(b^(1/3)) (eqs. 66, 71a).
  ShootingProblem problem(*s.solved.problem);
  RodContinuationOptions o;
  o.parameter = "log_b";
  o.target = -6.0;
  o.max_step = 0.5;
  o.compute_invariants = false;
  o.detect_branch_points = false;
  const ContinuationResult r = RodContinuation(problem, o).run(s.sol.result.x);
  ASSERT_EQ(r.reason, StopReason::ReachedTarget) << r.message;
  problem.set_parameter("log_b", -6.0);
  ShootingResult end;
  end.x = r.points.back().x;
  end.parameters = problem.parameters_at(end.x);
  const Solution near_hard = make_solution(problem, end, 401, {"ny_jump"});
  const double Fc = analytic::wall_contact_elastica(1.0, 1.0, 0.026, 0.1).contact_force;
  EXPECT_NEAR(near_hard.derived.at("ny_jump") / Fc, 1.0, 0.02);
}

void tapered(const Shipped& s) {
  // Fig. 9: one half-wave above the chord, its load between those of the uniform rods of
  // stiffness EI(0) = 1 and EI(L) = 2 at the same slope; H'(s) = -EI'(s) theta'^2 / 2 (eq. 57),
  // integrated along the profile (trapezoid, error ~1e-6 at 401 samples).
  const double P = s.derived("P"), P1 = analytic::PinnedElastica{1.0, 1.0, 1.0}.load();
  EXPECT_GT(P, P1);
  EXPECT_LT(P, 2.0 * P1);
  const auto& p = s.sol.profile;
  for (size_t i = 1; i + 1 < p.size(); ++i) EXPECT_GT(p[i].r.y(), 0.0) << p[i].s;
  double change = 0.0;  // int -EI' theta'^2 / 2 with EI' = 1
  for (size_t i = 1; i < p.size(); ++i)
    change -= 0.25 * (p[i].u.y() * p[i].u.y() + p[i - 1].u.y() * p[i - 1].u.y()) * (p[i].s - p[i - 1].s);
  const RodModel& model = s.solved.problem->equations(s.sol.result.parameters)->model();
  EXPECT_NEAR(hamiltonian(model, p.back()) - hamiltonian(model, p.front()), change, 1e-4 * std::abs(change));
}

void tapered_column(const Shipped& s) {
  // P = 1 is below the tapered column's first buckling load (above pi^2 EI0 / L^2 = 9.87): the
  // straight column.
  EXPECT_EQ(s.derived("y_max"), 0.0);
  EXPECT_EQ(s.derived("theta0"), 0.0);
}

void twisted_clamped(const Shipped& s) {
  // phi = 6 without tension: the straight twisted rod, m3 = C phi / L, below the clamped rod's
  // Greenhill moment (so the straight rod is the stable equilibrium the description names first).
  const analytic::StraightTwistedRod straight{1.0, 0.769230769230769, 1.0, 6.0, 0.0};
  EXPECT_NEAR(s.derived("M"), straight.twisting_moment(), 1e-9);
  EXPECT_NEAR(s.derived("end_to_end"), 1.0, 1e-12);
  EXPECT_LT(straight.twisting_moment(), analytic::clamped_twisted_critical_moment(1.0, 0.0, 1.0));
}

void twisted_ribbon_pole(const Shipped& s) {
  // One point contact with the pole, found from the contact-free guess, pushing (force > 0),
  // and H the same on both sides of it (section 6.3).
  ASSERT_EQ(s.sol.contacts.size(), 1u);
  const PointContact& c = s.sol.contacts[0];
  EXPECT_FALSE(c.extended);
  EXPECT_GT(c.force, 0.0);
  EXPECT_GT(c.s, 0.0);
  EXPECT_LT(c.s, 1.0);
  EXPECT_NEAR(s.derived("min_gap"), 0.0, 1e-9);
  const auto [before, after] = testing::hamiltonian_across(*s.solved.problem, s.sol.result.x, c.s);
  EXPECT_NEAR(before, after, 1e-7 * std::abs(before));
}

void wall(const Shipped& s) {
  // Fig. 12, hard wall: one point contact at mid-span with the elliptic solution's force.
  const auto exact = analytic::wall_contact_elastica(1.0, 1.0, 0.026, 0.1);
  ASSERT_EQ(s.sol.contacts.size(), 1u);
  EXPECT_FALSE(s.sol.contacts[0].extended);
  EXPECT_NEAR(s.sol.contacts[0].s, 0.5, 1e-9);
  EXPECT_NEAR(s.derived("contact_force") / exact.contact_force, 1.0, kClosedForm);
  EXPECT_NEAR(s.derived("H") / exact.H, 1.0, kClosedForm);
}

void wall_symmetric(const Shipped& s) {
  const auto exact = analytic::wall_contact_elastica(1.0, 1.0, 0.026, 0.1);
  EXPECT_NEAR(-2.0 * s.derived("n_y") / exact.contact_force, 1.0, kClosedForm);
  EXPECT_NEAR(s.derived("kappa_end") / exact.kappa_c, 1.0, kClosedForm);
}

void wrapped_indenter(const Shipped& s) {
  const auto exact = analytic::three_point_bending_wrapped(1.0, 1.0, 0.5, kSupportSlope);
  ASSERT_EQ(s.sol.contacts.size(), 1u);
  const PointContact& wrap = s.sol.contacts[0];
  EXPECT_TRUE(wrap.extended);
  EXPECT_NEAR(wrap.s, exact.contact_start, 1e-9);
  EXPECT_NEAR(wrap.s_end, 1.0 - exact.contact_start, 1e-9);
  EXPECT_NEAR(wrap.force / exact.edge_force, 1.0, kClosedForm);
  EXPECT_NEAR(s.derived("min_wrap_tension") / exact.tension, 1.0, kClosedForm);
}

const std::map<std::string, std::function<void(const Shipped&)>>& checks() {
  static const std::map<std::string, std::function<void(const Shipped&)>> table{
      {"arm_scale.toml", arm_scale},
      {"cavity.toml", cavity},
      {"clamped_clamped.toml", clamped_clamped},
      {"euler_column.toml", euler_column},
      {"heavy_cantilever.toml", heavy_cantilever},
      {"indenter.toml", indenter},
      {"michell_ring.toml", michell_ring},
      {"plectoneme.toml", plectoneme},
      {"reissner.toml", reissner},
      {"shallow_arch.toml", shallow_arch},
      {"simply_supported.toml", simply_supported},
      {"sleeve.toml", sleeve},
      {"soft_wall.toml", soft_wall},
      {"tapered.toml", tapered},
      {"tapered_column.toml", tapered_column},
      {"twisted_clamped.toml", twisted_clamped},
      {"twisted_ribbon_pole.toml", twisted_ribbon_pole},
      {"wall.toml", wall},
      {"wall_symmetric.toml", wall_symmetric},
      {"wrapped_indenter.toml", wrapped_indenter},
  };
  return table;
}

TEST(ShippedCases, EveryCaseHasACheck) {
  std::set<std::string> shipped;
  for (const auto& entry : fs::directory_iterator(KIRCHHOFF_CASES_DIR))
    if (entry.path().extension() == ".toml") shipped.insert(entry.path().filename().string());
  for (const auto& name : shipped) EXPECT_TRUE(checks().count(name)) << name << " has no check in this file";
  for (const auto& [name, check] : checks()) EXPECT_TRUE(shipped.count(name)) << name << " is not shipped";
}

class DefaultSolve : public ::testing::TestWithParam<std::string> {};

TEST_P(DefaultSolve, GivesTheEquilibriumItsDescriptionNames) {
  const Shipped s = solve_shipped(GetParam());
  ASSERT_TRUE(s.sol.result.summary.converged());
  checks().at(GetParam())(s);
}

std::vector<std::string> case_names() {
  std::vector<std::string> out;
  for (const auto& entry : checks()) out.push_back(entry.first);
  return out;
}

INSTANTIATE_TEST_SUITE_P(Cases, DefaultSolve, ::testing::ValuesIn(case_names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param.substr(0, info.param.size() - 5);  // without ".toml"
                         });

// The CLI on a file (no --set: the default solve), its stdout and stderr.
struct CliOutput {
  int status = 0;
  std::string out, err;
};
CliOutput run_cli(const std::string& args) {
  const std::string out = testing::scratch_path("shipped_cli.out"), err = testing::scratch_path("shipped_cli.err");
  const int status = std::system((std::string(KIRCHHOFF_CLI) + " " + args + " > '" + out + "' 2> '" + err + "'").c_str());
  const auto read = [](const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  return {status, read(out), read(err)};
}

// wall.toml at Delta = 0.032, written as the file's own value so that `solve` runs the active-set
// loop from the free arch: it settles on two point contacts with the rod flat between them, which
// solve reports as one extended contact, in JSON and in text, as `continue` does.
TEST(SolveCli, FlatContactFoundAsTwoPointContactsIsReportedAsExtended) {
  std::ifstream in(testing::case_path("wall.toml"));
  std::string text(std::istreambuf_iterator<char>(in), {});
  const std::string from = "Delta = 0.026";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "Delta = 0.032");
  const std::string path = testing::scratch_path("wall_flat.toml");
  std::ofstream(path) << text;
  const CliOutput json = run_cli("solve '" + path + "' --json");
  ASSERT_EQ(json.status, 0) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  ASSERT_EQ(j["contacts"].size(), 1u) << json.out;
  EXPECT_TRUE(j["contacts"][0]["extended"].get<bool>());
  EXPECT_GT(j["contacts"][0]["s_end"].get<double>() - j["contacts"][0]["s"].get<double>(), 0.03);
  EXPECT_NEAR(j["derived"]["contact_length"].get<double>(),
              j["contacts"][0]["s_end"].get<double>() - j["contacts"][0]["s"].get<double>(), 1e-12);
  const CliOutput text_run = run_cli("solve '" + path + "'");
  ASSERT_EQ(text_run.status, 0) << text_run.err;
  EXPECT_NE(text_run.out.find("(wall) over ["), std::string::npos) << text_run.out;
  EXPECT_NE(text_run.err.find("one extended contact over ["), std::string::npos) << text_run.err;
}

// wrapped_indenter.toml states its wrap over [0.45, 0.55]; it converges over the closed form's
// interval, and solve says so on stderr and in JSON.
TEST(SolveCli, StatedContactThatMovedSaysWhere) {
  const CliOutput json = run_cli("solve '" + testing::case_path("wrapped_indenter.toml") + "' --json");
  ASSERT_EQ(json.status, 0) << json.err;
  const auto stated = nlohmann::json::parse(json.out)["stated_contacts"];
  ASSERT_EQ(stated.size(), 1u);
  EXPECT_TRUE(stated[0]["moved"].get<bool>());
  EXPECT_EQ(stated[0]["stated_s"].get<double>(), 0.45);
  EXPECT_NEAR(stated[0]["s"].get<double>(),
              analytic::three_point_bending_wrapped(1.0, 1.0, 0.5, kSupportSlope).contact_start, 1e-9);
  const std::string expected = "stated over [0.45, 0.55] converged over [0.377472, 0.622528]";
  EXPECT_NE(stated[0]["message"].get<std::string>().find(expected), std::string::npos) << stated[0]["message"];
  const CliOutput text = run_cli("solve '" + testing::case_path("wrapped_indenter.toml") + "'");
  EXPECT_NE(text.err.find(expected), std::string::npos) << text.err;
}

}  // namespace
}  // namespace kirchhoff

// The index of equilibria whose sliding length is a degree of freedom (stability_free_length.hpp):
// the reduced energy's curvature S against energies computed along the fixed-length equilibria
// (which the method does not use), the sign against a scan of that energy, the fixed-length index
// against the discretised energy, and a case with a stable and an unstable sliding equilibrium.
#include <cmath>
#include <memory>
#include <tuple>

#include "kirchhoff/analysis/detail/stability_free_length.hpp"
#include "kirchhoff/analysis/discrete_stability.hpp"
#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/jobs/equilibria.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

struct Sliding {
  Case c;
  std::unique_ptr<ShootingProblem> problem;
  Eigen::VectorXd x;
  double inside_H = 0.0;  // H of the straight part inside the sleeve (the case's extra_hamiltonian)
  // How far in ell / ell the fixed-length family is followed: sleeve.toml's has a fold in ell at
  // 1.008 ell (the outside part's own buckling family turns back there), the others are smooth
  // over several per cent.
  double reach = 2e-2;
};

Sliding solve_sliding(Case c, double inside_H) {
  Sliding s;
  s.c = std::move(c);
  s.inside_H = inside_H;
  s.problem = std::make_unique<ShootingProblem>(s.c.definition);
  const ShootingResult r = solve(*s.problem, s.problem->initial_unknowns(s.c.start_guess));
  EXPECT_TRUE(r.summary.converged()) << r.summary.brief_report();
  s.x = r.x;
  return s;
}

Sliding sleeve() {
  const Case c = load_case(testing::case_path("sleeve.toml"));
  Sliding s = solve_sliding(c, -c.definition.parameters["P"]);
  s.reach = 2e-3;
  return s;
}
Sliding arm_scale(const ParameterOverrides& overrides = {}) {
  return solve_sliding(load_case(testing::case_path("arm_scale.toml"), overrides), 0.0);
}
Sliding sling(const ParameterOverrides& overrides) {
  return solve_sliding(load_case_text(testing::kTwoSleeveRodCase, testing::case_path("sling.toml"), overrides), 0.0);
}

double length_of(const Sliding& s) { return s.problem->parameters_at(s.x).get("ell"); }

// The equilibria with the length held: E*(ell), the whole energy (the part inside the sleeve,
// straight under H_inside, adds H_inside ell up to a constant: its end load's work as the rod
// slides), and H at the exit, from Newton solves marched along the family from the equilibrium
// in steps of at most 0.5 % of ell, each started from the linear extrapolation of the last two
// (the sleeve's rod is 6 % above its critical length: a 1 % jump from the equilibrium's unknowns
// loses Newton).
class FixedFamily {
 public:
  explicit FixedFamily(const Sliding& s) : inside_H_(s.inside_H), step_(std::min(5e-3, s.reach / 4)) {
    name_ = rod_changing_unknown(*s.problem);
    fixed_ = fixed_length_problem(*s.problem, s.x, name_);
    ell0_ = length_of(s);
    exit_at_start_ = s.problem->definition().start.extra_count() > 0;
  }
  struct Point {
    double energy, exit_H;
  };
  Point at(double ell) const {
    const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(ell - ell0_) / (step_ * ell0_))));
    Eigen::VectorXd previous = fixed_.x, current = fixed_.x;
    Point point{0.0, 0.0};
    for (int k = 0; k <= steps; ++k) {
      const double l = ell0_ + (ell - ell0_) * k / steps;
      const Eigen::VectorXd guess = k < 2 ? current : Eigen::VectorXd(2 * current - previous);
      const Eigen::VectorXd solved = solve_at(l, guess, k == steps ? &point : nullptr);
      previous = current;
      current = solved;
    }
    return point;
  }

 private:
  Eigen::VectorXd solve_at(double ell, const Eigen::VectorXd& guess, Point* point) const {
    ProblemDefinition d = fixed_.problem->definition();
    d.parameters.set(name_, ell);
    // Newton ends well below this (its last step is quadratic); the energies' second differences
    // need the equilibria to ~1e-12.
    d.options.newton.residual_tolerance = 1e-11;
    const ShootingProblem problem(d);
    const ShootingResult r = solve(problem, guess);
    EXPECT_TRUE(r.summary.converged()) << "ell " << ell << ": " << r.summary.brief_report();
    if (point) {
      const double L = problem.length(problem.parameters_at(r.x));
      const RodPoint exit = problem.sample(r.x, {exit_at_start_ ? 0.0 : L}).front();
      const auto equations = problem.equations(problem.parameters_at(r.x));
      *point = {total_potential_energy(problem, r.x) + inside_H_ * ell, hamiltonian(equations->model(), exit)};
    }
    return r.x;
  }

  FixedLengthProblem fixed_;
  std::string name_;
  double inside_H_ = 0.0, step_ = 0.0, ell0_ = 0.0;
  bool exit_at_start_ = false;
};

// The cases the tests run: the two shipped ones and the sling's two coexisting equilibria.
std::vector<Sliding> cases() {
  std::vector<Sliding> out;
  out.push_back(sleeve());
  out.push_back(arm_scale());
  out.push_back(sling({{"ell", 1.2}}));                     // stable
  out.push_back(sling({{"ell", 3.0}, {"m_guess", 4.0}}));   // index 1 from S
  return out;
}

TEST(FreeLength, ShippedSleeveAndArmScaleAreMaximaOfTheEnergyInTheirLength) {
  for (const Sliding& s : {sleeve(), arm_scale()}) {
    const FreeLengthStability f = analyse_free_length(*s.problem, s.x);
    ASSERT_TRUE(f.report.defined()) << f.report.reason;
    EXPECT_EQ(f.parameter, "ell");
    EXPECT_EQ(f.report.method, "conjugate_points+reduced_energy");
    EXPECT_EQ(*f.fixed_length.index, 0);  // the outside part is stable at its length
    EXPECT_LT(f.reduced_curvature, 0.0);
    EXPECT_EQ(*f.report.index, 1);        // the rod slides in or out
    EXPECT_EQ(f.report.zero_modes, 0);
    EXPECT_EQ(analyse_free_length_stability(*s.problem, s.x).index, f.report.index);
  }
}

TEST(FreeLength, SlingHasAStableAndAnUnstableEquilibriumAtTheSameSleeves) {
  const Sliding stable = sling({{"ell", 1.2}}), unstable = sling({{"ell", 3.0}, {"m_guess", 4.0}});
  // Two distinct equilibria (measured ell = 1.1132 and 1.9572).
  ASSERT_GT(length_of(unstable) - length_of(stable), 0.5);
  const FreeLengthStability a = analyse_free_length(*stable.problem, stable.x);
  const FreeLengthStability b = analyse_free_length(*unstable.problem, unstable.x);
  ASSERT_TRUE(a.report.defined() && b.report.defined()) << a.report.reason << b.report.reason;
  EXPECT_EQ(*a.fixed_length.index, 0);
  EXPECT_EQ(*b.fixed_length.index, 0);
  EXPECT_GT(a.reduced_curvature, 0.0);
  EXPECT_LT(b.reduced_curvature, 0.0);
  EXPECT_EQ(*a.report.index, 0);
  EXPECT_EQ(*b.report.index, 1);
}

// The two equilibria of the two-sleeve rod meet at a fold as the first sleeve turns: `kirchhoff
// continue` of testing::kTwoSleeveRodCase in theta1 (theta2 = 1) locates it at theta1 =
// 1.96768195, ell = 2.10198316 (its fold detector: the parameter component of the branch's tangent changing sign,
// bisected - the whole problem's Jacobian, not this analysis). Just before it (theta1 = 1.96768)
// the two equilibria are stable and index 1, with S of opposite signs and small (2e-3 of its
// scale, against 1 away from the fold), and S interpolated linearly between them vanishes at the
// fold's length to 2e-5 (the interpolation's error, ~ the square of their distance 3.4e-3).
TEST(FreeLength, SlingExchangesStabilityAtTheFoldInTheSleeveAngle) {
  const Sliding before = sling({{"theta1", 1.96768}, {"ell", 2.0}});
  const Sliding after = sling({{"theta1", 1.96768}, {"ell", 2.09}});
  const double la = length_of(before), lb = length_of(after);
  ASSERT_GT(lb - la, 1e-3);  // two equilibria (measured 2.100262 and 2.103705)
  const FreeLengthStability a = analyse_free_length(*before.problem, before.x);
  const FreeLengthStability b = analyse_free_length(*after.problem, after.x);
  ASSERT_TRUE(a.report.defined() && b.report.defined()) << a.report.reason << b.report.reason;
  EXPECT_EQ(*a.report.index, 0);
  EXPECT_EQ(*b.report.index, 1);
  EXPECT_LT(std::abs(a.reduced_curvature), 1e-2 * a.curvature_scale);
  EXPECT_LT(std::abs(b.reduced_curvature), 1e-2 * b.curvature_scale);
  const double zero = la + a.reduced_curvature * (lb - la) / (a.reduced_curvature - b.reduced_curvature);
  EXPECT_NEAR(zero, 2.10198316, 2e-5);
}

// The unknowns' layout with several shooting segments (the length's column after every node's
// state): the same index, and S to 1e-6 of its scale, the Jacobian's own accuracy (each segment
// integrated to 1e-12, the length's column by central differences either way); measured 4e-10.
TEST(FreeLength, MultipleShootingGivesTheSameCurvature) {
  for (const char* name : {"sleeve.toml", "arm_scale.toml"}) {
    Case c = load_case(testing::case_path(name));
    const Sliding single = solve_sliding(c, 0.0);
    c.definition.options.segments = 4;
    const Sliding multiple = solve_sliding(c, 0.0);
    const FreeLengthStability a = analyse_free_length(*single.problem, single.x);
    const FreeLengthStability b = analyse_free_length(*multiple.problem, multiple.x);
    ASSERT_TRUE(a.report.defined() && b.report.defined()) << a.report.reason << b.report.reason;
    EXPECT_EQ(*a.report.index, *b.report.index);
    EXPECT_NEAR(a.reduced_curvature, b.reduced_curvature, 1e-6 * (std::abs(a.reduced_curvature) + a.curvature_scale));
  }
}

// S from the Jacobian's Schur complement against d2E*/dell2 from energies alone: second
// differences at h, h/2, h/4 (h = 0.2 reach ell) converge to it (the h/4 one is closer than the h
// one) and their Richardson extrapolation (4 d(h/4) - d(h/2)) / 3 agrees with S to 1e-6 of |S| +
// the terms' scale (what the Jacobian's central differences leave), plus the round-off of energies
// exact to eps = 1e-11 (1 + |E|) (the family's Newton tolerance; the energy is stationary, so the
// residual enters it at first order times lengths ~1), which the extrapolation turns into
// ~6 eps / (h/4)^2. Measured: 2e-9 to 2e-8 of the scale on the arm scale and the sling, 8e-6 on
// the sleeve (its family folds 0.8 % of ell away, so h is small and round-off dominates).
TEST(FreeLength, CurvatureIsTheSecondDifferenceOfTheEnergyAlongTheFixedLengthFamily) {
  for (const Sliding& s : cases()) {
    const FreeLengthStability f = analyse_free_length(*s.problem, s.x);
    ASSERT_TRUE(f.report.defined()) << f.report.reason;
    const FixedFamily family(s);
    const double ell = length_of(s), E0 = family.at(ell).energy;
    auto second = [&](double h) { return (family.at(ell + h).energy - 2 * E0 + family.at(ell - h).energy) / (h * h); };
    const double h = 0.2 * s.reach * ell;
    const double d1 = second(h), d2 = second(h / 2), d4 = second(h / 4);
    EXPECT_LT(std::abs(d4 - f.reduced_curvature), std::abs(d1 - f.reduced_curvature));
    const double coarse = (4 * d2 - d1) / 3, fine = (4 * d4 - d2) / 3;  // Richardson: error ~h^4
    const double round_off = 6 * 1e-11 * (1 + std::abs(E0)) / std::pow(h / 4, 2);
    EXPECT_NEAR(fine, f.reduced_curvature, 1e-6 * (std::abs(f.reduced_curvature) + f.curvature_scale) + round_off)
        << "d(h) " << d1 << " d(h/2) " << d2 << " d(h/4) " << d4 << " Richardson from h: " << coarse;
  }
}

// The factor between the H condition and the energy's slope that S rests on: dE*/dell = -(H_exit
// - H_inside) along the fixed-length family, at the equilibrium and `reach` either side (where the
// slope is far from zero: a wrong factor would show at its full size). Central differences of
// energies with Richardson (h = 0.05 reach ell: error ~h^4 plus round-off 1e-11 |E| / h <= 1e-7):
// 1e-6 of the force scale |H_exit| + |H_in| + B/ell^2; measured 2e-8 at worst.
TEST(FreeLength, EnergySlopeIsMinusTheJumpOfHAcrossTheExit) {
  for (const Sliding& s : cases()) {
    const FixedFamily family(s);
    const double ell0 = length_of(s);
    for (const double ell : {(1 - s.reach) * ell0, ell0, (1 + s.reach) * ell0}) {
      const double h = 0.05 * s.reach * ell0;
      auto central = [&](double step) { return (family.at(ell + step).energy - family.at(ell - step).energy) / (2 * step); };
      const double slope = (4 * central(h / 2) - central(h)) / 3;
      const double H = family.at(ell).exit_H;
      EXPECT_NEAR(slope, -(H - s.inside_H), 1e-6 * (std::abs(H) + std::abs(s.inside_H) + 1.0 / (ell * ell)))
          << "ell " << ell;
    }
  }
}

// The sign of S against a direct scan of E*(ell): a minimum in ell (every neighbour higher) exactly
// when S > 0, a maximum when S < 0, at steps of reach / 2 and reach (1 % and 2 % of ell; 0.1 % and
// 0.2 % on the sleeve, whose family folds at 0.8 %), where the quadratic term S step^2 / 2 exceeds
// the energies' error 1e-11 |E| by 1e3 at least and the next term (cubic) by its ratio step / reach.
TEST(FreeLength, SignOfTheCurvatureMatchesAScanOfTheEnergy) {
  for (const Sliding& s : cases()) {
    const FreeLengthStability f = analyse_free_length(*s.problem, s.x);
    ASSERT_TRUE(f.report.defined()) << f.report.reason;
    const FixedFamily family(s);
    const double ell = length_of(s), E0 = family.at(ell).energy;
    for (const double k : {-2.0, -1.0, 1.0, 2.0}) {
      const double E = family.at(ell * (1 + 0.5 * s.reach * k)).energy;
      if (f.reduced_curvature > 0) EXPECT_GT(E, E0) << "step " << k;
      else EXPECT_LT(E, E0) << "step " << k;
    }
  }
}

// The fixed-length index from conjugate points against the discretised energy's Hessian
// (discrete_stability.hpp), which covers these fixed-length problems (planar, clamped or sliding
// ends, dead loads): on the four cases above and on a pinned sleeve whose fixed-length problem is
// itself unstable (end A held at (-d, 0): index 1 at fixed length, 2 in all).
TEST(FreeLength, FixedLengthIndexAgreesWithTheDiscretisedEnergy) {
  std::vector<Sliding> all = cases();
  std::string text = testing::case_text("sleeve.toml");
  const std::string sliding_start = "type = \"sliding\"\naxis = [1, 0, 0]\nposition = [0, 0]\nforce = [\"P_prime\", 0]";
  const auto at = text.find(sliding_start);
  ASSERT_NE(at, std::string::npos) << "sleeve.toml's start changed";
  text.replace(at, sliding_start.size(), "type = \"pinned\"\nposition = [\"-d\", 0]");
  text.replace(text.find("EI = 1.0"), 8, "EI = 1.0\nd = 0.8");
  all.push_back(solve_sliding(load_case_text(text, testing::case_path("sleeve.toml"), {{"P", 40.0}, {"P_prime", 45.0}}), -40.0));
  std::vector<int> fixed_indices;
  for (const Sliding& s : all) {
    const FreeLengthStability f = analyse_free_length(*s.problem, s.x);
    ASSERT_TRUE(f.report.defined()) << f.report.reason;
    const FixedLengthProblem fixed = fixed_length_problem(*s.problem, s.x, f.parameter);
    const DiscreteStability check = discrete_stability(*fixed.problem, fixed.x);
    ASSERT_TRUE(check.defined() && check.trustworthy) << describe(check) << " " << check.check_message;
    EXPECT_EQ(*check.index, *f.fixed_length.index);
    fixed_indices.push_back(*f.fixed_length.index);
  }
  EXPECT_EQ(fixed_indices.back(), 1);  // the pinned sleeve at P = 40 (measured ell = 1.00007)
  EXPECT_EQ(*analyse_free_length(*all.back().problem, all.back().x).report.index, 2);
}

// The arm scale in the small-deflection limit (alpha -> 0): E*(ell) = W sin(alpha) ell - W^2
// cos(alpha)^2 ell^3 / (6 EI) (a cantilever's tip deflection W cos(alpha) ell^3 / 3 EI), stationary at
// ell^2 = 2 EI sin(alpha) / (W cos(alpha)^2), where S = -W^2 cos(alpha)^2 ell / EI < 0: a maximum.
// At alpha = 0.01 the next order is ~alpha^2 = 1e-4 (measured 1.1e-4 for S, 1e-5 for ell).
TEST(FreeLength, ArmScaleMatchesTheSmallDeflectionLimit) {
  const double alpha = 0.01, W = 2.0;
  const double ell = std::sqrt(2 * std::sin(alpha) / W) / std::cos(alpha);
  const Sliding s = arm_scale({{"alpha", alpha}, {"W", W}, {"ell", ell}});
  const FreeLengthStability f = analyse_free_length(*s.problem, s.x);
  ASSERT_TRUE(f.report.defined()) << f.report.reason;
  EXPECT_NEAR(length_of(s) / ell, 1.0, 1e-3);
  const double S = -W * W * std::cos(alpha) * std::cos(alpha) * length_of(s);
  EXPECT_NEAR(f.reduced_curvature / S, 1.0, 1e-3);
  EXPECT_EQ(*f.report.index, 1);
}

// Where the reduction does not apply the index stays null with the reason: the same arm-scale
// equilibrium with ell chosen so that the tip is horizontal (an angle condition, not the sliding
// condition) is not a sliding length, nor is a length that also scales the stiffness; a problem
// without an unknown changing the rod is not this analysis's business.
TEST(FreeLength, NullWhereTheLengthDoesNotSlide) {
  Case c = load_case(testing::case_path("arm_scale.toml"));
  ProblemDefinition& d = c.definition;
  d.start = EndCondition::clamped(constant(Vec3::Zero()), [](const Parameters& p) {
    return OrientationTarget{Vec3::UnitZ(), p["alpha"]};
  });
  d.end.impose_orientation_angle(Vec3::UnitZ(), [](const Parameters&) { return 0.0; });
  const ShootingProblem problem(d);
  const ShootingResult r = solve(problem, problem.initial_unknowns(c.start_guess));
  ASSERT_TRUE(r.summary.converged()) << r.summary.brief_report();
  const StabilityReport report = analyse_free_length_stability(problem, r.x);
  EXPECT_FALSE(report.defined());
  EXPECT_NE(report.reason.find("not balanced by the continuity of H"), std::string::npos) << report.reason;

  // The length also scaling the stiffness: the energy's slope is no longer -H at the exit.
  std::string text = testing::case_text("arm_scale.toml");
  text.replace(text.find("B = \"EI\""), 8, "B = \"EI * ell\"");
  const Sliding scaled = solve_sliding(load_case_text(text, testing::case_path("arm_scale.toml")), 0.0);
  const StabilityReport stiff = analyse_free_length_stability(*scaled.problem, scaled.x);
  EXPECT_FALSE(stiff.defined());
  EXPECT_NE(stiff.reason.find("not only its length"), std::string::npos) << stiff.reason;

  // The part inside the sleeve without a known energy: an H condition whose value changes with
  // the length (not the constant H of a straight part under a dead load), and a sleeve free to
  // turn (its exit pinned: the part inside and its load turn with it). Both solve; neither gets a
  // count, from this analysis or from the discretised energy (discrete_stability_sleeve_test).
  std::string moving_H = testing::case_text("arm_scale.toml");
  moving_H.replace(moving_H.find("extra_hamiltonian = 0.0"), 23, "extra_hamiltonian = \"0.05*ell\"");
  std::string pinned_exit = testing::case_text("sleeve.toml");
  pinned_exit.replace(pinned_exit.find("type = \"clamped\""), 16, "type = \"pinned\"");
  for (const auto& [name, text, reason] :
       {std::tuple<std::string, std::string, std::string>{"arm_scale.toml", moving_H, "changes with the sliding length"},
        {"sleeve.toml", pinned_exit, "does not hold the rod's position and direction"}}) {
    const Case uncovered = load_case_text(text, testing::case_path(name));
    const ShootingProblem p(uncovered.definition);
    const ShootingResult solved = solve(p, p.initial_unknowns(uncovered.start_guess));
    ASSERT_TRUE(solved.summary.converged()) << name << ": " << solved.summary.brief_report();
    const StabilityReport whole = analyse_stability(p, solved.x);
    EXPECT_FALSE(whole.defined()) << name;
    EXPECT_NE(whole.reason.find(reason), std::string::npos) << whole.reason;
  }

  const auto column = testing::solve_case("euler_column.toml");
  const StabilityReport none = analyse_free_length_stability(*column.problem, column.solution.result.x);
  EXPECT_FALSE(none.defined());
  EXPECT_NE(none.reason.find("no unknown parameter changes the rod"), std::string::npos) << none.reason;
}

}  // namespace
}  // namespace kirchhoff

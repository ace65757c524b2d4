// Ipopt on the discretised energy as the shooting solver's starting point (discrete_seed.hpp):
// from its shape, end reactions and gap multipliers the active-set shooting reaches equilibria
// that it cannot reach from a contact-free guess, and they are the equilibria Ipopt found.
#include <cmath>

#include "kirchhoff/analysis/discrete_seed.hpp"
#include "kirchhoff/jobs/case_equilibria.hpp"
#include "kirchhoff/jobs/equilibria.hpp"
#include "test_support.hpp"

namespace kirchhoff {
namespace {

// Bending energy of a shooting solution, by the trapezoidal rule on 4001 samples (~1e-8).
double bending_energy(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  std::vector<double> s;
  for (int i = 0; i <= 4000; ++i) s.push_back(i / 4000.0);
  const auto points = problem.sample(x, s);
  double energy = 0.0;
  for (size_t i = 0; i + 1 < points.size(); ++i)
    energy += 0.25 * (std::pow(points[i].m.z(), 2) + std::pow(points[i + 1].m.z(), 2)) * (s[i + 1] - s[i]);
  return energy;  // EI = 1: m^2 / 2
}

struct SeedCase {
  double Delta, a;
  int contacts;  // what the discrete minimum touches
};

TEST(DiscreteSeed, CavityEquilibriaBeyondTheActiveSetLoopsReach) {
  // cases/cavity.toml: from its free-arch guess the active-set loop fails at these end shortenings
  // (it adds contacts one by one where the free rod penetrates; the equilibria here are S-shaped,
  // touching the walls where the free arch does not).
  // The last is a narrow cavity (walls 0.02 apart): the rod snakes between them with ten contacts.
  for (const SeedCase& sc :
       {SeedCase{0.05, 0.1, 1}, SeedCase{0.03, 0.05, 2}, SeedCase{0.3, 0.1, 3}, SeedCase{0.03, 0.01, 10}}) {
    SCOPED_TRACE("Delta = " + std::to_string(sc.Delta) + ", a = " + std::to_string(sc.a));
    const Case c = load_case(testing::case_path("cavity.toml"), {{"Delta", sc.Delta}, {"a", sc.a}});
    DiscreteSeed seed;
    const ContactSolveResult r = solve_from_discrete_seed(c.definition, 200, 0.05, &seed);
    ASSERT_TRUE(r.result.summary.converged()) << r.result.summary.brief_report();
    ASSERT_TRUE(r.complementarity) << r.message;
    EXPECT_EQ(static_cast<int>(seed.contacts.size()), sc.contacts) << seed.summary;
    // The seed's contact set was right: the loop did not change it.
    EXPECT_TRUE(r.log.empty()) << r.log.front();
    ASSERT_EQ(r.definition.contacts.size(), seed.contacts.size());
    for (size_t k = 0; k < seed.contacts.size(); ++k) {
      EXPECT_EQ(r.definition.contacts[k].obstacle, seed.contacts[k].obstacle);
      EXPECT_NEAR(r.definition.contacts[k].s, seed.contacts[k].s, 2.0 / 200);  // within two segments
    }
    const ShootingProblem problem(r.definition);
    const Solution sol = make_solution(problem, r.result, 401, {"min_gap"});
    EXPECT_GE(sol.derived.at("min_gap"), -1e-10);
    EXPECT_LE(sol.invariants.H.relative_spread(), 1e-9);  // H across every contact
    // The same equilibrium as Ipopt's: energies agree to the discretisation's O((h / l)^2), l the
    // shortest free arc (between contacts or a clamp and a contact; ~5e-5 on wall.toml's rod at
    // N = 200), with a factor 4 for the contacts' positions between nodes (measured: 0.5-1.6 times
    // (h / l)^2 on these four).
    double shortest = r.definition.contacts.front().s;
    for (size_t k = 0; k < r.definition.contacts.size(); ++k) {
      const double next = k + 1 < r.definition.contacts.size() ? r.definition.contacts[k + 1].s : 1.0;
      shortest = std::min(shortest, next - r.definition.contacts[k].s);
    }
    const double h = 1.0 / 200;
    EXPECT_NEAR(bending_energy(problem, r.result.x) / seed.discrete.energy, 1.0, 4.0 * std::pow(h / shortest, 2));

  }
}

TEST(DiscreteSeed, StartStateIsCloseToTheSolution) {
  // The seed's n(0) and m(0) are first-order approximations (h = 1/200) of the solved ones.
  const Case c = load_case(testing::case_path("wall.toml"));
  DiscreteSeed seed;
  const ContactSolveResult r = solve_from_discrete_seed(c.definition, 200, 0.05, &seed);
  ASSERT_TRUE(r.complementarity) << r.message;
  const ShootingProblem problem(r.definition);
  const RodPoint start = problem.sample(r.result.x, {0.0}).front();
  EXPECT_LE((seed.start.n - start.n).norm() / start.n.norm(), 2e-2);
  EXPECT_NEAR(seed.start.m.z(), start.m.z(), 2e-2 * std::abs(start.m.z()));
  EXPECT_LE((seed.start.r - start.r).norm(), 1e-15);
}

TEST(DiscreteSeed, RefusesWhatTheDiscreteModelDoesNotDescribe) {
  auto refused = [](const std::string& name, const std::string& reason) {
    const Case c = load_case(testing::case_path(name));
    try {
      seed_from_discrete_energy(c.definition);
      ADD_FAILURE() << name << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  refused("twisted_ribbon_pole.toml", "spatial");
  refused("indenter.toml", "the end is neither clamped nor pinned");  // a roller
  refused("simply_supported.toml", "solves for parameters");
  refused("heavy_cantilever.toml", "the end is neither clamped nor pinned");  // free
}

// Pinned ends (position held, no couple): the end segments' angles are free. A pinned-pinned rod
// held at D = 0.7 (L = EI = 1) buckles into the first-mode Elastica, energy 3.211755985 (the
// elliptic closed form 8 EI K (E - (1 - m) K) / L, a probe's); the discrete energy converges to it
// at second order (N = 200: within 10 h^2 relative), and the shooting solve from the seed to 1e-8
// (the closed form is quoted to ten digits; the solve's energy is good to ~1e-10).
// Under a wall at y = 0.2 the rod buckled towards it rests on it at one point (energy 12.2722,
// stable; 12.2722219 is the shooting solution's, checked here to 1e-6 as a regression value, and a
// probe's discretised energy agrees to its O(h^2): 12.2699 at N = 120), which `equilibria` did not list
// while the seeds were made for clamped ends only.
TEST(DiscreteSeed, PinnedEndsTurnFreely) {
  std::string text = R"(model = "planar"
[parameters]
D = 0.7
[rod]
length = 1.0
B = 1.0
[start]
type = "pinned"
position = [0, 0]
[end]
type = "pinned"
position = ["D", 0]
[guess]
orientation = { axis = [0, 0, 1], angle = 1.2 }
force = [-15, 0]
)";
  const Case free_rod = load_case_text(text, "pinned.toml");
  DiscreteSeed seed;
  const ContactSolveResult r = solve_from_discrete_seed(free_rod.definition, 200, 0.05, &seed);
  ASSERT_TRUE(r.result.summary.converged()) << r.message;
  const double exact = 3.211755985, h = 1.0 / 200;
  EXPECT_NEAR(seed.discrete.energy / exact, 1.0, 10 * h * h);
  EXPECT_NEAR(seed.start.m.z(), 0.0, 1e-12);
  const ShootingProblem problem(r.definition);
  EXPECT_NEAR(total_potential_energy(problem, r.result.x), exact, 1e-8);

  text += "[[obstacles]]\ntype = \"plane\"\nname = \"wall\"\npoint = [0, 0.2]\nnormal = [0, -1, 0]\n";
  const Case walled = load_case_text(text, "pinned_wall.toml");
  EquilibriaOptions options;
  options.max_equilibria = 12;  // (the CLI's `equilibria --max 12` lists both, 2nd and 3rd by energy)
  const EquilibriaSearch search = find_case_equilibria(walled, 21, options);
  int stable_contacts = 0;
  for (const Equilibrium& e : search.equilibria)
    if (!e.solution.contacts.empty() && e.stability.stable()) {
      ++stable_contacts;
      EXPECT_NEAR(e.energy, 12.2722219, 1e-6);
    }
  EXPECT_EQ(stable_contacts, 2) << "the contact at s = 0.2839 and its mirror image at 0.7161";
  // And lying flat on the wall over [0.3204, 0.6796], symmetric about mid-span: the
  // mirror-symmetric seed, whose Ipopt minimiser passes the KKT check to a seed's accuracy only
  // (stationarity 2.5e-4 at 200 segments), was refused before. Its energy against the discretised
  // energy's at 100, 200 and 400 segments (11.611699, 11.618643, 11.620383: second order, ratio
  // 4.0), Richardson-extrapolated to 11.620963: 1e-5 leaves ten times the extrapolation's own error
  // (the next term, h^4, ~1e-6). Unstable: index 1 by the discretised energy (the conjugate
  // points do not cover a flat contact). (The shooting holds it as two flat contacts carrying the
  // edge forces with the rod on the wall between them, force-free: the span is the outer ends.)
  const Equilibrium* flat = nullptr;
  for (const Equilibrium& e : search.equilibria)
    for (const PointContact& c : e.solution.contacts)
      if (c.extended) flat = &e;
  ASSERT_NE(flat, nullptr) << "the rod lying flat on the wall is not listed";
  EXPECT_NEAR(flat->energy, 11.620963, 1e-5);
  double first = 1.0, last = 0.0;
  for (const PointContact& c : flat->solution.contacts) {
    first = std::min(first, c.s);
    last = std::max(last, c.extended ? c.s_end : c.s);
  }
  // (The edges are Newton's unknowns, solved to a residual of 6e-14: measured, they sum to 1
  // within 2.3e-14; 1e-8 leaves five decades for a flat contact's weaker conditioning.)
  EXPECT_NEAR(first + last, 1.0, 1e-8) << "symmetric about mid-span";
  ASSERT_TRUE(flat->stability.defined()) << flat->stability.reason;
  EXPECT_EQ(*flat->stability.index, 1);
}

}  // namespace
}  // namespace kirchhoff

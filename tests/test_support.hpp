// Helpers shared by the tests: load a case from cases/, solve it, sample it.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/model/rod_model.hpp"

namespace kirchhoff::testing {

inline std::string case_path(const std::string& name) { return std::string(KIRCHHOFF_CASES_DIR) + "/" + name; }

// A scratch file's path in gtest's temporary directory, own to this process: ctest runs the tests
// of one binary as parallel processes, and a shared name lets one overwrite what another is about
// to read (two tolerances of one case read each other's file).
inline std::string scratch_path(const std::string& name) {
  return ::testing::TempDir() + "/kirchhoff_" + std::to_string(getpid()) + "_" + name;
}

// The text of a shipped case file, for tests that edit it before loading it.
inline std::string case_text(const std::string& name) {
  std::ifstream file(case_path(name));
  EXPECT_TRUE(file.good()) << case_path(name);
  return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

// A rod between two frictionless sleeves (an "elastica sling", Cazzolli & Dal Corso 2024): it
// leaves the first at the origin at angle theta1 and enters the second at (D, 0) at angle -theta2;
// both parts inside are straight and unloaded (H = 0 there), so the length outside, ell, slides.
// Equilibria at ell = 1.1132 (index 0) and 1.9572 (index 1). Used by the sliding-length stability
// tests and their discretised-energy check.
// A rod of natural curvature k0 (2 pi: its unstressed circle), both ends pinned at the origin:
// without force, theta linear in s; one of a family (the ring turns about its pin).
inline constexpr const char* kNaturalRingPinnedAtOnePoint = R"(model = "planar"
[parameters]
k0 = 6.283185307179586
[rod]
length = 1.0
B = 1.0
u_hat = [0, "k0", 0]
[start]
type = "pinned"
position = [0, 0]
[end]
type = "pinned"
position = [0, 0]
[guess]
orientation = { axis = [0, 0, 1], angle = 1.5707963267948966 }
force = [0, 0]
)";

inline constexpr const char* kTwoSleeveRodCase = R"(
title = "A rod between two sliding sleeves"
model = "planar"

[parameters]
theta1 = 0.5
theta2 = 1.0
D = 1.0
EI = 1.0
ell = 1.2
m_guess = 1.0

[rod]
length = "ell"
B = "EI"

[start]
type = "clamped"
position = [0, 0]
orientation = { axis = [0, 0, 1], angle = "theta1" }

[end]
type = "clamped"
position = ["D", 0]
orientation = { axis = [0, 0, 1], angle = "-theta2" }
extra_hamiltonian = 0.0

[solver]
unknowns = ["ell"]

[guess]
force = [-1, 0]
moment = [0, 0, "m_guess"]
)";

// wall.toml with a guess next to its asymmetric point contact far from mid-span (s = 0.454754,
// f = 49.1106 at Delta = 0.0307, found by `equilibria`); load it with {{"Delta", 0.0307},
// {"P_guess", 131.24}, {"m_guess", 1.213}}.
inline std::string far_asymmetric_wall_contact_text() {
  std::string text = case_text("wall.toml");
  const std::string guess_force = "force = [\"-P_guess\", 0]";
  const auto at = text.find(guess_force);
  EXPECT_NE(at, std::string::npos) << "wall.toml's guess force changed";
  if (at != std::string::npos) text.replace(at, guess_force.size(), "force = [\"-P_guess\", -24.33]");
  return text + "\n[[guess.contacts]]\nobstacle = \"wall\"\ns = 0.4548\nforce = 49.1\n";
}

// A Winkler foundation V = k y^2 / 2 per length (force -k y e_y, gradient -k e_y e_y^T): a field
// whose force depends on position, with closed-form eigenvalues on a straight column.
class WinklerFoundation final : public ExternalField {
 public:
  explicit WinklerFoundation(double k) : k_(k) {}
  double potential(double, const Vec3& r) const override { return 0.5 * k_ * r.y() * r.y(); }
  Vec3 force(double, const Vec3& r) const override { return Vec3(0.0, -k_ * r.y(), 0.0); }
  Mat3 force_gradient(double, const Vec3&) const override {
    Mat3 g = Mat3::Zero();
    g(1, 1) = -k_;
    return g;
  }

 private:
  double k_;
};

struct Solved {
  Case c;
  std::unique_ptr<ShootingProblem> problem;
  Solution solution;
};

// Loads cases/<name>, solves from its guess and asserts convergence.
inline Solved solve_case(const std::string& name, const ParameterOverrides& overrides = {},
                         const std::string& phase_condition = "", int samples = 401) {
  Solved out;
  out.c = load_case(case_path(name), overrides, phase_condition);
  out.problem = std::make_unique<ShootingProblem>(out.c.definition);
  ShootingResult r = solve(*out.problem, out.problem->initial_unknowns(out.c.start_guess));
  EXPECT_TRUE(r.summary.converged()) << name << ": " << r.summary.brief_report();
  out.solution = make_solution(*out.problem, std::move(r), samples, out.c.derived);
  return out;
}

// A contact continuation with, for every reported point, the problem it was solved in (its
// active set and parameter value), to look at its contacts and profile.
struct ContactBranch {
  ContactContinuationResult result;
  std::vector<ContinuationPoint> points;  // as reported, events labelled by what changed
  std::vector<std::shared_ptr<ShootingProblem>> problems;
  std::vector<PointContact> contacts(size_t i) const { return problems[i]->contacts_at(points[i].x); }
};

inline ContactBranch follow_contacts(const Case& c, const RodContinuationOptions& o) {
  ContactBranch out;
  ProblemDefinition leg = c.definition;
  auto on_leg = [&](const std::vector<PointContact>& active) { leg.contacts = active; };
  auto on_point = [&](const ContinuationPoint& p) {
    auto problem = std::make_shared<ShootingProblem>(leg);
    problem->set_parameter(o.parameter, p.parameter);
    out.problems.push_back(problem);
  };
  out.result = continue_with_contacts(c.definition, c.start_guess, o, on_point, {}, on_leg);
  out.points = out.result.result.points;
  EXPECT_EQ(out.points.size(), out.problems.size());
  return out;
}

// How the plectoneme tests follow cases/plectoneme.toml in its end rotation, as the plectonemes
// command does at L/2R = 100: long steps, modified Newton, a point whose chord iterations converged
// keeping the previous matrix, no branch points.
inline RodContinuationOptions plectoneme_turns_options(double target, const std::vector<std::string>& derived) {
  RodContinuationOptions o;
  o.parameter = "turns";
  o.target = target;
  o.initial_step = 1.0;
  o.max_step = 60.0;
  o.max_points = 2000;
  o.derived = derived;
  o.samples = 1001;
  o.detect_branch_points = false;
  o.modified_newton = true;
  o.corrector_max_iterations = 16;
  o.grow_iterations = 10;
  o.shrink_iterations = 14;
  o.reuse_jacobian_iterations = 8;
  return o;
}

// H just before and just after arclength s (either side of a contact).
inline std::pair<double, double> hamiltonian_across(const ShootingProblem& problem, const Eigen::VectorXd& x, double s) {
  const RodModel& model = problem.equations(problem.parameters_at(x))->model();
  const auto pair = problem.sample(x, {s - 1e-9, s + 1e-9});
  return {hamiltonian(model, pair[0]), hamiltonian(model, pair[1])};
}

}  // namespace kirchhoff::testing

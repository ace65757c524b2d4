// Helpers shared by the tests: load a case from cases/, solve it, sample it.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "kirchhoff/case_file.hpp"
#include "kirchhoff/contact.hpp"
#include "kirchhoff/invariants.hpp"
#include "kirchhoff/solution.hpp"

namespace kirchhoff::testing {

inline std::string case_path(const std::string& name) { return std::string(KIRCHHOFF_CASES_DIR) + "/" + name; }

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

inline ContactBranch follow_contacts(const Case& c, const ContinuationOptions& o) {
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
inline ContinuationOptions plectoneme_turns_options(double target, const std::vector<std::string>& derived) {
  ContinuationOptions o;
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

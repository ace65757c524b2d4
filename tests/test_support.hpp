// Helpers shared by the tests: load a case from cases/, solve it, sample it.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "kirchhoff/case_file.hpp"
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

}  // namespace kirchhoff::testing

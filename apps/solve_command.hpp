// The CLI's commands; each returns the process exit status.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/case_solve.hpp"

namespace kirchhoff::cli {

// Exit statuses shared by all commands.
constexpr int kExitOk = 0;
constexpr int kExitNotConverged = 1;  // the solver ran and reported a failure status
constexpr int kExitBadInput = 2;      // the case file or the command line was refused

struct SolveArguments {
  std::string case_path;
  StartSeed seed;
  std::vector<std::string> overrides;  // NAME=VALUE
  std::vector<std::string> solver;     // --solver KEY=VALUE: [solver] keys
  bool json = false;
  std::string profile_path;
  std::string phase_condition;  // empty: as in the case file
  double max_seconds = kDefaultSolveSeconds;  // wall-clock limit of the whole solve (0: none)
  bool direct = false;  // Newton from the guess at the --set values instead of the homotopy
};

int run_solve(const SolveArguments& args);

// NAME=VALUE texts as overrides; throws CaseError naming the bad one.
ParameterOverrides parse_overrides(const std::string& case_path, const std::vector<std::string>& texts);

// A case loaded and solved the way `solve` does it (case_solve.hpp).
struct SolvedCase {
  Case c;
  CaseSolve solved;
};
// Loads and solves; on failure prints the reason (and, with json, a failure object on stdout)
// and returns the exit status, else kExitOk. With `analyse` (solve's own), the solution, its
// checks and its stability are made too (CaseSolveOptions); without, only the equilibrium.
// `refusal`, when given, says of the loaded case why the command cannot run on it ("" when it
// can): said as bad input before anything is solved.
int load_and_solve(const std::string& case_path, const std::vector<std::string>& overrides,
                   const std::string& phase_condition, bool json, SolvedCase* out, const StartSeed& seed = {},
                   double max_seconds = kDefaultSolveSeconds, bool direct = false,
                   const std::vector<std::string>& solver = {}, bool analyse = true,
                   const std::function<std::string(const Case&)>& refusal = {});
// Prints why a solve is not a trustworthy equilibrium (and, with json, the failure object) and
// returns kExitNotConverged.
int report_not_converged(const Case& c, const NewtonSummary& summary, bool json);
int run_check(const std::string& case_path, const std::vector<std::string>& overrides,
              const std::vector<std::string>& solver = {});

}  // namespace kirchhoff::cli

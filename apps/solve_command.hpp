// The CLI's commands; each returns the process exit status.
#pragma once

#include <string>
#include <vector>

namespace kirchhoff::cli {

// Exit statuses shared by all commands.
constexpr int kExitOk = 0;
constexpr int kExitNotConverged = 1;  // the solver ran and reported a failure status
constexpr int kExitBadInput = 2;      // the case file or the command line was refused

struct SolveArguments {
  std::string case_path;
  std::vector<std::string> overrides;  // NAME=VALUE
  bool json = false;
  std::string profile_path;
  std::string phase_condition;  // empty: as in the case file
};

int run_solve(const SolveArguments& args);
int run_check(const std::string& case_path, const std::vector<std::string>& overrides);

}  // namespace kirchhoff::cli

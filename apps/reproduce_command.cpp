#include "reproduce_command.hpp"

#include <filesystem>
#include <iostream>

#include "kirchhoff/reproduce/reproduce.hpp"
#include "solve_command.hpp"

namespace kirchhoff::cli {

int run_reproduce(const std::string& out_dir, const std::string& cases_dir, bool full) {
  std::cerr << "kirchhoff reproduce -> " << out_dir << "\n";
  ReproduceResult result;
  try {
    result = reproduce({out_dir, cases_dir, full}, [](const std::string& line) { std::cerr << "  " << line << std::endl; });
  } catch (const CaseError& e) {  // a case file missing or refused: bad input, as Python's CaseError
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitNotConverged;
  }
  const int failed = result.failed();
  std::cerr << "  wrote " << (std::filesystem::path(out_dir) / "report.md").string() << " ("
            << result.rows.size() - failed << "/" << result.rows.size() << " pass) in " << result.seconds << " s\n";
  return failed == 0 ? kExitOk : kExitNotConverged;
}

}  // namespace kirchhoff::cli

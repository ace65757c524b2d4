// libFuzzer target: the case-file loader and --set parsing, on arbitrary bytes.
//
// The input is the text of a case file. Its leading lines of the form "#--set NAME=VALUE" (TOML
// comments, so seeds stay valid case files) are also given to parse_override, as the CLI's --set
// would be, and the overrides it accepts are passed to the loader.
//
// Expected outcomes: a Case, or a CaseError (refused input) from load_case_text, or
// std::invalid_argument from parse_override. Anything else - another exception, a crash, a
// sanitizer report, a hang or a blow-up in memory - is a bug, and libFuzzer reports it.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/shooting/shooting.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  kirchhoff::ParameterOverrides overrides;
  std::istringstream lines(text);
  std::string phase_condition;
  for (std::string line; std::getline(lines, line) && line.rfind("#--", 0) == 0;) {
    if (line.rfind("#--set ", 0) == 0) {
      try {
        overrides.push_back(kirchhoff::parse_override(line.substr(7)));
      } catch (const std::invalid_argument&) {
        // Refused, as the CLI refuses it (exit 2).
      }
    } else if (line == "#--phase-condition axial") {
      phase_condition = "axial";
    }
  }
  try {
    const kirchhoff::Case c = kirchhoff::load_case_text(text, "fuzz.toml", overrides, phase_condition);
    // What `kirchhoff check` does after loading.
    const kirchhoff::ShootingProblem problem(c.definition);
    (void)problem.size();
  } catch (const kirchhoff::CaseError&) {
    // Refused with a message: the expected outcome for most inputs.
  }
  return 0;
}

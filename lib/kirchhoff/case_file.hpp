// Case files: a TOML description of a rod problem (see cases/ and the README for the keys).
// Every number in the rod, end and guess tables may be an expression in the [parameters]
// (muParser syntax), and material properties may also use the arclength s.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kirchhoff/shooting.hpp"

namespace kirchhoff {

// A case file that cannot be used; what() names the file, the key (with its line where the
// TOML parser knows it) and the reason.
struct CaseError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Case {
  std::string path;
  std::string title;
  std::string description;
  ProblemDefinition definition;
  RodPoint start_guess;                 // completed by the start conditions before solving
  std::vector<std::string> derived;     // names from derived_catalogue()
  int samples = 201;                    // profile points
};

using ParameterOverrides = std::vector<std::pair<std::string, double>>;

// Reads, validates and builds the case (including a ShootingProblem construction, so that
// inconsistent boundary conditions are reported here). Overrides replace [parameters] values
// and must name existing parameters.
// phase_condition, when non-empty, replaces [solver] phase_condition ("none" or "axial").
Case load_case(const std::string& path, const ParameterOverrides& overrides = {},
               const std::string& phase_condition = "");

// Parses "NAME=VALUE"; throws std::invalid_argument with the reason.
std::pair<std::string, double> parse_override(const std::string& text);

}  // namespace kirchhoff

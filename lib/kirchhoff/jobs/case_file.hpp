// Case files: a TOML description of a rod problem (see cases/ and docs/case-files.md for the keys).
// Every number in the rod, end and guess tables may be an expression in the [parameters]
// (muParser syntax), and material properties may also use the arclength s.
#pragma once

#include <cstddef>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// A case file that cannot be used; what() names the file, the key (with its line where the
// TOML parser knows it) and the reason.
struct CaseError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

using ParameterOverrides = std::vector<std::pair<std::string, double>>;
// [solver] keys and their values as TOML text (--solver tolerance=1e-10, stepper=rk78).
using SolverOverrides = std::vector<std::pair<std::string, std::string>>;

struct Case {
  std::string path;
  std::string title;
  std::string description;
  ProblemDefinition definition;
  RodPoint start_guess;                 // completed by the start conditions before solving
  std::vector<std::string> derived;     // names from derived_catalogue()
  int samples = 201;                    // profile points
  // The parameters as the file gives them, and the overrides (--set) the definition's values
  // include: a solve at the overridden values may reach them from the file's (homotopy.hpp).
  Parameters file_parameters;
  ParameterOverrides overrides;
  // The parameters the rod, its ends or its obstacles use: the others only shape the [guess].
  std::set<std::string> problem_parameters;
  std::string text;             // the file's text and the options it was read with (reload_case)
  std::string phase_condition;
  SolverOverrides solver_overrides;
};

// What a case file may ask for. Input beyond these bounds is refused (file, line, key, reason)
// rather than left to exhaust the stack, the memory or the range of doubles; each bound is far
// above what the shipped cases use (in brackets) and is justified beside it.
namespace case_limits {
// Case files are a few kB; a larger file is not a case file.
constexpr std::size_t kMaxFileBytes = std::size_t{1} << 20;
// Arrays and inline tables inside each other, plus the components of dotted keys leading to
// them (the shipped cases: 3). toml11 parses nesting by recursion, so thousands of levels
// overflow the stack; the text is scanned for this before toml11 sees it.
constexpr int kMaxNesting = 64;
// Named parameters (12). Every expression binds all of them, and each evaluation looks them up
// by name.
constexpr int kMaxParameters = 256;
// Multiple-shooting segments (200, the plectoneme at L/2R = 1000). Newton's Jacobian is a dense
// n x n matrix, n = 13 x segments for a spatial rod: 1000 segments take 1.6 GB, 2000 about 6 GB.
constexpr int kMaxSegments = 2000;
// Profile samples (2001). 1e5 samples are a 21 MB profile CSV (2 s); 1e6 took 20 s and 0.6 GB.
constexpr int kMaxSamples = 100000;
// Newton iterations (50): a converging Newton needs tens, each one costs a Jacobian.
constexpr int kMaxIterations = 10000;
// Threads for multiple shooting (0 = all): more than the segments/4 it can use is pointless.
constexpr int kMaxThreads = 1024;
// [[obstacles]] (2), [[guess.contacts]] (1), and the names in unknowns and output.derived (7):
// each obstacle is checked against every sample of every Newton iterate.
constexpr int kMaxObstacles = 64;
constexpr int kMaxContacts = 64;
constexpr int kMaxNames = 64;
// Every number the case computes (lengths, stiffnesses, loads, positions, angles, parameters):
// |value| <= 1e100, so that the products of up to three of them the equations form (B u^2 L,
// n x r, energies) stay below the largest double (1.8e308) instead of overflowing to inf.
constexpr double kMaxMagnitude = 1e100;
// Integrator and Newton tolerances lie in (0, 1e-2]: a looser tolerance gives answers wrong in
// the second digit that would still be reported as converged (the cases use 1e-8 to 1e-13).
// Tolerances too small to be met fail honestly (integration_failed / max_iterations, exit 1).
constexpr double kMaxTolerance = 1e-2;
}  // namespace case_limits

// Reads, validates and builds the case (including a ShootingProblem construction, so that
// inconsistent boundary conditions are reported here). Overrides replace [parameters] values
// and must name existing parameters.
// phase_condition, when non-empty, replaces [solver] phase_condition ("none" or "axial").
// Solver overrides replace (or add) [solver] keys, each validated as in the file; a value that is
// not TOML is a string (stepper=rk78), and messages name the option ("--solver KEY=VALUE").
Case load_case(const std::string& path, const ParameterOverrides& overrides = {},
               const std::string& phase_condition = "", const SolverOverrides& solver = {});
// The same from the text of a case file; `path` names it in messages (and in Case::path).
Case load_case_text(const std::string& text, const std::string& path, const ParameterOverrides& overrides = {},
                    const std::string& phase_condition = "", const SolverOverrides& solver = {});

// The same case read again with other overrides (and the options it was read with).
Case reload_case(const Case& c, const ParameterOverrides& overrides);

// Why `name` cannot be set, continued in or solved for when it is computed from other
// parameters ([parameters] A = "pi*r^2"): "A is computed from r (...); <action> r instead",
// naming the parameters it is ultimately computed from. Empty when `name` is not computed.
std::string dependent_parameter_refusal(const std::vector<DependentParameter>& dependents, const std::string& name,
                                       const std::string& action);

// Parses "KEY=VALUE" (--solver) into the key and the value's text; throws std::invalid_argument
// when there is no '=', no value or a key that is not a name. The key and value are checked
// when the case is loaded.
std::pair<std::string, std::string> parse_solver_override(const std::string& text);
// Every --solver text parsed; throws CaseError naming the bad one ("--solver tolerance: ...").
SolverOverrides parse_solver_overrides(const std::vector<std::string>& texts);

// Parses "NAME=VALUE" (--set, --event); throws std::invalid_argument with the reason: no '=', an
// empty name or one that is not an identifier, a value that is not a number. The value's range
// (finite, |value| <= 1e100) is checked where it is used, as for a value Python passes: load_case
// refuses a --set value, the continuation's request an event's.
std::pair<std::string, double> parse_override(const std::string& text);

}  // namespace kirchhoff

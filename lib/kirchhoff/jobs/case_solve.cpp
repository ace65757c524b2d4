#include "kirchhoff/jobs/case_solve.hpp"

#include <algorithm>
#include <cmath>

#include "kirchhoff/analysis/discrete_seed.hpp"
#include "kirchhoff/equations/integrator.hpp"

namespace kirchhoff {
namespace {

bool solved_for(const ProblemDefinition& d, const std::string& name) {
  return std::find(d.unknown_parameters.begin(), d.unknown_parameters.end(), name) != d.unknown_parameters.end();
}

// Whether a parameter only says where Newton starts: solved for (its value is a guess), or used
// by the [guess] alone.
bool only_a_guess(const Case& c, const std::string& name) {
  return solved_for(c.definition, name) || !c.problem_parameters.count(name);
}

CaseSolve by_homotopy(const Case& c, std::vector<ParameterChange> changes, HomotopyOptions options) {
  CaseSolve out;
  out.path.method = "homotopy";
  out.path.changes = changes;
  const Case start = case_at_file_values(c);
  DefinitionSolve at_start = solve_definition(start.definition, start.start_guess);
  if (!at_start.result.summary.converged()) {
    // Newton's own status: what failed is a solve, the one the path would start from.
    out.failure = to_string(at_start.result.summary.status);
    out.solved.result.summary = at_start.result.summary;
    out.message = "not converged: the case's own solve at its file's values, where the homotopy to the requested "
                  "values starts: " + at_start.result.summary.brief_report() + kDirectSolveHint;
    return out;
  }
  HomotopyResult h =
      follow_homotopy(at_start.problem->definition(), at_start.result.x, changes, options);
  if (h.stop != "reached" && h.stop != "not_converged") {
    out.failure = h.stop;
    out.message = h.message + kDirectSolveHint;
    // No iterate at the requested values was evaluated: no residual there to report.
    out.solved.result.summary.residual_norm = INFINITY;
    out.path.homotopy = std::move(h);
    return out;
  }
  out.solved.problem = std::make_unique<ShootingProblem>(h.definition);
  out.solved.result = std::move(h.result);
  for (const auto& line : at_start.contact_log) out.solved.contact_log.push_back("start: " + line);
  for (const auto& line : h.contact_changes) out.solved.contact_log.push_back("homotopy: " + line);
  out.path.homotopy = std::move(h);
  return out;
}

// How the equilibrium is reached: "ipopt_seed", "homotopy" or "direct" (SolvePath::method).
std::string solve_method(const Case& c, const CaseSolveOptions& options) {
  if (options.seed.ipopt) return "ipopt_seed";
  return !options.direct && !homotopy_changes(c).empty() ? "homotopy" : "direct";
}

// The equilibrium reached, by the seed, the homotopy or directly (the options' choice).
CaseSolve reach_equilibrium(const Case& c, const CaseSolveOptions& options) {
  const std::string method = solve_method(c, options);
  if (method == "ipopt_seed") {
    CaseSolve out;
    out.path.method = "ipopt_seed";
    DiscreteSeed seed;
    out.solved = as_definition_solve(
        solve_from_discrete_seed(c.definition, options.seed.segments, options.seed.amplitude, &seed));
    out.path.seed_summary = seed.summary;
    return out;
  }
  if (method == "homotopy") {
    HomotopyOptions homotopy = options.homotopy;
    homotopy.deadline = std::min(homotopy.deadline, c.definition.options.newton.deadline);
    return by_homotopy(c, homotopy_changes(c), homotopy);
  }
  CaseSolve out;
  out.path.method = "direct";
  out.solved = solve_definition(c.definition, c.start_guess);
  return out;
}

// A solve that stopped before Newton's first iteration: no iterate, so no residual to report.
CaseSolve stopped_before_newton(const std::string& method, const std::string& status, const std::string& message) {
  CaseSolve out;
  out.path.method = method;
  out.failure = status;
  out.message = message;
  out.solved.result.summary.iterations = 0;
  out.solved.result.summary.residual_norm = INFINITY;
  return out;
}

// What is reported of a converged equilibrium: its solution, checked as it is made, then (unless
// the checks failed) its stability.
void analyse(const Case& c, const CaseSolveOptions& options, CaseSolve* out) {
  const ShootingProblem& problem = *out->solved.problem;
  if (options.solution) {
    out->solution = make_solution(problem, out->solved.result, options.samples > 0 ? options.samples : c.samples,
                                  c.derived);
    if (!out->solution->result.summary.converged()) return;
  }
  const Eigen::VectorXd& x = out->solved.result.x;
  if (options.stability) out->stability = analyse_stability(problem, x);
  if (options.stability_check) out->stability_check = discrete_stability(problem, x);
  if (out->stability && out->stability_check)
    out->stability = with_discretised_index(std::move(*out->stability), *out->stability_check);
}

}  // namespace

// The overrides of parameters only the [guess] uses choose the equilibrium the homotopy starts
// from (the straight column, the S-shaped mode). Guesses of solved-for parameters are guesses at
// the requested values, which the path carries there itself: the start is the case's own solve.
Case case_at_file_values(const Case& c) {
  ParameterOverrides guesses;
  for (const auto& [name, value] : c.overrides)
    if (!solved_for(c.definition, name) && !c.problem_parameters.count(name)) guesses.emplace_back(name, value);
  Case start = reload_case(c, guesses);
  // The solver settings as the case was given them (a wall-clock limit, command-line settings).
  start.definition.options = c.definition.options;
  return start;
}

std::vector<ParameterChange> homotopy_changes(const Case& c) {
  std::vector<ParameterChange> changes;
  for (const auto& override_pair : c.overrides) {
    // Named copies: clang's C++17 (the fuzzer build) refuses a lambda capturing a structured binding.
    const std::string& name = override_pair.first;
    const double value = override_pair.second;
    if (only_a_guess(c, name) || !c.file_parameters.contains(name)) continue;
    const double from = c.file_parameters.get(name);
    if (from == value) continue;
    const auto same = std::find_if(changes.begin(), changes.end(), [&](const auto& k) { return k.name == name; });
    if (same != changes.end()) same->to = value;  // the last --set of a name wins, as in load_case
    else changes.push_back({name, from, value});
  }
  // A name set twice, back to its file value, is no change.
  changes.erase(std::remove_if(changes.begin(), changes.end(), [](const auto& k) { return k.from == k.to; }),
                changes.end());
  return changes;
}

std::string StartSeed::validate() const {
  if (segments < 4 || segments > 100000) return "seed segments must be in [4, 100000]";
  if (!std::isfinite(amplitude) || std::abs(amplitude) > 1.0)
    return "seed amplitude must be finite, within +-1 (a fraction of the rod's length)";
  return "";
}

CaseSolve solve_case(const Case& c, const CaseSolveOptions& options) {
  if (const std::string why = options.seed.validate(); !why.empty()) throw std::invalid_argument(why);
  CaseSolve out;
  // (At the requested values: a homotopy from the file's would otherwise follow the rod until its
  // imposed end enters the obstacle and report where it stopped, a fold say, not why.)
  if (const std::string why = imposed_end_inside_obstacle(c.definition); !why.empty())
    return stopped_before_newton(solve_method(c, options), "infeasible", why);
  try {
    out = reach_equilibrium(c, options);
  } catch (const InfeasibleContact& e) {
    return stopped_before_newton(solve_method(c, options), "infeasible", e.what());
  } catch (const IntegrationError& e) {
    return stopped_before_newton(solve_method(c, options), "integration_failed",
                                 std::string("the initial guess cannot be integrated: ") + e.what());
  } catch (const std::runtime_error& e) {  // from the seed alone: Ipopt's minimisation did not converge
    if (!options.seed.ipopt) throw;
    return stopped_before_newton(solve_method(c, options), "seed_failed", e.what());
  }
  if (out.failure.empty() && out.solved.result.summary.converged()) analyse(c, options, &out);
  return out;
}

}  // namespace kirchhoff

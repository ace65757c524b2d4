#include "solve_command.hpp"

#include <iostream>
#include <nlohmann/json.hpp>

#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/result_json.hpp"

namespace kirchhoff::cli {
namespace {

void print_human(const Case& c, const Solution& sol, const StabilityReport& stability,
                 const DiscreteStability& discrete) {
  std::cout << (c.title.empty() ? c.path : c.title) << "\n";
  std::cout << "  " << sol.result.summary.brief_report() << "\n";
  std::cout.precision(12);
  for (const auto& name : c.derived) std::cout << "  " << name << " = " << sol.derived.at(name) << "\n";
  const auto& H = sol.invariants.H;
  std::cout << "  H = " << H.mean << " (spread " << H.spread << ", " << H.relative_spread() << " of its scale"
            << (H.applies ? "" : "; not invariant for this rod") << ")\n";
  if (sol.invariants.m3.applies)
    std::cout << "  m3 = " << sol.invariants.m3.mean << " (spread " << sol.invariants.m3.spread << ")\n";
  if (sol.invariants.n_dot_m.applies)
    std::cout << "  n.m = " << sol.invariants.n_dot_m.mean << " (spread " << sol.invariants.n_dot_m.spread << ")\n";
  for (const auto& contact : sol.contacts) {
    std::cout << "  contact with obstacle " << contact.obstacle;
    if (const std::string& name = c.definition.obstacles[contact.obstacle].name; !name.empty())
      std::cout << " (" << name << ")";
    if (contact.extended)
      std::cout << " over [" << contact.s << ", " << contact.s_end << "], end forces " << contact.force << ", "
                << contact.force_end << "\n";
    else
      std::cout << " at s = " << contact.s << ", force " << contact.force << "\n";
  }
  std::cout << "  " << describe(stability) << "\n";
  const bool checked = discrete.defined() && discrete.trustworthy;
  if (checked && stability.index && *stability.index != *discrete.index)
    std::cout << "  warning: the discretised energy's check finds index " << *discrete.index << "\n";
  if (checked && !stability.index)
    std::cout << "  the discretised energy's check (" << discrete.elements << " elements, passed its own tests) finds index "
              << *discrete.index << "\n";
}

// How the equilibrium was reached, when a homotopy took it there.
void print_path(const SolvePath& path) {
  if (path.method != "homotopy") return;
  const HomotopyResult& h = path.homotopy;
  std::cout << "  reached by homotopy from the case's " << describe_values(path.changes, 0.0) << " in " << h.points
            << " continuation points\n";
  for (double t : h.branch_points)
    std::cout << "  crossed a branch point at " << describe_values(path.changes, t)
              << " (another branch crosses there; the stability may change)\n";
  if (!h.branch_points_checked) std::cout << "  (branch points were not looked for: too many unknowns)\n";
}

}  // namespace

ParameterOverrides parse_overrides(const std::string& case_path, const std::vector<std::string>& texts) {
  ParameterOverrides out;
  for (const auto& t : texts) {
    try {
      out.push_back(parse_override(t));
    } catch (const std::invalid_argument& e) {
      throw CaseError(case_path + ": --set: " + e.what());
    }
  }
  return out;
}

int load_and_solve(const std::string& case_path, const std::vector<std::string>& overrides,
                   const std::string& phase_condition, bool json, SolvedCase* out, const StartSeed& seed,
                   double max_seconds, bool direct, const std::vector<std::string>& solver, bool analyse,
                   const std::function<std::string(const Case&)>& refusal) {
  Case& c = out->c;
  try {
    c = load_case(case_path, parse_overrides(case_path, overrides), phase_condition, parse_solver_overrides(solver));
    limit_wall_clock(c.definition.options, max_seconds);
  } catch (const CaseError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: --max-seconds: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (const std::string why = refusal ? refusal(c) : ""; !why.empty()) {
    std::cerr << "error: " << c.path << ": " << why << "\n";
    return kExitBadInput;
  }
  CaseSolveOptions options;
  options.seed = seed;
  options.direct = direct;
  options.solution = options.stability = options.stability_check = analyse;
  CaseSolve& solved = out->solved;
  try {
    solved = solve_case(c, options);
  } catch (const std::invalid_argument& e) {  // a case the Ipopt seed does not model
    std::cerr << "error: " << c.path << ": --seed ipopt: " << e.what() << "\n";
    return kExitBadInput;
  }
  if (!solved.path.seed_summary.empty()) std::cerr << "seed: " << solved.path.seed_summary << "\n";
  if (!solved.failure.empty()) {
    std::cerr << "error: " << c.path << ": " << solved.failure << ": " << solved.message << "\n";
    if (json) {
      const NewtonSummary& summary = solved.solved.result.summary;
      nlohmann::json j = failure_json(c, solved.failure, summary.iterations, summary.residual_norm, solved.message);
      j["path"] = path_json(solved.path);
      std::cout << j.dump(2) << "\n";
    }
    return kExitNotConverged;
  }
  if (!json)
    for (const auto& line : solved.solved.contact_log) std::cerr << "contact: " << line << "\n";
  // Newton's verdict, or the solution's checks' (verification.hpp): a failure is a status, not a result.
  if (!solved.converged()) return report_not_converged(c, solved.summary(), json);
  return kExitOk;
}

int report_not_converged(const Case& c, const NewtonSummary& summary, bool json) {
  std::cerr << "error: " << c.path << ": not converged: " << summary.brief_report() << "\n";
  if (json)
    std::cout << failure_json(c, to_string(summary.status), summary.iterations, summary.residual_norm,
                              summary.why_stopped())
                     .dump(2)
              << "\n";
  return kExitNotConverged;
}

int run_solve(const SolveArguments& args) {
  SolvedCase solved;
  if (const int status = load_and_solve(args.case_path, args.overrides, args.phase_condition, args.json, &solved, args.seed,
                                        args.max_seconds, args.direct, args.solver);
      status != kExitOk)
    return status;
  const Case& c = solved.c;
  const CaseSolve& run = solved.solved;
  const ShootingProblem& problem = *run.solved.problem;
  const Solution& sol = *run.solution;
  if (!args.profile_path.empty()) {
    try {
      write_profile_csv(args.profile_path, problem.equations(sol.result.parameters)->model(), sol.profile,
                        problem.definition().kind);
    } catch (const std::runtime_error& e) {
      std::cerr << "error: " << e.what() << "\n";
      return kExitBadInput;
    }
  }
  // The stability index and its independent check (where it applies), as solve_case made them.
  const StabilityReport& stability = *run.stability;
  const DiscreteStability& discrete = *run.stability_check;
  if (args.json) {
    nlohmann::json j = solution_json(c, problem, sol, stability, &discrete);
    j["path"] = path_json(run.path);
    std::cout << j.dump(2) << "\n";
  } else {
    print_human(c, sol, stability, discrete);
    print_path(run.path);
  }
  return kExitOk;
}

int run_check(const std::string& case_path, const std::vector<std::string>& overrides,
              const std::vector<std::string>& solver) {
  try {
    const Case c = load_case(case_path, parse_overrides(case_path, overrides), "", parse_solver_overrides(solver));
    const ShootingProblem problem(c.definition);
    if (const std::string why = imposed_end_inside_obstacle(c.definition); !why.empty()) {
      std::cerr << "error: " << case_path << ": " << why << "\n";
      return kExitBadInput;
    }
    std::cout << case_path << ": ok (" << (c.definition.kind == RodKind::Planar ? "planar" : "spatial") << ", "
              << problem.size() << " unknowns, " << c.definition.options.segments << " segment(s))\n";
    return kExitOk;
  } catch (const CaseError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
}

}  // namespace kirchhoff::cli

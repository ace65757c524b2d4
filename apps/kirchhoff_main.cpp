// kirchhoff: equilibria of elastic rods by shooting, checked against Noether's invariants.
#include <CLI/CLI.hpp>
#include <iostream>

#include "reproduce_command.hpp"
#include "solve_command.hpp"

int main(int argc, char** argv) {
  using namespace kirchhoff::cli;
  CLI::App app{
      "kirchhoff - equilibria of elastic rods (planar Elastica, twisted Kirchhoff rods, extensible and\n"
      "shearable Reissner rods) by shooting, each solution checked against the invariants that\n"
      "Noether's theorem gives (H = n.v + m.u - V, m3, n.m, ...).\n\n"
      "A case file (TOML, see cases/) describes the rod, its two ends and named [parameters];\n"
      "--set NAME=VALUE changes a parameter without editing the file.\n\n"
      "Examples:\n"
      "  kirchhoff solve cases/simply_supported.toml --set theta0=2.0\n"
      "  kirchhoff solve cases/twisted_clamped.toml --json --profile rod.csv\n"
      "  kirchhoff check cases/tapered.toml\n"
      "  kirchhoff reproduce --out out\n\n"
      "Exit status: 0 solved, 1 solver failure (status and best residual reported), 2 input refused."};
  app.require_subcommand(1);

  SolveArguments solve;
  auto* solve_cmd = app.add_subcommand("solve", "Solve one equilibrium and report derived quantities and invariants");
  solve_cmd->add_option("case", solve.case_path, "Case file (TOML)")->required()->check(CLI::ExistingFile);
  solve_cmd->add_option("--set", solve.overrides, "Override a parameter: NAME=VALUE (repeatable)");
  solve_cmd->add_flag("--json", solve.json,
                      "Print one JSON object: status, iterations, residual, parameters, derived, invariants, ends");
  solve_cmd->add_option("--profile", solve.profile_path,
                        "Write the solution along the rod as CSV: s, r, d1, d2, d3, n, m, u, H, m3, n.m, dH/ds");

  solve_cmd
      ->add_option("--phase-condition", solve.phase_condition,
                   "Override [solver] phase_condition: 'axial' selects one buckled solution of an isotropic\n"
                   "twisted rod out of its circle of rotated copies (singular on the straight rod)")
      ->check(CLI::IsMember({"none", "axial"}));

  std::string check_path;
  std::vector<std::string> check_overrides;
  auto* check_cmd = app.add_subcommand("check", "Validate a case file without solving");
  check_cmd->add_option("case", check_path, "Case file (TOML)")->required()->check(CLI::ExistingFile);
  check_cmd->add_option("--set", check_overrides, "Override a parameter: NAME=VALUE (repeatable)");

  std::string out_dir = "out";
  std::string cases_dir = KIRCHHOFF_DEFAULT_CASES_DIR;
  auto* reproduce_cmd = app.add_subcommand(
      "reproduce", "Recompute the paper's results the toolkit covers: DIR/report.md, DIR/report.json, DIR/profiles/*.csv");
  reproduce_cmd->add_option("--out", out_dir, "Output folder (created)")->capture_default_str();
  reproduce_cmd->add_option("--cases", cases_dir, "Folder of the case files")->capture_default_str()->check(CLI::ExistingDirectory);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : kExitBadInput;
  }
  if (*solve_cmd) return run_solve(solve);
  if (*check_cmd) return run_check(check_path, check_overrides);
  if (*reproduce_cmd) return run_reproduce(out_dir, cases_dir);
  return kExitBadInput;
}

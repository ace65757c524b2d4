// kirchhoff: equilibria of elastic rods by shooting, checked against Noether's invariants.
#include <CLI/CLI.hpp>
#include <iostream>

#include "continue_command.hpp"
#include "plectonemes_command.hpp"
#include "reproduce_command.hpp"
#include "solve_command.hpp"
#include "vibrate_command.hpp"
#include "equilibria_command.hpp"
#include "sweep_command.hpp"

namespace {

// --seed, --seed-segments, --seed-amplitude (solve and continue).
void add_seed_options(CLI::App* command, std::string* choice, kirchhoff::StartSeed* seed) {
  command
      ->add_option("--seed", *choice,
                   "Where Newton starts: 'guess' (the case's [guess] and [[guess.contacts]]), or 'ipopt':\n"
                   "minimise the discretised energy first and start from its shape, end reactions and\n"
                   "contact set (planar clamped-clamped rods; finds contact sets the active-set loop\n"
                   "cannot reach from a contact-free guess)")
      ->check(CLI::IsMember({"guess", "ipopt"}))
      ->capture_default_str();
  command->add_option("--seed-segments", seed->segments, "Segments of the discretised rod for --seed ipopt")
      ->check(CLI::Range(4, 100000))
      ->capture_default_str();
  command
      ->add_option("--seed-amplitude", seed->amplitude,
                   "Amplitude of the buckling mode Ipopt starts from, as a fraction of L (its sign: the side)")
      ->capture_default_str();
}

}  // namespace

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
      "  kirchhoff continue cases/euler_column.toml --param P --to 100 --set theta_guess=0 --out column.csv\n"
      "  kirchhoff continue cases/euler_column.toml --param P --to 12 --set theta_guess=0 --switch-at-bp 1 \\\n"
      "      --event theta0=3 --out buckled.csv\n"
      "  kirchhoff vibrate cases/euler_column.toml --set P=5 --set theta_guess=0 --modes 3\n"
      "  kirchhoff reproduce --out out\n"
      "  kirchhoff plectonemes --slenderness 100,200 --turns 10,20 --out plectonemes\n\n"
      "Exit status: 0 solved, 1 solver failure (status and best residual reported), 2 input refused."};
  app.require_subcommand(1);

  SolveArguments solve;
  auto* solve_cmd = app.add_subcommand("solve", "Solve one equilibrium and report derived quantities and invariants");
  solve_cmd->add_option("case", solve.case_path, "Case file (TOML)")->required()->check(CLI::ExistingFile);
  solve_cmd->add_option("--solver", solve.solver, "Override a [solver] key: KEY=VALUE, e.g. tolerance=1e-10, stepper=dopri5 (repeatable; checked as in the file)");
  solve_cmd->add_option("--set", solve.overrides,
                        "Override a parameter: NAME=VALUE (repeatable). The equilibrium at the new values is\n"
                        "reached by continuation from the case's own (a homotopy in all changed parameters\n"
                        "together), so it lies on the branch the case's guess starts; a fold on the way is\n"
                        "reported (exit 1), never jumped");
  solve_cmd->add_flag("--direct", solve.direct,
                      "Newton from the case's guess at the --set values instead of the homotopy (whichever\n"
                      "equilibrium attracts the guess)");
  solve_cmd->add_flag("--json", solve.json,
                      "Print one JSON object: status, iterations, residual, parameters, derived, invariants, ends");
  solve_cmd->add_option("--profile", solve.profile_path,
                        "Write the solution along the rod as CSV: s, r, d1, d2, d3, n, m, u, H, m3, n.m, dH/ds");

  std::string solve_seed = "guess";
  add_seed_options(solve_cmd, &solve_seed, &solve.seed);
  solve_cmd
      ->add_option("--max-seconds", solve.max_seconds,
                   "Wall-clock limit of the solve in seconds (0: none); past it the solve stops with status "
                   "time_limit, exit 1")
      ->capture_default_str();
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
  std::vector<std::string> check_solver;
  check_cmd->add_option("--solver", check_solver, "Override a [solver] key: KEY=VALUE, e.g. tolerance=1e-10, stepper=dopri5 (repeatable; checked as in the file)");

  ContinueArguments cont;
  auto* continue_cmd = app.add_subcommand(
      "continue",
      "Follow a branch of equilibria in one parameter (pseudo-arclength), locating folds and branch points;\n"
      "one CSV row per point, flushed as it goes; --resume picks up a killed run");
  continue_cmd->add_option("case", cont.case_path, "Case file (TOML)")->required()->check(CLI::ExistingFile);
  continue_cmd->add_option("--param", cont.parameter, "Parameter to continue in (from [parameters])")->required();
  continue_cmd->add_option("--to", cont.to, "Stop when the parameter reaches this value")
      ->each([&](const std::string&) { cont.has_to = true; });
  continue_cmd->add_option("--step", cont.step, "Initial pseudo-arclength step")->capture_default_str();
  continue_cmd->add_option("--min-step", cont.min_step, "Smallest step before giving up")->capture_default_str();
  continue_cmd->add_option("--max-step", cont.max_step, "Largest step")->capture_default_str();
  continue_cmd->add_option("--max-points", cont.max_points, "Largest number of points")->capture_default_str();
  continue_cmd->add_option("--switch-at-bp", cont.switch_at_bp,
                           "Switch onto the branch bifurcating at the K-th branch point found (double branch points\n"
                           "of isotropic twisted rods switch with the axial phase condition)");
  continue_cmd->add_flag("--no-stability", cont.no_stability,
                         "Skip the stability index of every point (column stability_index left empty)");
  continue_cmd->add_flag("--no-branch-points", cont.no_branch_points,
                         "Do not look for branch points: their test functions cost an SVD per point, most of a\n"
                         "run on multiple-shooting cases of hundreds of unknowns (plectonemes); folds are still found");
  continue_cmd
      ->add_option("--start-from", cont.start_from,
                   "Start from the last row another run wrote (its CSV's .state.json; the endpoint at --to\n"
                   "included), e.g. a ply followed in turns, continued now in slenderness: that run's\n"
                   "parameter at the point's value, its --set values kept (this command's --set wins), and\n"
                   "its active contact set on cases with obstacles; the values are printed")
      ->check(CLI::ExistingFile);
  continue_cmd->add_option("--start-param", cont.start_param,
                           "The parameter of a --start-from state file that does not name it");
  std::string continue_seed = "guess";
  add_seed_options(continue_cmd, &continue_seed, &cont.seed);
  continue_cmd->add_option("--side", cont.switch_side, "Which side of the bifurcating branch: 1 or -1")
      ->capture_default_str();
  continue_cmd->add_option("--event", cont.stop_events, "Stop when a derived quantity crosses a value: NAME=VALUE");
  continue_cmd->add_option("--record", cont.record_events, "Record (without stopping) a crossing: NAME=VALUE");
  continue_cmd->add_option("--out", cont.out_path, "Branch CSV (a .state.json file is kept beside it)")
      ->capture_default_str();
  continue_cmd->add_option("--profiles", cont.profiles_dir, "Write each point's profile CSV into this folder");
  continue_cmd->add_option("--samples", cont.samples, "Profile samples per point (invariants, derived quantities)")
      ->capture_default_str();
  continue_cmd->add_flag("--resume", cont.resume, "Resume the run whose CSV is --out from its last written point");
  continue_cmd->add_flag("--deflate", cont.deflate,
                         "Follow every branch through the equilibria found at the start by deflation (as\n"
                         "`equilibria` lists them); branch K of the CSV starts at the K-th by energy. Not with\n"
                         "--resume, --start-from, --switch-at-bp or --seed");
  continue_cmd->add_option("--deflate-max", cont.deflate_max, "At most this many equilibria (and branches) with --deflate")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  continue_cmd
      ->add_option("--max-seconds", cont.max_seconds,
                   "Wall-clock limit of the run in seconds (0: none); it stops after the last point written, "
                   "with time_limit and exit 1, and --resume goes on")
      ->capture_default_str();
  continue_cmd
      ->add_option("--checkpoint", cont.checkpoint_seconds,
                   "Save the state file (for --resume) at most once per this many seconds (0: after every\n"
                   "point); a resumed run recomputes the rows after the last save, the same rows")
      ->capture_default_str();
  continue_cmd->add_option("--set", cont.overrides, "Override a parameter: NAME=VALUE (repeatable)");
  continue_cmd->add_option("--solver", cont.solver, "Override a [solver] key: KEY=VALUE, e.g. tolerance=1e-10, stepper=dopri5 (repeatable; checked as in the file)");
  continue_cmd->add_option("--phase-condition", cont.phase_condition, "As for solve")
      ->check(CLI::IsMember({"none", "axial"}));

  EquilibriaArguments eq;
  auto* equilibria_cmd = app.add_subcommand(
      "equilibria",
      "List the distinct equilibria at one set of parameters, by deflated Newton, sorted by energy,\n"
      "with stability index, contact set, derived quantities and invariants");
  equilibria_cmd->footer(
      "Starts from the case's guess, its mirror images, perturbations along the low modes of every\n"
      "equilibrium found and, for planar rods clamped at both ends, Ipopt's discretised minimisers;\n"
      "deflation keeps Newton from converging to an equilibrium already found. Equilibria are\n"
      "compared by their profiles relative to L; every one listed has converged and, with obstacles,\n"
      "satisfies 0 <= gap perp force >= 0. The energy is the elastic energy plus the potential of the\n"
      "field and of the given end loads (-F.r, -M theta). See docs/equilibria.md. Exit status: 0 at\n"
      "least one equilibrium, 1 none found, 2 input refused.\n\n"
      "Examples:\n"
      "  kirchhoff equilibria cases/euler_column.toml --set P=50\n"
      "  kirchhoff equilibria cases/wall.toml --set Delta=0.033 --max 6 --json --profiles wall_eq/");
  equilibria_cmd->add_option("case", eq.case_path, "Case file (TOML)")->required()->check(CLI::ExistingFile);
  equilibria_cmd->add_option("--set", eq.overrides, "Override a parameter: NAME=VALUE (repeatable)");
  equilibria_cmd->add_option("--solver", eq.solver, "Override a [solver] key: KEY=VALUE, e.g. tolerance=1e-10, stepper=dopri5 (repeatable; checked as in the file)");
  equilibria_cmd->add_option("--max", eq.max_equilibria, "Stop once this many distinct equilibria are found")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  equilibria_cmd->add_flag("--json", eq.json,
                           "Print JSON: {\"equilibria\": [solve's object with \"energy\", \"rank\", \"found_by\"], "
                           "\"rejected\", \"stopped_because\", \"log\"}");
  equilibria_cmd->add_option("--profiles", eq.profiles_dir,
                             "Write each equilibrium's profile as DIR/equilibrium_K.csv (K as in the table)");
  equilibria_cmd
      ->add_option("--max-seconds", eq.max_seconds, "Wall-clock limit of the search in seconds (0: none)")
      ->capture_default_str();

  VibrateArguments vib;
  auto* vibrate_cmd = app.add_subcommand(
      "vibrate",
      "Small-amplitude vibrations about a planar equilibrium (section 9, eqs. B.4): the lowest\n"
      "eigenfrequencies omega_k and mode shapes of qbar = (xbar, ybar, thetabar, mbar, nbar_x, nbar_y),\n"
      "with the invariant H_vib of eq. (95b) along each mode");
  vibrate_cmd->footer(
      "The equilibrium is solved as `kirchhoff solve` does. The vibrating rod keeps the case's end\n"
      "conditions with every imposed quantity held at its equilibrium value: supports and clamps stay\n"
      "put, applied end loads are dead loads (nbar = 0, mbar = 0 along them). So euler_column.toml\n"
      "(pinned, far end rolling along x under P) is the classic column under a dead load, whose first\n"
      "frequency vanishes at the Euler load; a case with both ends pinned holds the chord instead.\n"
      "Extra conditions (the end slope theta0 of simply_supported.toml) only pick the equilibrium.\n\n"
      "H_vib = 1/2 EI thetabar'^2 - thetabar (nbar_x sin theta_e - nbar_y cos theta_e)\n"
      "        + 1/2 rhoS omega^2 (xbar^2 + ybar^2) - 1/2 thetabar^2 (n_xe cos theta_e + n_ye sin theta_e)\n"
      "is conserved along s only when the equilibrium is straight; its spread is reported either way.\n"
      "omega is in the case's units; sqrt(EI / (rhoS L^4)) sets its scale. Mode shapes are scaled to a\n"
      "largest displacement of 1. An unstable equilibrium also has omega^2 < 0 (imaginary frequencies,\n"
      "listed first as unstable modes with their growth rates): their number is its stability index\n"
      "under dead loads. Exit status: 0 done, 1 the equilibrium did not converge, 2 refused\n"
      "(spatial case, extensible rod, active contacts, a sleeve end, or fewer frequencies than asked).\n\n"
      "Examples:\n"
      "  kirchhoff vibrate cases/euler_column.toml --set P=4.934802200544679 --set theta_guess=0\n"
      "  kirchhoff vibrate cases/simply_supported.toml --set theta0=1 --modes 4 --out vib.json --profiles modes/\n"
      "  kirchhoff vibrate cases/heavy_cantilever.toml --set w=0 --rho-s 2 --json");
  vibrate_cmd->add_option("case", vib.case_path, "Case file (TOML) of a planar rod")->required()->check(CLI::ExistingFile);
  vibrate_cmd->add_option("--set", vib.overrides, "Override a parameter: NAME=VALUE (repeatable)");
  vibrate_cmd->add_option("--solver", vib.solver, "Override a [solver] key: KEY=VALUE, e.g. tolerance=1e-10, stepper=dopri5 (repeatable; checked as in the file)");
  vibrate_cmd->add_option("--modes", vib.modes, "Number of lowest frequencies to find")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  vibrate_cmd->add_option("--rho-s", vib.rho_s, "Mass per unit length rho S (uniform)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  vibrate_cmd->add_option("--out", vib.out_path,
                          "Write JSON {\"frequencies\": [...], \"modes\": [{\"omega\", \"H_vib_spread\", ...}]}");
  vibrate_cmd->add_option("--profiles", vib.profiles_dir,
                          "Write each mode as DIR/mode_K.csv (unstable ones DIR/unstable_mode_K.csv): s, xbar, ybar, "
                          "thetabar, mbar, nbarx, nbary, H_vib");
  vibrate_cmd->add_flag("--json", vib.json, "Print the JSON on stdout instead of the table");

  std::string out_dir = "out";
  std::string cases_dir = KIRCHHOFF_DEFAULT_CASES_DIR;
  auto* reproduce_cmd = app.add_subcommand(
      "reproduce", "Recompute the paper's results the toolkit covers: DIR/report.md, DIR/report.json, DIR/profiles/*.csv");
  reproduce_cmd->add_option("--out", out_dir, "Output folder (created)")->capture_default_str();
  bool reproduce_full = false;
  reproduce_cmd->add_flag("--full", reproduce_full,
                          "Fig. 11 with all four slendernesses (L/2R = 100, 200, 500 to 10, 20, 20 turns; 1000 from\n"
                          "the 500 ply to 50 and down to 4) and the ply with exact contact at 100, 200 and 500 to\n"
                          "10, 20 and 20 turns: about 20 minutes instead of 2");
  reproduce_cmd->add_option("--cases", cases_dir, "Folder of the case files")->capture_default_str()->check(CLI::ExistingDirectory);

  PlectonemesArguments plect;
  plect.case_path = std::string(KIRCHHOFF_DEFAULT_CASES_DIR) + "/plectoneme.toml";
  auto* plectonemes_cmd = app.add_subcommand(
      "plectonemes",
      "The Fig. 11 sweep: plectoneme branches (cases/plectoneme.toml) for several slendernesses L/2R,\n"
      "each followed in the end rotation from the untwisted rod through the end loop into the ply;\n"
      "DIR/plectoneme_<L/2R>.csv per branch (index, turns, T_ext, helix_angle, helix_radius rho,\n"
      "T_rho2_over_EI and eq61 side by side, m3 and m3_eq58b, H_A, H_B, self_distance, ...),\n"
      "wall time and points per second on stdout. Long: minutes to hours per slenderness; --resume\n"
      "continues a killed sweep.");
  plectonemes_cmd->add_option("--case", plect.case_path, "The plectoneme case file")->capture_default_str()
      ->check(CLI::ExistingFile);
  plectonemes_cmd->add_option("--slenderness", plect.slenderness, "Slendernesses L/2R")->delimiter(',')
      ->capture_default_str();
  plectonemes_cmd->add_option("--turns", plect.turns, "Largest end rotation (turns), one per slenderness")
      ->delimiter(',')->capture_default_str();
  plectonemes_cmd->add_option("--out", plect.out_dir, "Output folder (created)")->capture_default_str();
  plectonemes_cmd
      ->add_option("--from-ply", plect.from_ply,
                   "Slendernesses reached from the ply of the previous one in --slenderness (by continuation in\n"
                   "L/2R, then in the barrier's log_softness), then followed in turns up to their --turns and down\n"
                   "to --turns-min: at L/2R = 1000 this is how the ply is reached (docs/plectonemes.md). With --hard-from,\n"
                   "from the previous one's exact ply, continued in L/2R with exact contact")
      ->delimiter(',')
      ->capture_default_str();
  plectonemes_cmd->add_option("--turns-min", plect.turns_min, "Where --from-ply branches end on the way down")
      ->capture_default_str();
  plectonemes_cmd->add_option("--ply-log-softness", plect.ply_log_softness,
                              "log10 of the self-contact barrier's strength on --from-ply branches")
      ->capture_default_str();
  plectonemes_cmd->add_flag("--resume", plect.resume,
                            "Pick a killed sweep up where it stopped: finished branches are kept, an unfinished one\n"
                            "continues from its last point (DIR/plectoneme_<L/2R>.csv.state.json)");
  plectonemes_cmd
      ->add_option("--max-step", plect.max_step,
                   "Largest pseudo-arclength step at L/2R = 100 (scaled by (L/2R / 100)^2 with the forces)")
      ->capture_default_str();
  plectonemes_cmd
      ->add_option("--reuse-jacobian", plect.reuse_jacobian,
                   "A point whose chord iterations converged within this many keeps the previous point's\n"
                   "Jacobian (-1: every point computes its own)")
      ->check(CLI::Range(-1, 100))
      ->capture_default_str();
  plectonemes_cmd->add_flag("!--full-newton", plect.modified_newton,
                            "A new Jacobian at every corrector iteration, with shorter steps (by default the\n"
                            "corrector keeps a Jacobian while the residual halves, on longer steps)");
  plectonemes_cmd
      ->add_option("--hard-contact-every", plect.hard_contact_every,
                   "Re-solve ply points this many turns apart (and each branch's end) with hard, complementarity\n"
                   "self-contact (Ipopt on the discretised half rod, seeded by the barrier solution): strands\n"
                   "exactly 2R apart, contact forces the constraints' multipliers; DIR/plectoneme_<L/2R>_hard.csv\n"
                   "(0: off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  plectonemes_cmd->add_option("--hard-spacing", plect.hard_spacing, "Node spacing of the hard-contact rod, in R")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  plectonemes_cmd
      ->add_option("--hard-from", plect.hard_from,
                   "Exact self-contact in the shooting core from this many turns (0: the barrier throughout):\n"
                   "the barrier branch stops there, its ply is re-solved with the strands touching exactly\n"
                   "(contact points and the line of the ply, read off the discretised solution) and followed\n"
                   "in turns up to --turns and down to --turns-min, each leg stopping where complementarity\n"
                   "would fail; DIR/plectoneme_<L/2R>_ply.csv (T_ext R^2/EI beside eq. 61 with R itself).\n"
                   "With it, --from-ply slendernesses are reached from the previous one's exact ply instead\n"
                   "(continued in L/2R with exact contact; no barrier branch): the all-exact Fig. 11 is\n"
                   "--hard-from 5 --from-ply 200,500,1000 (Ipopt, which seeds the contact set, fails at 500)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  plectonemes_cmd
      ->add_option("--ply-max-step", plect.ply_max_step,
                   "Largest pseudo-arclength step of the exact ply's legs at L/2R = 100 (scaled like --max-step)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  plectonemes_cmd
      ->add_option("--sensitivity-tol", plect.sensitivity_tol,
                   "Tolerance of the variational equations (the Jacobian) of the barrier branches and of the exact "
                   "ply's legs, integrated apart from the state, which keeps the case's 1e-13: Newton and the "
                   "tangents need the Jacobian to a few digits, and at 1e-8 the sweep is 2.25 times faster with the "
                   "branch ends the same to 10-12 digits (0: the case's; the exact ply's first solve from its seed "
                   "always keeps the case's)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();

  SweepArguments sweep;
  auto* sweep_cmd = app.add_subcommand(
      "sweep",
      "Run the jobs of a sweep file (solve or equilibria over a grid or list of parameter values):\n"
      "DIR/jobs/<id>/ per job (result.json, profiles), DIR/index.csv (one row per job, in job order)\n"
      "and DIR/times.csv (wall times). Under mpirun/srun the jobs are shared out over the ranks\n"
      "(a manager hands them out, largest first) with the same files; see docs/sweeps.md");
  sweep_cmd->footer(
      "Exit status: 0 every job has its result (failed jobs are rows with their status), 2 refused.\n\n"
      "Examples:\n"
      "  kirchhoff sweep sweeps/wall_phase_diagram.toml --out wall_phase\n"
      "  mpirun -n 8 kirchhoff sweep sweeps/wall_phase_diagram.toml --out wall_phase --resume");
  sweep_cmd->add_option("spec", sweep.spec_path, "Sweep file (TOML)")->required()->check(CLI::ExistingFile);
  sweep_cmd->add_option("--out", sweep.out_dir, "Output folder (created)")->capture_default_str();
  sweep_cmd->add_flag("--resume", sweep.resume,
                      "Go on with the sweep in --out: finished jobs are kept, the others run (a sweep killed\n"
                      "and resumed leaves the same files as one never interrupted)");
  sweep_cmd->add_flag("--manager-only", sweep.manager_only,
                      "Under MPI: rank 0 only hands out jobs (by default it runs jobs too, on a thread)");
  sweep_cmd->add_flag("--quiet", sweep.quiet, "No progress line per job on stderr");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : kExitBadInput;
  }
  try {
    if (*solve_cmd) {
      solve.seed.ipopt = solve_seed == "ipopt";
      return run_solve(solve);
    }
    if (*check_cmd) return run_check(check_path, check_overrides, check_solver);
    if (*reproduce_cmd) return run_reproduce(out_dir, cases_dir, reproduce_full);
    if (*continue_cmd) {
      cont.seed.ipopt = continue_seed == "ipopt";
      return run_continue(cont);
    }
    if (*vibrate_cmd) return run_vibrate(vib);
    if (*equilibria_cmd) return run_equilibria(eq);
    if (*plectonemes_cmd) return run_plectonemes(plect);
    if (*sweep_cmd) return run_sweep(sweep);
  } catch (const std::exception& e) {
    // The commands report the errors they expect; anything else still ends with a message
    // rather than an abort.
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  return kExitBadInput;
}

// kirchhoff: equilibria of elastic rods by shooting, checked against Noether's invariants.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <sstream>
#include <iostream>
#include <string>

#include "continue_command.hpp"
#include "plectonemes_command.hpp"
#include "reproduce_command.hpp"
#include "solve_command.hpp"
#include "vibrate_command.hpp"
#include "equilibria_command.hpp"
#include "sweep_command.hpp"

#include "kirchhoff/jobs/process_memory.hpp"

namespace {

using namespace kirchhoff::cli;

// A number above `bound` (or at it, with `inclusive`), refused in words that say so.
CLI::Validator at_least(const std::string& option, double bound, bool inclusive) {
  return CLI::Validator(
      [=](const std::string& text) {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        const bool number = !text.empty() && end == text.c_str() + text.size();
        if (number && (inclusive ? v >= bound : v > bound)) return std::string();
        std::ostringstream why;
        why << option << " must be " << (inclusive ? ">= " : "> ") << bound << ", got " << text;
        return why.str();
      },
      "");
}

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

// The options every command that loads one case shares: the case file, --set and --solver.
// `set_help` replaces --set's description where the command gives it more meaning (solve).
template <class Arguments>
void add_case_options(CLI::App* command, Arguments* args, const std::string& case_help = "Case file (TOML)",
                      const std::string& set_help = "Override a parameter: NAME=VALUE (repeatable)") {
  command->add_option("case", args->case_path, case_help)->required()->check(CLI::ExistingFile);
  command->add_option("--set", args->overrides, set_help);
  command->add_option("--solver", args->solver,
                      "Override a [solver] key: KEY=VALUE, e.g. tolerance=1e-10, stepper=dopri5 (repeatable; "
                      "checked as in the file)");
}

// --phase-condition (solve and continue).
void add_phase_condition_option(CLI::App* command, std::string* phase_condition, const std::string& help) {
  command->add_option("--phase-condition", *phase_condition, help)->check(CLI::IsMember({"none", "axial"}));
}

// The arguments of `check` and `reproduce`, whose run functions take them one by one.
struct CheckArguments {
  std::string case_path;
  std::vector<std::string> overrides;
  std::vector<std::string> solver;
};
struct ReproduceArguments {
  std::string out_dir = "out";
  std::string cases_dir = KIRCHHOFF_DEFAULT_CASES_DIR;
  bool full = false;
};

// Each command declares its options into its arguments and returns its subcommand, which main
// asks whether it was given. *seed receives --seed ("guess" or "ipopt").
CLI::App* add_solve_command(CLI::App& app, SolveArguments* args, std::string* seed) {
  auto* command = app.add_subcommand("solve", "Solve one equilibrium and report derived quantities and invariants");
  add_case_options(command, args, "Case file (TOML)",
                   "Override a parameter: NAME=VALUE (repeatable). The equilibrium at the new values is\n"
                   "reached by continuation from the case's own (a homotopy in all changed parameters\n"
                   "together), so it lies on the branch the case's guess starts; a fold on the way is\n"
                   "reported (exit 1), never jumped");
  command->add_flag("--direct", args->direct,
                    "Newton from the case's guess at the --set values instead of the homotopy (whichever\n"
                    "equilibrium attracts the guess)");
  command->add_flag("--json", args->json,
                    "Print one JSON object: status, iterations, residual, parameters, derived, invariants, ends");
  command->add_option("--profile", args->profile_path,
                      "Write the solution along the rod as CSV: s, r, d1, d2, d3, n, m, u, H, m3, n.m, dH/ds");

  add_seed_options(command, seed, &args->seed);
  command
      ->add_option("--max-seconds", args->max_seconds,
                   "Wall-clock limit of the solve in seconds (0: none); past it the solve stops with status "
                   "time_limit, exit 1")
      ->capture_default_str();
  add_phase_condition_option(command, &args->phase_condition,
                             "Override [solver] phase_condition: 'axial' selects one buckled solution of an isotropic\n"
                             "twisted rod out of its circle of rotated copies (singular on the straight rod)");
  return command;
}

CLI::App* add_check_command(CLI::App& app, CheckArguments* args) {
  auto* command = app.add_subcommand("check", "Validate a case file without solving");
  add_case_options(command, args);
  return command;
}

CLI::App* add_continue_command(CLI::App& app, ContinueArguments* args, std::string* seed) {
  auto* command = app.add_subcommand(
      "continue",
      "Follow a branch of equilibria in one parameter (pseudo-arclength), locating folds and branch points;\n"
      "one CSV row per point, flushed as it goes; --resume picks up a killed run");
  add_case_options(command, args);
  command->add_option("--param", args->parameter, "Parameter to continue in (from [parameters])")->required();
  command->add_option("--to", args->to, "Stop when the parameter reaches this value (on the starting branch: a branch switched onto with "
                      "--switch-at-bp runs to an --event or --max-points)")
      ->each([args](const std::string&) { args->has_to = true; });
  command->add_option("--direction", args->direction,
                      "Which way the parameter goes first when there is no --to: 1 (up) or -1 (down)")
      ->capture_default_str();
  command->add_option("--step", args->step, "Initial pseudo-arclength step (at most --max-step)")->capture_default_str();
  command->add_option("--min-step", args->min_step, "Smallest step before giving up")->capture_default_str();
  command->add_option("--max-step", args->max_step, "Largest step")->capture_default_str();
  command->add_option("--max-points", args->max_points, "Largest number of points of each branch (a switched branch counts its own)")->capture_default_str();
  command->add_option("--switch-at-bp", args->switch_at_bp,
                      "Switch onto the branch bifurcating at the K-th branch point found, K >= 1 (0, the default:\n"
                      "no switch; double branch points of isotropic twisted rods switch with the axial phase\n"
                      "condition)");
  command->add_flag("--no-stability", args->no_stability,
                    "Skip the stability index of every point (column stability_index left empty)");
  command->add_flag("--no-branch-points", args->no_branch_points,
                    "Do not look for branch points: their test functions cost an SVD per point, most of a\n"
                    "run on multiple-shooting cases of hundreds of unknowns (plectonemes); folds are still found");
  command
      ->add_option("--start-from", args->start_from,
                   "Start from the last row another run wrote (its CSV's .state.json; the endpoint at --to\n"
                   "included), e.g. a ply followed in turns, continued now in slenderness: that run's\n"
                   "parameter at the point's value, its --set values kept (this command's --set wins), and\n"
                   "its active contact set on cases with obstacles; the values are printed")
      ->check(CLI::ExistingFile);
  command->add_option("--start-param", args->start_param,
                      "The parameter of a --start-from state file that does not name it");
  add_seed_options(command, seed, &args->seed);
  command->add_option("--side", args->switch_side, "Which side of the bifurcating branch (with --switch-at-bp): 1 or -1")
      ->capture_default_str();
  command->add_option("--event", args->stop_events, "Stop when a derived quantity crosses a value: NAME=VALUE");
  command->add_option("--record", args->record_events, "Record (without stopping) a crossing: NAME=VALUE");
  command->add_option("--out", args->out_path, "Branch CSV (a .state.json file is kept beside it)")
      ->capture_default_str();
  command->add_option("--profiles", args->profiles_dir, "Write each point's profile CSV into this folder");
  command->add_option("--samples", args->samples,
                      "Profile samples per point (invariants, derived quantities); not the case's [output] "
                      "samples, which solve uses")
      ->capture_default_str();
  command->add_flag("--resume", args->resume, "Resume the run whose CSV is --out from its last written point");
  command->add_flag("--deflate", args->deflate,
                    "Follow every branch through the equilibria found at the start by deflation (as\n"
                    "`equilibria` lists them); branch K of the CSV starts at the K-th by energy. Not with\n"
                    "--resume, --start-from, --switch-at-bp or --seed");
  command->add_option("--deflate-max", args->deflate_max, "At most this many equilibria (and branches) with --deflate")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  command
      ->add_option("--max-seconds", args->max_seconds,
                   "Wall-clock limit of the run in seconds (0: none); it stops after the last point written, "
                   "with time_limit and exit 1, and --resume goes on")
      ->capture_default_str();
  command
      ->add_option("--checkpoint", args->checkpoint_seconds,
                   "Save the state file (for --resume) at most once per this many seconds (0: after every\n"
                   "point); a resumed run recomputes the rows after the last save, the same rows")
      ->capture_default_str();
  add_phase_condition_option(command, &args->phase_condition, "As for solve");
  return command;
}

CLI::App* add_equilibria_command(CLI::App& app, EquilibriaArguments* args) {
  auto* command = app.add_subcommand(
      "equilibria",
      "List the distinct equilibria at one set of parameters, by deflated Newton, sorted by energy,\n"
      "with stability index, contact set, derived quantities and invariants");
  command->footer(
      "Starts from the case's guess, its mirror images, perturbations along the low modes of every\n"
      "equilibrium found and, for planar rods clamped or pinned at both ends, Ipopt's discretised minimisers;\n"
      "deflation keeps Newton from converging to an equilibrium already found. Equilibria are\n"
      "compared by their profiles relative to L; every one listed has converged and, with obstacles,\n"
      "satisfies 0 <= gap perp force >= 0. The energy is the elastic energy plus the potential of the\n"
      "field and of the given end loads (-F.r, -M theta). See docs/equilibria.md. Exit status: 0 at\n"
      "least one equilibrium, 1 none found, 2 input refused.\n\n"
      "Examples:\n"
      "  kirchhoff equilibria cases/euler_column.toml --set P=50\n"
      "  kirchhoff equilibria cases/wall.toml --set Delta=0.033 --max 6 --json --profiles wall_eq/");
  add_case_options(command, args);
  // (Its range, [1, 1000], is the library's check: EquilibriaOptions::validate, as Python's.)
  command->add_option("--max", args->max_equilibria, "Stop once this many distinct equilibria are found (1 to 1000)")
      ->capture_default_str();
  command->add_flag("--json", args->json,
                    "Print JSON: {\"equilibria\": [solve's object with \"energy\", \"rank\", \"found_by\"], "
                    "\"rejected\", \"stopped_because\", \"log\"}");
  command->add_option("--profiles", args->profiles_dir,
                      "Write each equilibrium's profile as DIR/equilibrium_K.csv (K as in the table)");
  command
      ->add_option("--max-seconds", args->max_seconds, "Wall-clock limit of the search in seconds (0: none)")
      ->capture_default_str();
  return command;
}

CLI::App* add_vibrate_command(CLI::App& app, VibrateArguments* args) {
  auto* command = app.add_subcommand(
      "vibrate",
      "Small-amplitude vibrations about a planar equilibrium (section 9, eqs. B.4): the lowest\n"
      "eigenfrequencies omega_k and mode shapes of qbar = (xbar, ybar, thetabar, mbar, nbar_x, nbar_y),\n"
      "with the invariant H_vib of eq. (95b) along each mode");
  command->footer(
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
  add_case_options(command, args, "Case file (TOML) of a planar rod");
  // (CLI11's PositiveNumber refused 0 saying "not in range 0 to 1.8e308": the bound said here.)
  command->add_option("--modes", args->modes, "Number of lowest frequencies to find (>= 1)")
      ->capture_default_str()
      ->check(at_least("--modes", 1.0, true));
  command->add_option("--rho-s", args->rho_s, "Mass per unit length rho S (uniform, > 0)")
      ->capture_default_str()
      ->check(at_least("--rho-s", 0.0, false));
  command->add_option("--out", args->out_path,
                      "Write JSON {\"frequencies\": [...], \"modes\": [{\"omega\", \"H_vib_spread\", ...}]}");
  command->add_option("--profiles", args->profiles_dir,
                      "Write each mode as DIR/mode_K.csv (unstable ones DIR/unstable_mode_K.csv): s, xbar, ybar, "
                      "thetabar, mbar, nbarx, nbary, H_vib");
  command->add_flag("--json", args->json, "Print the JSON on stdout instead of the table");
  return command;
}

CLI::App* add_reproduce_command(CLI::App& app, ReproduceArguments* args) {
  auto* command = app.add_subcommand(
      "reproduce", "Recompute the paper's results the toolkit covers: DIR/report.md, DIR/report.json, DIR/profiles/*.csv");
  command->add_option("--out", args->out_dir, "Output folder (created)")->capture_default_str();
  command->add_flag("--full", args->full,
                    "Fig. 11 with all four slendernesses (L/2R = 100, 200, 500 to 10, 20, 20 turns; 1000 from\n"
                    "the 500 ply to 50 and down to 4) and the ply with exact contact at 100, 200 and 500 to\n"
                    "10, 20 and 20 turns: about 20 minutes instead of 2");
  command->add_option("--cases", args->cases_dir, "Folder of the case files")->capture_default_str()->check(CLI::ExistingDirectory);
  return command;
}

CLI::App* add_plectonemes_command(CLI::App& app, PlectonemesArguments* args) {
  args->case_path = std::string(KIRCHHOFF_DEFAULT_CASES_DIR) + "/plectoneme.toml";
  auto* command = app.add_subcommand(
      "plectonemes",
      "The Fig. 11 sweep: plectoneme branches (cases/plectoneme.toml) for several slendernesses L/2R,\n"
      "each followed in the end rotation from the untwisted rod through the end loop into the ply;\n"
      "DIR/plectoneme_<L/2R>.csv per branch (index, turns, T_ext, helix_angle, helix_radius rho,\n"
      "T_rho2_over_EI and eq61 side by side, m3 and m3_eq58b, H_A, H_B, self_distance, ...),\n"
      "wall time and points per second on stdout. Long: minutes to hours per slenderness; --resume\n"
      "continues a killed sweep.");
  command->add_option("--case", args->case_path, "The plectoneme case file")->capture_default_str()
      ->check(CLI::ExistingFile);
  command->add_option("--slenderness", args->slenderness, "Slendernesses L/2R")->delimiter(',')
      ->capture_default_str();
  command->add_option("--turns", args->turns, "Largest end rotation (turns), one per slenderness")
      ->delimiter(',')->capture_default_str();
  command->add_option("--out", args->out_dir, "Output folder (created)")->capture_default_str();
  command
      ->add_option("--from-ply", args->from_ply,
                   "Slendernesses reached from the ply of the previous one in --slenderness (by continuation in\n"
                   "L/2R, then in the barrier's log_softness), then followed in turns up to their --turns and down\n"
                   "to --turns-min: at L/2R = 1000 this is how the ply is reached (docs/plectonemes.md). With --hard-from,\n"
                   "from the previous one's exact ply, continued in L/2R with exact contact")
      ->delimiter(',')
      ->capture_default_str();
  command->add_option("--turns-min", args->turns_min, "Where --from-ply branches end on the way down")
      ->capture_default_str();
  command->add_option("--ply-log-softness", args->ply_log_softness,
                      "log10 of the self-contact barrier's strength on --from-ply branches")
      ->capture_default_str();
  command->add_flag("--resume", args->resume,
                    "Pick a killed sweep up where it stopped: finished branches are kept, an unfinished one\n"
                    "continues from its last point (DIR/plectoneme_<L/2R>.csv.state.json)");
  command
      ->add_option("--max-step", args->max_step,
                   "Largest pseudo-arclength step at L/2R = 100 (scaled by (L/2R / 100)^2 with the forces)")
      ->capture_default_str();
  command
      ->add_option("--reuse-jacobian", args->reuse_jacobian,
                   "A point whose chord iterations converged within this many keeps the previous point's\n"
                   "Jacobian (-1: every point computes its own)")
      ->check(CLI::Range(-1, 100))
      ->capture_default_str();
  command->add_flag("!--full-newton", args->modified_newton,
                    "A new Jacobian at every corrector iteration, with shorter steps (by default the\n"
                    "corrector keeps a Jacobian while the residual halves, on longer steps)");
  command
      ->add_option("--hard-contact-every", args->hard_contact_every,
                   "Re-solve ply points this many turns apart (and each branch's end) with hard, complementarity\n"
                   "self-contact (Ipopt on the discretised half rod, seeded by the barrier solution): strands\n"
                   "exactly 2R apart, contact forces the constraints' multipliers; DIR/plectoneme_<L/2R>_hard.csv\n"
                   "(0: off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_option("--hard-spacing", args->hard_spacing, "Node spacing of the hard-contact rod, in R")
      ->check(CLI::Range(0.01, 1.0))
      ->capture_default_str();
  command
      ->add_option("--hard-from", args->hard_from,
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
  command
      ->add_option("--ply-max-step", args->ply_max_step,
                   "Largest pseudo-arclength step of the exact ply's legs at L/2R = 100 (scaled like --max-step)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--sensitivity-tol", args->sensitivity_tol,
                   "Tolerance of the variational equations (the Jacobian) of the barrier branches and of the exact "
                   "ply's legs, integrated apart from the state, which keeps the case's 1e-13: Newton and the "
                   "tangents need the Jacobian to a few digits, and at 1e-8 the sweep is 2.25 times faster with the "
                   "branch ends the same to 10-12 digits (0: the case's; the exact ply's first solve from its seed "
                   "always keeps the case's)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return command;
}

CLI::App* add_sweep_command(CLI::App& app, SweepArguments* args) {
  auto* command = app.add_subcommand(
      "sweep",
      "Run the jobs of a sweep file (solve or equilibria over a grid or list of parameter values):\n"
      "DIR/jobs/<id>/ per job (result.json, profiles), DIR/index.csv (one row per job, in job order)\n"
      "and DIR/times.csv (wall times). Under mpirun/srun the jobs are shared out over the ranks\n"
      "(a manager hands them out, largest first) with the same files; see docs/sweeps.md");
  command->footer(
      "Exit status: 0 every job has its result (failed jobs are rows with their status), 2 refused.\n\n"
      "Examples:\n"
      "  kirchhoff sweep sweeps/wall_phase_diagram.toml --out wall_phase\n"
      "  mpirun -n 8 kirchhoff sweep sweeps/wall_phase_diagram.toml --out wall_phase --resume");
  command->add_option("spec", args->spec_path, "Sweep file (TOML)")->required()->check(CLI::ExistingFile);
  command->add_option("--out", args->out_dir, "Output folder (created)")->capture_default_str();
  command->add_flag("--resume", args->resume,
                    "Go on with the sweep in --out: finished jobs are kept, the others run (a sweep killed\n"
                    "and resumed leaves the same files as one never interrupted)");
  command->add_flag("--manager-only", args->manager_only,
                    "Under MPI: rank 0 only hands out jobs (by default it runs jobs too, on a thread)");
  command->add_flag("--quiet", args->quiet, "No progress line per job on stderr");
  return command;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace kirchhoff::cli;
  // Long rods' Jacobians (over 100 MB) are reused from the heap instead of mapped afresh for
  // each one (process_memory.hpp): the exact ply at L/2R = 1000 in about two thirds of the time.
  kirchhoff::keep_freed_memory_for_reuse();
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

  // Declared in this order, so listed in this order by --help.
  SolveArguments solve;
  std::string solve_seed = "guess";
  auto* solve_cmd = add_solve_command(app, &solve, &solve_seed);
  CheckArguments check;
  auto* check_cmd = add_check_command(app, &check);
  ContinueArguments cont;
  std::string continue_seed = "guess";
  auto* continue_cmd = add_continue_command(app, &cont, &continue_seed);
  EquilibriaArguments eq;
  auto* equilibria_cmd = add_equilibria_command(app, &eq);
  VibrateArguments vib;
  auto* vibrate_cmd = add_vibrate_command(app, &vib);
  ReproduceArguments reproduce;
  auto* reproduce_cmd = add_reproduce_command(app, &reproduce);
  PlectonemesArguments plect;
  auto* plectonemes_cmd = add_plectonemes_command(app, &plect);
  SweepArguments sweep;
  sweep.command_line = argv;
  auto* sweep_cmd = add_sweep_command(app, &sweep);

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
    if (*check_cmd) return run_check(check.case_path, check.overrides, check.solver);
    if (*reproduce_cmd) return run_reproduce(reproduce.out_dir, reproduce.cases_dir, reproduce.full);
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

// The Fig. 11 sweep (`kirchhoff plectonemes`, Python's kirchhoff.plectonemes): plectoneme branches
// of cases/plectoneme.toml for several slendernesses, each followed in the end rotation from the
// untwisted rod (or from a thicker rod's ply), written as CSV rows of T_ext rho^2/EI against the
// helical angle beside eq. (61), resumable after a kill (run_state.hpp). The physics of such runs
// (forces and tolerances scaled with the slenderness, the ply handed to exact contact) is here;
// progress lines go to a callback (PlectonemeRunOptions::progress) that the CLI sets to print.
#pragma once

#include <functional>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace kirchhoff {

// Largest pseudo-arclength step at L/2R = 100: the unknowns are dominated by forces of 1e2-1e4
// there, so steps of tens are small.
inline constexpr double kPlectonemeMaxStep = 60.0;
inline constexpr int kPlectonemeReuseJacobian = 8;
inline constexpr double kPlyMaxStep = 120.0;
// The variational equations of the barrier branches and of the exact ply's legs at this tolerance
// (the state stays at the case's 1e-13): the whole sweep 703 s -> 312 s, the branch ends the same
// to 10-12 digits.
inline constexpr double kPlectonemeSensitivityTol = 1e-8;

struct PlectonemeBranchSummary {
  int points = 0;
  double seconds = 0.0;
  std::string stop;                         // the continuation's stop reason
  int refused_steps = 0;                    // steps that would have carried the rod through itself
  std::map<std::string, double> last;       // the CSV columns at the last point with a ply
  std::vector<std::map<std::string, double>> ply;  // the same at every point with a ply, in order
  // The ply with exact contact in the shooting core (--hard-from): its points, time, stops and,
  // at every point with a ply, its CSV columns.
  int hard_ply_points = 0;
  double hard_ply_seconds = 0.0;
  std::string hard_ply_stop;
  std::vector<std::map<std::string, double>> hard_ply;
  int hard_points = 0;                      // ply points re-solved with hard self-contact
  int hard_failures = 0;                    // of those, the ones Ipopt did not solve (rows say why)
  double hard_seconds = 0.0;                // time spent in them
};

struct PlectonemeRunOptions {
  // Where progress lines go ("  L/2R = 200  point 50  turns = 3.1", the handover's steps, each
  // slenderness's start), without their newline; unset: nowhere. The CLI prints them on stderr.
  std::function<void(const std::string&)> progress;
  int progress_every = 0;                 // a progress line every this many points (0: none)
  double max_step = kPlectonemeMaxStep;   // at L/2R = 100, scaled with the forces (1/R^2)
  // A point whose chord iterations converged within this many keeps the previous Jacobian
  // (ContinuationOptions::reuse_jacobian_iterations; -1: every point computes its own).
  int reuse_jacobian = kPlectonemeReuseJacobian;
  // The corrector keeps a matrix while the residual halves (ContinuationOptions::modified_newton),
  // with steps that grow while it takes up to 10 iterations; false: a matrix per iteration.
  bool modified_newton = true;
  // Continue a killed run from csv_path's state file (csv_path + ".state.json"); a branch whose
  // CSV ends at its endpoint is left as it is. Without a state file the branch starts afresh.
  bool resume = false;
  // log10 of the self-contact barrier's strength on a branch reached from a thicker rod's ply (see
  // follow_from_ply): at L/2R = 1000 the case's -4 lets the thinner ply's strands 36 % of R apart at
  // 20 turns; -5 gives 20 % there and 5 % at 50 turns, like the case's -4 at L/2R = 100-500. (-6
  // gave 6 % at 20 turns; that run's steps collapsed near 29 turns, before the tolerances were
  // scaled with the forces - not retried since.)
  double ply_log_softness = -5.0;
  // > 0: ply points at least this many turns apart (and each branch's end) are re-solved with
  // hard, complementarity self-contact (hard_self_contact.hpp) at node spacing hard_spacing R,
  // into csv_path with "_hard.csv" for ".csv".
  double hard_contact_every = 0.0;
  double hard_spacing = 0.25;
  // > 0 (and below the branch's largest turns): the barrier branch stops at this many turns and
  // hands its ply to exact contact in the shooting core (hard_ply_definition): the contact set read
  // off the discretised hard solution (Ipopt, at hard_spacing R), the shooting problem solved and
  // followed in turns up to the branch's largest turns and down to hard_turns_min, into csv_path
  // with "_ply.csv" for ".csv". Each leg stops where complementarity would fail (the contact set
  // changes there; not followed).
  double hard_from = 0.0;
  double hard_turns_min = 4.0;
  // Largest pseudo-arclength step of the exact ply's legs at L/2R = 100, scaled with the forces:
  // its unknowns hold 2-3 times the barrier's segments, so the same change of the ply is a longer
  // step (L/2R = 200, 5 -> 8 and 5 -> 4.5 turns: 279 points in 41 s at 60, 152 in 21 s at 120,
  // 94 in 20 s at 240, the end points the same to 11 digits).
  double ply_max_step = kPlyMaxStep;
  // IntegratorOptions::sensitivity_tol of the barrier branches and of the exact ply's legs (0: the
  // case's); the exact ply's first solve from its seed keeps the case's.
  double sensitivity_tol = kPlectonemeSensitivityTol;
  // Called after every point is written (the Python module checks for Ctrl-C there); it may
  // throw SweepStopped to stop the run, which a resume then continues.
  std::function<void()> after_point;
};

// What after_point throws to stop a sweep. Not a std::exception, so that the sweep's reports of a
// failed branch ("L/2R = ...: ...") let it through to the caller.
struct SweepStopped {};

// Follows cases/plectoneme.toml (at `case_path`) with slenderness set, from turns = 0 to
// turns_max, writing one CSV row per point to csv_path (flushed as it goes) and the state to
// resume from beside it. Throws on a case that does not solve at turns = 0. A resumed run's
// summary counts (and its `ply` holds) only the points computed after resuming.
PlectonemeBranchSummary follow_plectoneme_branch(const std::string& case_path, double slenderness, double turns_max,
                                                 const std::string& csv_path, const PlectonemeRunOptions& options);

// A slenderness reached the way an experimenter thins a rod - at L/2R = 1000 faster than from the
// untwisted rod (which, with steps checked for passing the rod through itself, reaches the same
// ply at 20 turns in 1419 s against 897 s for this whole leg; docs/plectonemes.md): starts from the last point
// of a thicker rod's branch (base_state_path, a ply at its largest turns), continues it in
// slenderness to `slenderness` and in log_softness to options.ply_log_softness, then in turns up
// to turns_max (CSV branch 0) and from the same start down to turns_min (branch 1). The start is
// saved beside the CSV (csv_path + ".start.json"), so a resumed run skips those moves, and
// resumes the turns leg it was in.
PlectonemeBranchSummary follow_from_ply(const std::string& case_path, const std::string& base_state_path,
                                        double base_slenderness, double slenderness, double turns_min,
                                        double turns_max, const std::string& csv_path,
                                        const PlectonemeRunOptions& options);

// With --hard-from, a slenderness in --from-ply is reached from the thicker rod's exact ply
// instead (no barrier branch, no Ipopt: at L/2R = 500 Ipopt fails): its start (base_start_path,
// the thicker rod's _ply.csv.start.json) is continued in slenderness with exact contact, every
// step checked for complementarity (an event there is a failure), re-segmented by length at the
// new R and solved, then followed in turns up to turns_max and down to turns_min into hard_csv
// (the start saved beside it).
PlectonemeBranchSummary follow_hard_from_ply(const std::string& case_path, const std::string& base_start_path,
                                             double base_slenderness, double slenderness, double turns_min,
                                             double turns_max, const std::string& hard_csv,
                                             const PlectonemeRunOptions& options);

// The sweep: the options of every branch (PlectonemeRunOptions, given to each as they are, with
// progress lines every 50 points) and which branches to follow.
struct PlectonemesArguments : PlectonemeRunOptions {
  PlectonemesArguments() { progress_every = 50; }
  std::string case_path;
  std::vector<double> slenderness{100, 200, 500, 1000};
  std::vector<double> turns{10, 20, 20, 50};
  // Slendernesses reached from the ply of the one before them in the list (follow_from_ply).
  std::vector<double> from_ply{1000};
  // Where branches reached from a ply end on the way down, and the exact ply's legs
  // (PlectonemeRunOptions::hard_turns_min, which the sweep sets to it).
  double turns_min = 4.0;
  std::string out_dir = "plectonemes";
};

// What a sweep computed for one slenderness: the CSV of its barrier branch (empty for one reached
// from a thicker rod's exact ply) and of its exact ply (empty without hard_from), and its summary.
struct PlectonemeSweepBranch {
  double slenderness = 0.0;
  std::string barrier_csv, ply_csv;
  PlectonemeBranchSummary summary;
};

struct PlectonemeSweep {
  std::vector<PlectonemeSweepBranch> branches;
  int points = 0;  // computed by this run (a resumed run counts only its own)
  double seconds = 0.0;
};

// The sweep: each slenderness in turn (follow_plectoneme_branch, follow_from_ply or
// follow_hard_from_ply), progress lines to args.progress and a line per finished slenderness on
// `report`.
// Throws CaseError, before anything runs, for arguments that cannot make a sweep (lists of
// different lengths, a slenderness from a ply the sweep would not have), and std::runtime_error
// ("L/2R = <slenderness>: ...") when a branch fails; the branches before it stay written.
PlectonemeSweep sweep_plectonemes(const PlectonemesArguments& args, std::ostream& report);

}  // namespace kirchhoff

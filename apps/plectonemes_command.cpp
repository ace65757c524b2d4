#include "plectonemes_command.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "kirchhoff/analytic.hpp"
#include "kirchhoff/case_file.hpp"
#include "kirchhoff/continuation.hpp"
#include "run_state.hpp"

namespace kirchhoff::cli {
namespace {

// Columns of a plectoneme branch: the case's measures, then what Fig. 11 plots and the closed
// forms beside them (NaN where there is no ply, theta outside (0, pi/4)).
const std::vector<std::string> kMeasured = {"T_ext", "helix_angle", "helix_radius", "m3", "contact_pressure",
                                            "contact_start", "contact_end", "H_A", "H_B", "self_distance",
                                            "loop_clearance"};

std::map<std::string, double> columns(const ContinuationPoint& p, double EI) {
  std::map<std::string, double> c;
  for (const auto& name : kMeasured) c[name] = p.derived.count(name) ? p.derived.at(name) : NAN;
  const double theta = c["helix_angle"], rho = c["helix_radius"];
  const bool ply = theta > 0.0 && theta < 0.25 * M_PI && rho > 0.0;
  // rho, the strands' distance to the axis, is the helix radius R of eqs. (58)-(61).
  c["T_rho2_over_EI"] = c["T_ext"] * rho * rho / EI;
  c["eq61"] = ply ? analytic::plectoneme_end_tension(theta, 1.0, 1.0) : NAN;  // T rho^2/EI by (61)
  c["m3_eq58b"] = ply ? analytic::helix_twisting_moment(theta, EI, rho) : NAN;
  return c;
}

// The CSV ends with its endpoint row: the branch was followed to its target.
bool branch_complete(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last.find(",endpoint,") != std::string::npos;
}

// How a plectoneme branch is followed in `turns`, at any slenderness.
ContinuationOptions continuation_options(const Case& c, double slenderness, double turns_max, double max_step,
                                         int reuse_jacobian) {
  ContinuationOptions o;
  o.parameter = "turns";
  o.target = turns_max;
  // Forces, and with them the unknowns and the pseudo-arclength, scale as EI/R^2.
  const double scale = (slenderness / 100.0) * (slenderness / 100.0);
  o.initial_step = 1.0 * scale;
  o.max_step = max_step * scale;
  o.max_points = 20000;
  o.derived = c.derived;
  o.samples = 10 * static_cast<int>(slenderness) + 1;  // R/10 apart on the half rod: the ply's pitch is 10-30 R
  // A point's Jacobian (14 sensitivities per segment) and measures cost tens of residual
  // evaluations: longer steps that take up to 9 chord iterations are cheaper per turn, and a
  // point whose chord iterations converged keeps the previous matrix. Measured at L/2R = 200 to
  // 10 turns: 215 s -> 77 s, the same end point to 12 digits.
  o.corrector_max_iterations = 12;
  o.grow_iterations = 6;
  o.shrink_iterations = 10;
  o.reuse_jacobian_iterations = reuse_jacobian;
  o.detect_branch_points = false;  // the barrier's stiffness turns the determinant's sign into noise
  return o;
}

}  // namespace

PlectonemeBranchSummary follow_plectoneme_branch(const std::string& case_path, double slenderness, double turns_max,
                                                 const std::string& csv_path, const PlectonemeRunOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  PlectonemeBranchSummary summary;
  const std::filesystem::path state_path = csv_path + ".state.json";
  const bool resuming = options.resume && std::filesystem::exists(state_path);
  if (options.resume && branch_complete(csv_path)) {
    summary.stop = "already complete";
    return summary;
  }
  const Case c = load_case(case_path, {{"slenderness", slenderness}});
  const double EI = c.definition.parameters.get("EI");
  ShootingProblem problem(c.definition);
  const ContinuationOptions o =
      continuation_options(c, slenderness, turns_max, options.max_step, options.reuse_jacobian);

  const std::vector<std::string> names = [] {
    std::vector<std::string> n = kMeasured;
    for (const char* extra : {"T_rho2_over_EI", "eq61", "m3_eq58b"}) n.push_back(extra);
    return n;
  }();
  RunState state;
  if (resuming) {
    state = load_state(state_path);
    truncate_csv(csv_path, state.saved_row);
  }
  state.parameter_name = "turns";
  std::ofstream csv(csv_path, resuming ? std::ios::app : std::ios::trunc);
  if (!csv) throw std::runtime_error("cannot write " + csv_path);
  csv << std::setprecision(12);
  if (!resuming) {
    csv << "index,turns,type";
    for (const auto& n : names) csv << ',' << n;
    csv << ",newton_iterations,step\n";
  }
  auto sink = [&](const ContinuationPoint& p) {
    const auto row = columns(p, EI);
    csv << ++state.row << ',' << p.parameter << ',' << to_string(p.type);
    for (const auto& n : names) csv << ',' << row.at(n);
    csv << ',' << p.newton_iterations << ',' << p.step << '\n' << std::flush;
    if (resumable(p)) save_resume_point(state_path, p, &state);
    ++summary.points;
    if (!std::isnan(row.at("eq61"))) {
      summary.last = row;
      summary.last["turns"] = p.parameter;
      summary.ply.push_back(summary.last);
    }
    if (options.progress_every > 0 && summary.points % options.progress_every == 0)
      std::cerr << "  L/2R = " << slenderness << "  point " << state.row << "  turns = " << std::setprecision(6)
                << p.parameter << "\n";
  };
  Continuation run(problem, o);
  ContinuationResult branch;
  if (resuming) {
    problem.set_parameter(o.parameter, state.last.parameter);
    branch = run.resume(state.last, sink);
  } else {
    const ShootingResult untwisted = solve(problem, problem.initial_unknowns(c.start_guess));
    if (!untwisted.summary.converged())
      throw std::runtime_error(case_path + ": the untwisted rod does not solve: " + untwisted.summary.brief_report());
    branch = run.run(untwisted.x, sink);
  }
  summary.stop = to_string(branch.reason) + (branch.message.empty() ? "" : " (" + branch.message + ")");
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return summary;
}

int run_plectonemes(const PlectonemesArguments& args) {
  if (args.slenderness.size() != args.turns.size()) {
    std::cerr << "error: --slenderness and --turns need the same number of values\n";
    return 2;
  }
  std::filesystem::create_directories(args.out_dir);
  const auto started = std::chrono::steady_clock::now();
  int total = 0;
  for (size_t k = 0; k < args.slenderness.size(); ++k) {
    const double sl = args.slenderness[k];
    const std::string csv = args.out_dir + "/plectoneme_" + std::to_string(static_cast<int>(sl)) + ".csv";
    std::cerr << "L/2R = " << sl << ": turns 0 -> " << args.turns[k] << "\n";
    try {
      PlectonemeRunOptions options;
      options.progress_every = 50;
      options.max_step = args.max_step;
      options.reuse_jacobian = args.reuse_jacobian;
      options.resume = args.resume;
      const auto s = follow_plectoneme_branch(args.case_path, sl, args.turns[k], csv, options);
      total += s.points;
      std::cout << "L/2R = " << sl << ": " << s.points << " points in " << std::setprecision(3) << s.seconds << " s ("
                << s.points / s.seconds << " points/s), stopped: " << s.stop << ", " << csv << "\n";
    } catch (const std::exception& e) {
      std::cerr << "L/2R = " << sl << ": " << e.what() << "\n";
      return 1;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::cout << "sweep: " << total << " points in " << std::setprecision(4) << seconds << " s ("
            << total / seconds << " points/s)\n";
  return 0;
}

}  // namespace kirchhoff::cli

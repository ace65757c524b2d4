#include "vibrate_command.hpp"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "kirchhoff/analysis/vibration.hpp"
#include "kirchhoff/jobs/result_json.hpp"
#include "solve_command.hpp"

namespace kirchhoff::cli {
namespace {

namespace fs = std::filesystem;

// One row per mode; an unstable mode (omega^2 < 0) has its growth rate instead of a frequency.
nlohmann::json modes_json(const std::vector<VibrationMode>& list, const std::vector<std::string>& profile_files) {
  nlohmann::json modes = nlohmann::json::array();
  for (size_t k = 0; k < list.size(); ++k) {
    const VibrationMode& m = list[k];
    nlohmann::json row = {{"omega2", m.omega2},
                          {"H_vib_mean", m.H_vib_stats.mean},
                          {"H_vib_spread", m.H_vib_stats.spread},
                          {"H_vib_scale", m.H_vib_stats.scale},
                          {"H_vib_relative_spread", m.H_vib_stats.relative_spread()},
                          {"H_vib_invariant", m.H_vib_stats.applies},
                          {"matching_residual", m.matching_residual}};
    if (m.omega2 < 0.0) {
      row["growth_rate"] = m.growth_rate();
    } else {
      row["omega"] = m.omega;
      row["omega_squared"] = m.omega2;
    }
    if (k < profile_files.size()) row["profile"] = profile_files[k];
    modes.push_back(row);
  }
  return modes;
}

nlohmann::json vibration_json(const Case& c, const ShootingResult& equilibrium, const VibrationOptions& options,
                               const VibrationAnalysis& analysis, const std::vector<std::string>& profile_files,
                               const std::vector<std::string>& unstable_files) {
  return {{"case", c.path},
          {"status", "converged"},
          {"parameters", parameters_json(equilibrium.parameters)},
          {"rho_s", options.rho_s},
          {"straight_equilibrium", analysis.straight_equilibrium},
          {"H_vib_not_conserved", analysis.H_vib_not_conserved},
          {"axial_indeterminate", analysis.axial_indeterminate},
          {"omega_scale", analysis.omega_scale},
          {"frequencies", analysis.frequencies()},
          {"modes", modes_json(analysis.modes, profile_files)},
          // Imaginary frequencies: as many as the equilibrium's index under dead end loads.
          {"omega2", analysis.omega2()},
          {"negative_omega2_count", analysis.negative_omega2_count()},
          {"unstable_modes", modes_json(analysis.unstable_modes, unstable_files)},
          {"unstable_search", {{"searched", analysis.unstable_searched}, {"sigma_max", analysis.sigma_max}}}};
}

void write_mode_csv(const fs::path& path, const VibrationMode& m) {
  std::ofstream csv(path);
  if (!csv) throw std::runtime_error("cannot write " + path.string());
  csv.precision(15);
  csv << "s,xbar,ybar,thetabar,mbar,nbarx,nbary,H_vib\n";
  for (size_t i = 0; i < m.s.size(); ++i) {
    const VibrationState& q = m.state[i];
    // The state is stored in the planar layout (x, y, theta, n_x, n_y, m).
    csv << m.s[i] << ',' << q[0] << ',' << q[1] << ',' << q[2] << ',' << q[5] << ',' << q[3] << ',' << q[4] << ','
        << m.H_vib[i] << '\n';
  }
}

void print_table(const Case& c, const VibrationAnalysis& analysis) {
  std::cout << (c.title.empty() ? c.path : c.title) << ": vibrations about the equilibrium"
            << (analysis.straight_equilibrium ? " (straight)" : "") << "\n";
  std::cout << "  k  omega               omega^2             H_vib mean          H_vib spread/scale\n";
  for (size_t k = 0; k < analysis.modes.size(); ++k) {
    const VibrationMode& m = analysis.modes[k];
    std::cout << "  " << std::setw(2) << k + 1 << std::setprecision(12) << "  " << std::setw(18) << m.omega << "  "
              << std::setw(18) << m.omega * m.omega << "  " << std::setw(18) << m.H_vib_stats.mean << "  "
              << std::setprecision(3) << m.H_vib_stats.relative_spread()
              << (m.H_vib_stats.applies ? "" : "  (not invariant: " + analysis.H_vib_not_conserved + ")") << "\n";
  }
  for (size_t k = 0; k < analysis.unstable_modes.size(); ++k) {
    const VibrationMode& m = analysis.unstable_modes[k];
    std::cout << "  u" << k + 1 << std::setprecision(12) << "  omega^2 = " << m.omega2
              << " < 0: imaginary frequency, grows as exp(" << m.growth_rate() << " t)\n";
  }
  if (analysis.unstable_modes.empty())
    std::cout << "  no mode with omega^2 < 0";
  else
    std::cout << "  unstable: " << analysis.unstable_modes.size() << " mode"
              << (analysis.unstable_modes.size() > 1 ? "s" : "") << " with omega^2 < 0";
  std::cout << std::setprecision(6) << " (searched growth rates up to " << analysis.sigma_max
            << "; end loads read as dead loads)\n";
}

}  // namespace

int run_vibrate(const VibrateArguments& args) {
  VibrationOptions options;
  options.modes = args.modes;
  options.rho_s = args.rho_s;
  SolvedCase solved;
  // The equilibrium alone: the vibration analysis needs no profile and no stability index. A
  // spatial case or bad options are refused before it is solved for.
  const auto refusal = [&](const Case& c) { return vibration_refusal(c.definition, options); };
  if (const int status = load_and_solve(args.case_path, args.overrides, "", args.json, &solved, {}, kDefaultSolveSeconds,
                                        false, args.solver, false, refusal);
      status != kExitOk)
    return status;
  const DefinitionSolve& equilibrium = solved.solved.solved;
  VibrationAnalysis analysis;
  try {
    analysis = VibrationProblem(*equilibrium.problem, equilibrium.result.x, options).analyse();
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << args.case_path << ": " << e.what() << "\n";
    return kExitBadInput;
  }
  std::vector<std::string> profile_files, unstable_files;
  try {
    if (!args.profiles_dir.empty()) {
      fs::create_directories(args.profiles_dir);
      auto write_all = [&](const std::vector<VibrationMode>& list, const std::string& stem, std::vector<std::string>* files) {
        for (size_t k = 0; k < list.size(); ++k) {
          const fs::path file = fs::path(args.profiles_dir) / (stem + std::to_string(k + 1) + ".csv");
          write_mode_csv(file, list[k]);
          files->push_back(file.string());
        }
      };
      write_all(analysis.modes, "mode_", &profile_files);
      write_all(analysis.unstable_modes, "unstable_mode_", &unstable_files);
    }
    const nlohmann::json json =
        vibration_json(solved.c, equilibrium.result, options, analysis, profile_files, unstable_files);
    if (!args.out_path.empty()) {
      std::ofstream out(args.out_path);
      if (!out) throw std::runtime_error("cannot write " + args.out_path);
      out << std::setprecision(17) << json.dump(2) << "\n";
    }
    if (args.json)
      std::cout << json.dump(2) << "\n";
    else
      print_table(solved.c, analysis);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace kirchhoff::cli

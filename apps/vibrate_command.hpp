// `kirchhoff vibrate`: small-amplitude vibrations about a planar equilibrium (section 9).
#pragma once

#include <string>
#include <vector>

namespace kirchhoff::cli {

struct VibrateArguments {
  std::string case_path;
  std::vector<std::string> overrides;  // NAME=VALUE
  std::vector<std::string> solver;     // --solver KEY=VALUE: [solver] keys
  int modes = 3;
  double rho_s = 1.0;
  std::string out_path;      // JSON file; empty: none
  std::string profiles_dir;  // mode-shape CSVs; empty: none
  bool json = false;         // print the JSON on stdout instead of the table
};

int run_vibrate(const VibrateArguments& args);

}  // namespace kirchhoff::cli

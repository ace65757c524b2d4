// `kirchhoff equilibria`: the distinct equilibria at one set of parameters (equilibria.hpp).
#pragma once

#include <string>
#include <vector>

namespace kirchhoff::cli {

struct EquilibriaArguments {
  std::string case_path;
  std::vector<std::string> overrides;  // NAME=VALUE
  std::vector<std::string> solver;     // --solver KEY=VALUE: [solver] keys
  int max_equilibria = 16;
  bool json = false;           // print the JSON on stdout instead of the table
  std::string profiles_dir;    // one profile CSV per equilibrium; empty: none
  double max_seconds = 120.0;  // wall-clock limit of the search (0: none)
};

int run_equilibria(const EquilibriaArguments& args);

}  // namespace kirchhoff::cli

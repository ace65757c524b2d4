// `kirchhoff plectonemes`: the Fig. 11 sweep (kirchhoff/sweeps/plectoneme_sweep.hpp) with its report
// and totals on stdout.
#pragma once

#include "kirchhoff/sweeps/plectoneme_sweep.hpp"

namespace kirchhoff::cli {

using kirchhoff::PlectonemesArguments;  // what the command line fills

// The CLI command: sweep_plectonemes with its report and totals on stdout; exit status 2 for bad
// arguments, 1 when a branch fails.
int run_plectonemes(const PlectonemesArguments& args);

}  // namespace kirchhoff::cli

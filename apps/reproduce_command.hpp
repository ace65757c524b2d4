// `kirchhoff reproduce`: recomputes the reference paper's results that the toolkit covers and
// writes a report (markdown and JSON) with numeric and analytic values side by side, plus the
// CSV profiles behind the figures.
#pragma once

#include <string>

namespace kirchhoff::cli {

// `full` adds Fig. 11's L/2R = 500 and 1000 (the whole `kirchhoff plectonemes` sweep, ~30 minutes).
int run_reproduce(const std::string& out_dir, const std::string& cases_dir, bool full = false);

}  // namespace kirchhoff::cli

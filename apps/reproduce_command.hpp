// `kirchhoff reproduce`: maps its arguments onto the library's `reproduce` (kirchhoff/reproduce/reproduce.hpp),
// which recomputes the reference paper's results and writes the report and the figure data.
#pragma once

#include <string>

namespace kirchhoff::cli {

// Progress on stderr; exit status 0 when every row passes, 1 when a row fails or a result cannot
// be computed. `full` adds Fig. 11's L/2R = 500 and 1000 and the wall's phase diagram.
int run_reproduce(const std::string& out_dir, const std::string& cases_dir, bool full = false);

}  // namespace kirchhoff::cli

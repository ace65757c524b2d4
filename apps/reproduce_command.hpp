// `kirchhoff reproduce`: recomputes the reference paper's results that the toolkit covers and
// writes a report (markdown and JSON) with numeric and analytic values side by side, plus the
// CSV profiles behind the figures.
#pragma once

#include <string>

namespace kirchhoff::cli {

int run_reproduce(const std::string& out_dir, const std::string& cases_dir);

}  // namespace kirchhoff::cli

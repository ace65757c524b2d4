// `kirchhoff reproduce` and Python's kirchhoff.reproduce: recompute the reference paper's results
// that the toolkit covers, each as a report row (expected value, computed value, tolerance,
// status) beside the CSV profiles behind its figure, and write the report (markdown and JSON).
// The CLI and Python only map their arguments onto `reproduce`.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace kirchhoff {

// One result of the paper: a closed form (`analytic`) or a printed value (`paper`) beside the
// computed one. A row without `analytic` is information (a value with nothing exact to meet).
struct ReportRow {
  ReportRow() = default;
  ReportRow(std::string id, std::string quantity, std::optional<double> paper, std::optional<double> analytic,
            double numeric, double reference_scale, double tolerance, std::string note)
      : id(std::move(id)), quantity(std::move(quantity)), paper(paper), analytic(analytic), numeric(numeric),
        reference_scale(reference_scale), tolerance(tolerance), note(std::move(note)) {}

  std::string id;  // figure or equation
  std::string quantity;
  std::optional<double> paper;     // value printed in the paper, when it prints one
  std::optional<double> analytic;  // closed form
  double numeric = 0.0;
  double reference_scale = 0.0;  // |analytic|, or the quantity's scale when analytic is 0
  double tolerance = 0.0;        // on rel_error, justified by the method's accuracy
  std::string note;
  std::string stability;  // of the equilibrium the row reports (stability.hpp), when it is one

  double rel_error() const;
  bool checked() const { return analytic.has_value(); }
  bool pass() const { return !checked() || rel_error() <= tolerance; }
  // "pass", "FAIL" or "info" (nothing exact to check against).
  const char* status() const;
};

// Progress lines ("Fig. 12: hard and soft walls", ...); the CLI prints them on stderr.
using ReproduceProgress = std::function<void(const std::string&)>;

struct ReproduceRequest {
  std::string out_dir;    // created; receives report.md, report.json, profiles/
  std::string cases_dir;  // the shipped cases/ (the full run also reads ../sweeps beside it)
  // Adds Fig. 11's L/2R = 500 and 1000 (the whole `kirchhoff plectonemes` sweep), the exact ply at
  // 500 and the hard wall's phase diagram (~20 minutes on 2 cores against a few).
  bool full = false;
};

struct ReproduceResult {
  std::vector<ReportRow> rows;
  double seconds = 0.0;  // wall time of the computation, as report.md states it
  int failed() const;
};

// Computes every row and figure file into request.out_dir/profiles (and out_dir/wall_phase with
// `full`), then writes report.md and report.json. Throws std::exception (a case that does not
// solve, a continuation that stops early) before writing the report; the profiles computed before
// stay written.
ReproduceResult reproduce(const ReproduceRequest& request, const ReproduceProgress& progress = {});

// report.md (a table with the rows and "k of n rows pass; computed in S s") and report.json (one
// object per row) in out_dir.
void write_reproduce_report(const std::string& out_dir, const std::vector<ReportRow>& rows, double seconds);

}  // namespace kirchhoff

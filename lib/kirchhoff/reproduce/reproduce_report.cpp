// report.md and report.json of `reproduce` (reproduce.hpp): one line (object) per row.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "kirchhoff/reproduce/reproduce.hpp"

namespace kirchhoff {

double ReportRow::rel_error() const { return analytic ? std::abs(numeric - *analytic) / reference_scale : 0.0; }

const char* ReportRow::status() const { return !checked() ? "info" : pass() ? "pass" : "FAIL"; }

namespace {

std::string format(const std::optional<double>& v) {
  if (!v) return "";
  std::ostringstream os;
  os << std::setprecision(10) << *v;
  return os.str();
}

// JSON null for an absent value.
template <class T>
nlohmann::json value_or_null(bool present, const T& v) {
  return present ? nlohmann::json(v) : nlohmann::json();
}

void markdown_line(std::ostream& md, const ReportRow& r) {
  std::ostringstream err, tol;
  err << std::setprecision(2) << std::scientific << r.rel_error();
  tol << std::setprecision(2) << r.tolerance;  // 1e-09, 0.12: as stated, not rounded to a power of ten
  const bool checked = r.checked();
  md << "| " << r.id << " | " << r.quantity << " | " << format(r.paper) << " | " << format(r.analytic) << " | "
     << format(r.numeric) << " | " << (checked ? err.str() : "") << " | " << (checked ? tol.str() : "") << " | "
     << (checked ? (r.pass() ? "pass" : "**FAIL**") : "info") << " | " << r.stability << " | " << r.note << " |\n";
}

nlohmann::json json_object(const ReportRow& r) {
  nlohmann::json j = {{"id", r.id}, {"quantity", r.quantity}, {"numeric", r.numeric}, {"note", r.note},
                      {"stability", r.stability}};
  j["paper"] = value_or_null(r.paper.has_value(), r.paper.value_or(0.0));
  j["analytic"] = value_or_null(r.checked(), r.analytic.value_or(0.0));
  j["rel_error"] = value_or_null(r.checked(), r.rel_error());
  j["tolerance"] = value_or_null(r.checked(), r.tolerance);
  j["pass"] = value_or_null(r.checked(), r.pass());
  return j;
}

}  // namespace

void write_reproduce_report(const std::string& out_dir, const std::vector<ReportRow>& rows, double seconds) {
  const std::filesystem::path out(out_dir);
  std::ofstream md(out / "report.md");
  md << "# Kirchhoff: the reference paper's results, recomputed\n\n"
     << "Numeric values from shooting (RK78 at 1e-12, Newton to 1e-10); analytic values from the closed forms\n"
     << "(GSL elliptic integrals, eq. 54, closed-form invariants). rel. error = |numeric - analytic| / scale.\n\n"
     << "| result | quantity | paper | analytic | numeric | rel. error | tolerance | pass | stability | note |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  nlohmann::json json = nlohmann::json::array();
  int failed = 0;
  for (const auto& r : rows) {
    markdown_line(md, r);
    failed += r.pass() ? 0 : 1;
    json.push_back(json_object(r));
  }
  md << "\n" << rows.size() - failed << " of " << rows.size() << " rows pass; computed in " << std::fixed
     << std::setprecision(2) << seconds << " s.\n";
  std::ofstream(out / "report.json") << json.dump(2) << "\n";
}

}  // namespace kirchhoff

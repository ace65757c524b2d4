// Consumer of the installed library: solves the simply supported Elastica from its case file,
// continues it in theta0 from 1 to 2 as `kirchhoff continue` does (continue_case), and runs a
// two-job sweep over theta0 as `kirchhoff sweep` does (run_sweep) into a scratch folder.
#include <kirchhoff/analysis/analytic.hpp>
#include <kirchhoff/jobs/case_continue.hpp>
#include <kirchhoff/jobs/case_file.hpp>
#include <kirchhoff/shooting/shooting.hpp>
#include <kirchhoff/sweeps/sweep.hpp>
#include <kirchhoff/sweeps/sweep_run.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

namespace {

// The points' P, as a library user's own sink keeps them.
struct LastLoad : kirchhoff::ContinueSink {
  double P = NAN;
  int points = 0;
  void point(const kirchhoff::RunPoint& p) override {
    P = p.point->derived.at("P");
    ++points;
  }
};

// Two solves of the case at theta0 = 1.5 and 2.5, each P against the elliptic closed form.
int sweep_matches_the_elastica(const std::string& case_path, const std::string& out_dir) {
  // Absolute: a sweep file's case path is read against the sweep file's folder.
  const std::string text = "title = \"theta0\"\ncase = \"" + std::filesystem::absolute(case_path).string() +
                           "\"\n[[jobs]]\nname = \"s\"\nkind = \"solve\"\ngrid = { theta0 = [1.5, 2.5] }\n";
  const kirchhoff::SweepSpec spec = kirchhoff::load_sweep_text(text, out_dir + "/sweep.toml");
  kirchhoff::SweepRunOptions options;
  options.out_dir = out_dir;
  const kirchhoff::SweepSummary sweep = kirchhoff::run_sweep(spec, options);
  const auto& columns = sweep.index.columns;
  const auto column = [&](const char* name) { return std::find(columns.begin(), columns.end(), name) - columns.begin(); };
  if (sweep.jobs != 2 || sweep.failed != 0 || sweep.index.rows.size() != 2) return 1;
  for (const auto& row : sweep.index.rows) {
    const double theta0 = std::stod(row[column("theta0")]), P = std::stod(row[column("P")]);
    const double exact = kirchhoff::analytic::PinnedElastica{1, 1, theta0}.load();
    std::printf("sweep: theta0 = %g, P = %.12f (elliptic %.12f)\n", theta0, P, exact);
    if (std::abs(P / exact - 1) > 1e-9) return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: consumer CASE.toml SWEEP_FOLDER\n");
    return 2;
  }
  const kirchhoff::Case c = kirchhoff::load_case(argv[1]);
  const kirchhoff::ShootingProblem p(c.definition);
  const auto r = kirchhoff::solve(p, p.initial_unknowns(c.start_guess));
  const double exact = kirchhoff::analytic::PinnedElastica{1, 1, 1}.load();
  std::printf("%s P = %.12f (elliptic %.12f)\n", kirchhoff::to_string(r.summary.status), r.parameters["P"], exact);
  if (!r.summary.converged() || std::abs(r.parameters["P"] / exact - 1) > 1e-9) return 1;

  kirchhoff::ContinueRequest request;
  request.parameter = "theta0";
  request.target = 2.0;
  LastLoad last;
  const kirchhoff::ContinueRunResult run = kirchhoff::continue_case(c, request, {&last});
  const double exact2 = kirchhoff::analytic::PinnedElastica{1, 1, 2}.load();
  std::printf("continue: %s, %d points, P = %.12f at theta0 = 2 (elliptic %.12f)\n", run.status.c_str(), last.points,
              last.P, exact2);
  if (!run.ok || run.status != "reached_target" || std::abs(last.P / exact2 - 1) > 1e-9) return 1;
  try {
    return sweep_matches_the_elastica(argv[1], argv[2]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep: %s\n", e.what());
    return 1;
  }
}

// Consumer of the installed library: solves the simply supported Elastica from its case file,
// then continues it in theta0 from 1 to 2 as `kirchhoff continue` does (continue_case).
#include <kirchhoff/analysis/analytic.hpp>
#include <kirchhoff/jobs/case_continue.hpp>
#include <kirchhoff/jobs/case_file.hpp>
#include <kirchhoff/shooting/shooting.hpp>
#include <cmath>
#include <cstdio>

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

}  // namespace

int main(int argc, char** argv) {
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
  return run.ok && run.status == "reached_target" && std::abs(last.P / exact2 - 1) < 1e-9 ? 0 : 1;
}

// Consumer of the installed library: solves the simply supported Elastica from its case file.
#include <kirchhoff/analytic.hpp>
#include <kirchhoff/case_file.hpp>
#include <kirchhoff/shooting.hpp>
#include <cmath>
#include <cstdio>
int main(int argc, char** argv) {
  const kirchhoff::Case c = kirchhoff::load_case(argv[1]);
  const kirchhoff::ShootingProblem p(c.definition);
  const auto r = kirchhoff::solve(p, p.initial_unknowns(c.start_guess));
  const double exact = kirchhoff::analytic::PinnedElastica{1, 1, 1}.load();
  std::printf("%s P = %.12f (elliptic %.12f)\n", kirchhoff::to_string(r.summary.status), r.parameters["P"], exact);
  return r.summary.converged() && std::abs(r.parameters["P"] / exact - 1) < 1e-9 ? 0 : 1;
}

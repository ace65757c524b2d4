// `reproduce`'s Section 9 (reproduce_steps.hpp): vibrations about straight and buckled columns.
// Frequencies against eq. (96)'s closed forms, the invariant H_vib of eq. (95b) and its column
// form (97), and omega_k^2(P) for the figure (python/make_figures.py).
#include <cmath>
#include <fstream>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/vibration.hpp"
#include "kirchhoff/reproduce/detail/reproduce_steps.hpp"

namespace kirchhoff::reproduce_steps {

namespace {

// Roots of a determinant of solutions integrated at 1e-12 over half the rod: ~1e-10 relative.
constexpr double kFrequencyTolerance = 1e-9;

VibrationAnalysis analyse(const Solved& s, int modes) {
  VibrationOptions options;
  options.modes = modes;
  return VibrationProblem(*s.problem, s.solution.result.x, options).analyse();
}

// H_vib of eq. (95b) along the straight column's modes, against eq. (97) with -P ybar'^2/2 and as
// printed (-P ybar^2/2).
void column_invariants(const Step& step, const VibrationAnalysis& straight, double P) {
  double worst_spread = 0.0, worst_difference = 0.0, printed_spread = 0.0;
  for (const auto& mode : straight.modes) {
    worst_spread = std::max(worst_spread, mode.H_vib_stats.relative_spread());
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < mode.H_vib.size(); ++i) {
      worst_difference = std::max(worst_difference, std::abs(mode.H_vib_column[i] - mode.H_vib[i]) / mode.H_vib_stats.scale);
      const VibrationState& q = mode.state[i];
      const double printed = eq97_hamiltonian(1.0, 1.0, mode.omega, P, {q[1], q[2], q[5], -q[4] - P * q[2]}, true);
      lo = std::min(lo, printed);
      hi = std::max(hi, printed);
    }
    printed_spread = std::max(printed_spread, (hi - lo) / mode.H_vib_stats.scale);
  }
  auto* rows = step.rows;
  rows->push_back({"eq. (95b), pinned column", "H_vib spread / scale, worst of modes 1-3", {}, 0.0, worst_spread, 1.0,
                   1e-9, "invariant: the equilibrium is straight"});
  rows->push_back({"eq. (97) vs (95b)", "max abs(H_97 - H_95b) / scale, modes 1-3", {}, 0.0, worst_difference, 1.0,
                   1e-9, "(97) with -P ybar'^2/2"});
  rows->push_back({"eq. (97) as printed", "spread / scale of the printed form (-P ybar^2/2)", {}, {}, printed_spread,
                   1.0, 0.0, "not constant: its derivative is P ybar' (ybar'' - ybar); -P ybar'^2/2 is"});
}

// The cantilever's first frequency, and the buckled Elastica's (no closed form).
void other_rods(const Step& step) {
  auto* rows = step.rows;
  const Solved cantilever = solve_for_report(step.cases / "heavy_cantilever.toml", {{"w", 0.0}}, 21);
  const double cantilever_exact = analytic::beam_frequency(analytic::BeamEnds::ClampedFree, 1.0, 1.0, 1.0, 1);
  rows->push_back({"cantilever (clamped-free, P = 0)", "omega_1 = 1.8751^2 sqrt(EI/rhoS)/L^2, 1 + cos cosh = 0", {},
                   cantilever_exact, analyse(cantilever, 1).modes[0].omega, cantilever_exact, kFrequencyTolerance,
                   "heavy_cantilever.toml with w = 0"});
  const Solved buckled = solve_for_report(step.cases / "simply_supported.toml", {{"theta0", 1.0}}, 21);
  const VibrationAnalysis about_buckled = analyse(buckled, 1);
  rows->push_back({"Section 9, buckled Elastica theta0 = 1",
                   "omega_1 (dead load P = " + format_short(buckled.solution.derived.at("P")) + ")", {}, {},
                   about_buckled.modes[0].omega, 1.0, 0.0, "no closed form"});
  rows->push_back({"Section 9, buckled Elastica theta0 = 1", "H_vib spread / scale (theta_e' != 0: not invariant)", {},
                   {}, about_buckled.modes[0].H_vib_stats.relative_spread(), 1.0, 0.0, "varies, as section 9 says"});
}

// omega_k^2(P): straight column below the Euler load, and the softest mode of the buckled
// Elastica just above it (omega_1^2 ~ 2 pi^2 (P - pi^2)).
void frequency_curves(const Step& step) {
  std::ofstream csv(step.out / "vibration_column.csv");
  csv.precision(15);
  csv << "P,branch,k,omega_squared,omega_squared_analytic\n";
  for (int i = 0; i <= 8; ++i) {
    const double P = 1.2 * i;  // up to 9.6, just below the Euler load pi^2
    const Solved s = solve_for_report(step.cases / "euler_column.toml", {{"P", P}, {"theta_guess", 0.0}}, 21);
    const VibrationAnalysis a = analyse(s, 3);
    for (int k = 1; k <= 3; ++k) {
      const double exact = analytic::pinned_column_frequency(1.0, P, 1.0, 1.0, k);
      csv << P << ",straight," << k << ',' << a.modes[k - 1].omega * a.modes[k - 1].omega << ',' << exact * exact << '\n';
    }
  }
  for (double theta0 : {0.2, 0.4, 0.6, 0.8, 1.0}) {
    const Solved s = solve_for_report(step.cases / "simply_supported.toml", {{"theta0", theta0}, {"P", 10.0}}, 21);
    const double omega = analyse(s, 1).modes[0].omega;
    csv << s.solution.derived.at("P") << ",buckled,1," << omega * omega << ",\n";
  }
}

}  // namespace

void vibrations(const Step& step) {
  const double P_half = 0.5 * M_PI * M_PI;
  const Solved column = solve_for_report(step.cases / "euler_column.toml", {{"P", P_half}, {"theta_guess", 0.0}}, 21);
  const VibrationAnalysis straight = analyse(column, 3);
  for (int k = 1; k <= 3; ++k) {
    const double exact = analytic::pinned_column_frequency(1.0, P_half, 1.0, 1.0, k);
    step.rows->push_back({"eq. (96), pinned column, P = pi^2/2",
                          "omega_" + std::to_string(k) + " = sqrt(EI (k pi)^4 - P (k pi)^2) (rhoS = 1)", {}, exact,
                          straight.modes[k - 1].omega, exact, kFrequencyTolerance, "far end rolling under the dead load P"});
  }
  column_invariants(step, straight, P_half);
  other_rods(step);
  frequency_curves(step);
}

}  // namespace kirchhoff::reproduce_steps

// Why a spatial rod can fail to converge where its tangent reverses through -e3: the frame's turn
// angle about e3, which the state carries, is undefined there.
#include <cmath>
#include <exception>
#include <sstream>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

namespace {

// The tangent within this of -e3, as 1 + d3.e3 (1 - cos of the angle from -e3: 2e-3 is 3.6
// degrees), is reversed. The turn angle's equation (spatial_equations.cpp) divides by
// w^2 + qz^2 = (1 + d3.e3) / 2, which vanishes there whatever the twist: on Michell's ring (its
// tangent passes exactly through -e3 at s = L/2) the state's error grew from 1e-12 to 1e-9 and
// Newton stalled above the tolerance 1e-10. A plectoneme's returning ply, tilted by its ply
// angle, stays farther (1 + d3.e3 ~ 1e-2 and more).
constexpr double kReversed = 2e-3;
// Samples along the rod: a tangent turning once about a ring passes them 0.9 degrees apart.
constexpr int kSamples = 401;

bool counts_turns(const EndCondition& end) {
  for (const SlotCondition& c : end.conditions())
    if (c.slot == Slot::Orientation && c.track_turns) return true;
  return false;
}

}  // namespace

std::string turn_count_hint(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  const ProblemDefinition& definition = problem.definition();
  if (definition.kind != RodKind::Spatial) return "";
  const bool counting = counts_turns(definition.start) || counts_turns(definition.end);
  // The turn angle is integrated with the state whether or not an end counts it: where the
  // tangent passes through -e3 it jumps, and dopri5's step control shrinks its steps to nothing
  // there (a step size underflow at s = L/2 on Michell's ring). RKF78's steps pass it.
  const bool dopri5 = definition.options.integrator.stepper == IntegratorOptions::Stepper::Dopri5;
  if (!counting && !dopri5) return "";
  const double L = problem.length(problem.parameters_at(x));
  std::vector<double> s(kSamples);
  for (int i = 0; i < kSamples; ++i) s[i] = L * i / (kSamples - 1);
  IntegratorOptions marched = definition.options.integrator;
  marched.stepper = IntegratorOptions::Stepper::RungeKutta78;
  std::vector<RodPoint> profile;
  try {
    profile = problem.sample(x, s, &marched);
  } catch (const std::exception&) {
    return "";  // no profile to read at x: no hint rather than a guessed one
  }
  double closest = 2.0, where = 0.0;  // 1 + d3.e3 at its smallest along the rod, and where
  for (const RodPoint& p : profile) {
    const double reversal = 1.0 + p.R(2, 2);
    if (reversal < closest) closest = reversal, where = p.s;
  }
  if (!(closest < kReversed)) return "";
  std::ostringstream os;
  os.precision(3);
  const double degrees = std::acos(1.0 - closest) * 180.0 / M_PI;
  os << "the tangent reverses through -e3 (";
  if (degrees < 0.05) os << "at s = " << where;
  else os << "within " << degrees << " degrees of it at s = " << where;
  os << "), where the frame's turn angle about e3 is undefined (a tangent reversed there has no turn count, and "
     << "the turn angle's equation is singular)";
  if (counting)
    os << ": set track_turns = false, and the end's frame is then imposed up to whole turns, Newton keeping the "
       << "guess's (cases/michell_ring.toml)";
  if (dopri5) os << (counting ? "; and " : ": ") << "stepper = \"rk78\", whose steps pass it where dopri5's cannot";
  return os.str();
}

}  // namespace kirchhoff

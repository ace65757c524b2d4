// Why a rod whose ends count whole turns (track_turns) can fail to converge: its tangent reverses
// through -e3, where the counted turn is undefined.
#include <cmath>
#include <exception>
#include <sstream>

#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

namespace {

// The tangent within this of -e3, as 1 + d3.e3 (1 - cos of the angle from -e3: 2e-3 is 3.6
// degrees), is reversed. The turn angle counted (spatial_state.hpp) jumps by about pi across
// -e3, to one side or the other as the rod passes it: on Michell's ring (its tangent passes
// exactly through -e3 at s = L/2) Newton stalled at a residual of 1e-9 against the tolerance
// 1e-10. A plectoneme's returning ply, tilted by its ply angle, stays farther (1 + d3.e3 ~ 1e-2
// and more).
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
  if (definition.kind != RodKind::Spatial || !(counts_turns(definition.start) || counts_turns(definition.end)))
    return "";
  const double L = problem.length(problem.parameters_at(x));
  std::vector<double> s(kSamples);
  for (int i = 0; i < kSamples; ++i) s[i] = L * i / (kSamples - 1);
  std::vector<RodPoint> profile;
  try {
    profile = problem.sample(x, s);
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
  os << "), where the whole turns about e3 that track_turns counts are undefined (a tangent reversed there has "
     << "no turn count): set track_turns = false, and the end's frame is then imposed up to whole turns, Newton "
     << "keeping the guess's (cases/michell_ring.toml)";
  return os.str();
}

}  // namespace kirchhoff

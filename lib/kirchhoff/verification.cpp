#include "kirchhoff/verification.hpp"

#include <cmath>
#include <sstream>

namespace kirchhoff {
namespace {

bool finite(const RodPoint& p) {
  return std::isfinite(p.s) && p.r.allFinite() && p.R.allFinite() && p.n.allFinite() && p.m.allFinite() &&
         p.u.allFinite() && p.v.allFinite() && std::isfinite(p.turn_angle);
}

std::string at(double s) {
  std::ostringstream os;
  os.precision(6);
  os << " at s = " << s;
  return os.str();
}

}  // namespace

std::string unknowns_failure(const ShootingProblem& problem, const ShootingResult& result) {
  if (!result.x.allFinite()) return "the unknowns hold NaN or inf";
  const Parameters& p = result.parameters;
  for (int i = 0; i < p.size(); ++i)
    if (!std::isfinite(p.values()[i])) return "parameter '" + p.names()[i] + "' is not finite";
  Eigen::VectorXd F;
  std::string failure;
  if (!problem.evaluate(result.x, &F, nullptr, &failure))
    return "the residual cannot be evaluated again at the solution: " + failure;
  const double norm = max_abs_or_nan(F);
  if (!std::isfinite(norm)) return "the residual recomputed at the solution holds NaN or inf";
  // Newton accepts a step that stopped moving at round-off with |F| up to 1e3 times the
  // tolerance (NewtonOptions::step_tolerance); anything beyond is not a converged residual.
  const double tolerance = problem.definition().options.newton.residual_tolerance;
  const double allowed = result.summary.message == "step at round-off" ? 1e3 * tolerance : tolerance;
  if (!(norm <= allowed)) {
    std::ostringstream os;
    os << "the residual recomputed at the solution is " << norm << ", above the tolerance " << allowed;
    return os.str();
  }
  return {};
}

std::string profile_failure(const RodModel& model, const std::vector<RodPoint>& profile) {
  for (const RodPoint& p : profile)
    if (!finite(p)) return "the solution's profile holds NaN or inf" + at(p.s);
  if (!model.field) return {};
  for (const RodPoint& p : profile) {
    const double gap = model.field->gap(p.s, p.r);
    // NaN: the field models no wall. A gap <= 0 is on or beyond the wall, where W_ext is
    // infinite or changes sign: outside the potential's domain.
    if (!std::isnan(gap) && !(gap > 0.0)) {
      std::ostringstream os;
      os << "the rod is on or beyond its soft wall" << at(p.s) << " (gap " << gap
         << "), outside the domain of the barrier potential";
      return os.str();
    }
  }
  return {};
}

void mark_check_failure(ShootingResult* result, const std::string& failure) {
  if (failure.empty() || !result->summary.converged()) return;
  result->summary.status = SolverStatus::CheckFailed;
  result->summary.message = failure;
}

}  // namespace kirchhoff

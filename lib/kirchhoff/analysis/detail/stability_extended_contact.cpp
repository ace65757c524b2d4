// The index where the rod lies on an obstacle (see stability_extended_contact.hpp).
#include "kirchhoff/analysis/detail/stability_extended_contact.hpp"

#include "kirchhoff/analysis/discrete_stability.hpp"

namespace kirchhoff {

bool has_extended_contact(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  for (const PointContact& c : problem.contacts_at(x))
    if (c.extended) return true;
  return false;
}

StabilityReport extended_contact_stability(const ShootingProblem& problem, const Eigen::VectorXd& x) {
  StabilityReport report;
  if (problem.definition().kind != RodKind::Planar) {
    report.reason = "an extended contact of a spatial rod (the rod lying on the obstacle): its second variation is "
                    "not implemented";
    return report;
  }
  report.method = "discretised_energy";
  report.method_reason = "an extended contact (the rod lying on the obstacle): the conjugate-point count does not "
                         "cover it; the index is the discretised energy's with the nodes on the obstacle held, "
                         "checked at two resolutions";
  // 800 elements (kDiscreteStabilityLyingElements) and 400 for the self-check.
  const DiscreteStability d = discrete_stability(problem, x);
  if (d.unstable) {  // no index, but a verdict: the flat part lifts off (discrete_stability.hpp)
    report.unstable = true;
    report.reason = d.reason;
    return report;
  }
  if (!d.defined()) {
    report.reason = "an extended contact (the rod lying on the obstacle), whose index comes from the discretised "
                    "energy: " + d.reason;
    return report;
  }
  if (!d.trustworthy) {
    report.reason = "an extended contact (the rod lying on the obstacle), whose index comes from the discretised "
                    "energy, which did not pass its self-check: " + d.check_message;
    return report;
  }
  report.index = d.index;
  report.zero_modes = d.zero_modes;
  return report;
}

}  // namespace kirchhoff

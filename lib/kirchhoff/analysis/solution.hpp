// A solved equilibrium as users see it: the sampled profile, the invariants along it, the
// derived quantities a case asks for, and the solver's summary.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

struct Solution {
  ShootingResult result;
  std::vector<RodPoint> profile;  // equally spaced in s, ends included
  InvariantReport invariants;
  std::map<std::string, double> derived;
  std::vector<PointContact> contacts;  // the active contacts, solved
};

// Samples (n_samples >= 2 points), computes invariants and the requested derived quantities.
Solution make_solution(const ShootingProblem& problem, ShootingResult result, int n_samples,
                       const std::vector<std::string>& derived_names);

// The solution described at s = 0 alone, without integrating the rod: a profile of one point, no
// invariants (their report says they do not apply), the contacts, and derived quantities that
// read only the start (throws std::logic_error for another). For a continuation that records
// such quantities at every point and nothing else; a field's domain along the rod (a soft wall's
// gap, which make_solution checks on its profile) is not checked here.
Solution make_start_solution(const ShootingProblem& problem, ShootingResult result,
                             const std::vector<std::string>& derived_names);

// What the outputs (CLI JSON, Python) say of each contact: where, how hard, and H just before it
// and just after it (after the flat part of an extended contact), which section 6.3 says agree.
struct ContactReport {
  int obstacle = 0;
  std::string obstacle_name;
  bool extended = false;
  double s = 0.0, s_end = 0.0;         // s_end = s for a point contact
  double force = 0.0, force_end = 0.0;  // force_end = 0 for a point contact
  double H_before = 0.0, H_after = 0.0;
};
std::vector<ContactReport> report_contacts(const ShootingProblem& problem, const Solution& sol);

// Names accepted in a case's derived list, with a one-line meaning each.
const std::map<std::string, std::string>& derived_catalogue();

// -dV/ds at fixed state: the explicit arclength dependence that makes H vary (eq. 57 for a
// tapered rod, H' = -1/2 EI'(s) theta'^2).
double explicit_s_derivative_of_energy(const RodModel& model, const RodPoint& p);

// Writes one row per profile point: s, r, d1, d2, d3, n, m, the curvatures, H, m3, n.m, dH/ds
// predicted by the explicit-s identity. The curvatures are u1, u2, u3 for a spatial rod and
// kappa = theta' (= u2) for a planar one, whose u1 and u3 are not unknowns of its equations.
// Throws std::runtime_error when the file cannot be written.
void write_profile_csv(const std::string& path, const RodModel& model, const std::vector<RodPoint>& profile,
                       RodKind kind = RodKind::Spatial);

}  // namespace kirchhoff

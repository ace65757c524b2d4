// What a symmetric plectoneme (section 7.6, Fig. 10) is measured by: the quantities of eqs.
// (58)-(61) read off a solved half rod whose end s = L/2 is a half-turn symmetry point and whose
// self-contact is a HalfTurnSelfContact (see self_contact.hpp and cases/plectoneme.toml).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kirchhoff/shooting.hpp"

namespace kirchhoff {

struct PlectonemeMeasures {
  double T_ext = 0.0;             // tension at the clamp, n(0).d3(0) (the pull on the end B)
  double m3 = 0.0;                // twisting moment m.d3 (constant for an isotropic rod)
  // Cross-sections within kContactGap of contact form the contact region [contact_start,
  // contact_end] (arclengths on the half rod); NaN bounds and averages when there is none.
  double contact_start = NAN, contact_end = NAN;
  double helix_angle = NAN;       // mean over the contact region of the angle between d3 and the axis
  double contact_pressure = NAN;  // mean over the contact region of the contact force per length
  double H_A = NAN;               // H in the middle of the contact region (point A of eq. 60)
  double H_B = 0.0;               // H at the clamped end (point B of eq. 59)
  // Smallest distance between cross-sections of the whole rod (both halves) that are more than
  // pi R apart along it, in units of 2R: >= 1 when no two parts of the rod interpenetrate.
  double self_distance = NAN;
  // Smallest (rho - R)/c where the contact is being switched off near the end loop: H drifts
  // there by ~ exp(-loop_clearance^2) times the barrier's scale, negligible beyond ~4.
  double loop_clearance = NAN;
};

// A cross-section is in contact when its gap rho - R is below this fraction of R (the barrier's
// gap at plectoneme pressures is ~1e-3 R; free cross-sections are at least ~R away).
constexpr double kContactGap = 0.02;

// Throws std::invalid_argument when the problem has no half-turn self-contact.
PlectonemeMeasures measure_plectoneme(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                      const std::vector<RodPoint>& profile);

// The derived quantities measure_plectoneme provides, by name, with their meaning.
const std::vector<std::pair<std::string, std::string>>& plectoneme_quantities();
double plectoneme_quantity(const PlectonemeMeasures& m, const std::string& name);

}  // namespace kirchhoff

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
  // The contact region [contact_start, contact_end] (arclengths on the half rod) runs from the
  // first to the last cross-section pressed with at least kContactFraction of the largest contact
  // force per length: the interwound part, crossings and line contacts alike. NaN bounds and
  // averages when nothing is pressed.
  double contact_start = NAN, contact_end = NAN;
  // Means over the central half of the contact region (the ply's ends bend away from a helix):
  double helix_angle = NAN;       // the angle between d3 and the axis
  double helix_radius = NAN;      // the distance to the axis (R + the barrier's gap)
  double contact_pressure = NAN;  // the contact force per length
  double H_A = NAN;               // H in the middle of the contact region (point A of eq. 60)
  double H_B = 0.0;               // H at the clamped end (point B of eq. 59)
  // Smallest distance between cross-sections of the whole rod (both halves) that are more than
  // pi R apart along it, in units of 2R: >= 1 when no two parts of the rod interpenetrate.
  double self_distance = NAN;
  // Smallest (rho - R)/c where the contact is being switched off near the end loop: H drifts
  // there by ~ exp(-loop_clearance^2) times the barrier's scale, negligible beyond ~4.
  double loop_clearance = NAN;
};

// Cross-sections pressed with less than this fraction of the largest contact force per length
// are outside the contact region (the barrier's force falls like exp(-(g/c)^2)/g^2 away from
// contact, so the threshold moves the region's ends by a small fraction of the range c).
constexpr double kContactFraction = 0.01;

// Throws std::invalid_argument when the problem has no half-turn self-contact.
PlectonemeMeasures measure_plectoneme(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                      const std::vector<RodPoint>& profile);

// The derived quantities measure_plectoneme provides, by name, with their meaning.
const std::vector<std::pair<std::string, std::string>>& plectoneme_quantities();
double plectoneme_quantity(const PlectonemeMeasures& m, const std::string& name);

}  // namespace kirchhoff

// The symmetric plectoneme (section 7.6, Fig. 10): the quantities of eqs. (58)-(61) read off a
// solved half rod whose end s = L/2 is a half-turn symmetry point, and its two self-contact
// formulations - a barrier (HalfTurnSelfContact, self_contact.hpp; cases/plectoneme.toml), which
// continuation follows from the untwisted rod through the loop's closing into the ply, and hard
// contact in the shooting core (hard_ply_definition below), the ply lying exactly on the cylinder
// of radius R about the axis, with complementarity.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kirchhoff/contact/self_contact.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// The obstacle a hard-contact plectoneme lies on (hard_ply_definition) is named this.
inline constexpr const char* kHalfTurnContactName = "half-turn self-contact";

// The half-turn geometry of a plectoneme problem at parameters p: its barrier's, or that of the
// cylinder its hard contact lies on; empty for other problems.
std::optional<HalfTurnGeometry> half_turn_geometry(const ShootingProblem& problem, const Parameters& p);

// Hard self-contact: the barrier problem `barrier` (a HalfTurnSelfContact in its rod) with the
// barrier removed and the half rod touching the cylinder of radius R about the half-turn axis
// where `contacts` say (obstacle 0, in order along the rod): at points, and over intervals where
// it lies on the cylinder with the pressure that keeps it there and concentrated forces at both
// ends (rod_on_cylinder.hpp). The ply of a plectoneme is a line contact with an isolated contact
// point beside it at each end (ply_contacts, hard_self_contact.hpp, reads the set off the
// discretised hard solution). The strands of the whole rod then touch exactly (rho = R, not R +
// the barrier's gap); complementarity off the contacts is checked, not imposed (min_contact_force,
// min_wrap_pressure, ply_clearance, self_distance). The cylinder
// moves with the parameters (the slenderness sets R). Throws std::invalid_argument when the barrier
// problem has no half-turn self-contact or its rod has another field besides, or the contacts are
// out of order.
// Its segments are set per piece by length (at most R long on the line contacts and on the gaps
// between contacts, 5 R on the tail and the end loop), not the barrier's.
ProblemDefinition hard_ply_definition(const ProblemDefinition& barrier, const std::vector<PointContact>& contacts);

// The hard-contact problem for a solved barrier plectoneme with the contact set given, and its
// unknowns from the barrier solution's states at its nodes. Newton takes it from there to the
// hard solution.
struct HardPlyStart {
  ProblemDefinition definition;
  Eigen::VectorXd x;
};
HardPlyStart hard_ply_from_barrier(const ShootingProblem& barrier, const Eigen::VectorXd& x,
                                   const std::vector<PointContact>& contacts);

// A solved hard ply (`hard` at x) re-segmented by length at x's parameters: its contacts as
// solved, its unknowns from its own solution at the new nodes. Continuation in slenderness moves
// the nodes with R but keeps their count, so a thinner rod's line contact has fewer segments per R
// than hard_ply_definition gives it; `barrier` is the definition the hard problem was made from.
HardPlyStart resegmented_hard_ply(const ProblemDefinition& barrier, const ShootingProblem& hard,
                                  const Eigen::VectorXd& x);

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
  // there by ~ exp(-loop_clearance^2) times the barrier's scale, negligible beyond ~4. NaN with
  // hard contact.
  double loop_clearance = NAN;
  // Hard contact only (NaN with the barrier): the smallest (rho - R)/R at the gaps between the
  // ply's contacts (a point contact beside the line contact at each end of the ply, say); where
  // it reaches 0 a new contact forms. NaN when the ply has no such gap. (The contacts' forces and
  // pressures are the derived quantities min_contact_force and min_wrap_pressure.)
  bool hard = false;
  double ply_clearance = NAN;
};

// Cross-sections pressed with less than this fraction of the largest contact force per length
// are outside the contact region (the barrier's force falls like exp(-(g/c)^2)/g^2 away from
// contact, so the threshold moves the region's ends by a small fraction of the range c).
constexpr double kContactFraction = 0.01;

// A self_distance below 1 - this is the rod passing through itself: at the hard contacts it is 1
// to the constraint's accuracy (1e-12 measured), and the bar is 2R (1 - 1e-9).
constexpr double kSelfDistanceSlack = 1e-9;

// Throws std::invalid_argument when the problem has no half-turn self-contact.
PlectonemeMeasures measure_plectoneme(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                      const std::vector<RodPoint>& profile);

// The derived quantities measure_plectoneme provides: name, meaning, and the measure it reads (one
// table, so that a name cannot lack its value or its meaning).
struct PlectonemeQuantity {
  std::string name;
  std::string meaning;
  double PlectonemeMeasures::*value;
};
const std::vector<PlectonemeQuantity>& plectoneme_quantities();

}  // namespace kirchhoff

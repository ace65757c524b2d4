// Refusing continuation steps that carry a rod through itself.
//
// Why. A plectoneme's self-contact (self_contact.hpp) is a barrier on each cross-section's
// distance to the symmetry axis, felt only where the integrator evaluates it; a continuation
// step is a jump, and its corrector may converge on the other side of the barrier: a strand
// that was in front of its partner ends up behind it, the linking number changes by a whole
// number, and the branch continues as the contact-free one with the rod passed through itself
// (seen at L/2R = 500 where the end loop closes, with steps that are otherwise safe). No
// property of the new point alone shows it. What does is the motion between the two points:
// move every cross-section on the straight line from its old to its new place; if no two
// cross-sections that are not neighbours along the rod come close on the way, the two
// configurations are deformed into each other without the rod crossing itself, so the step kept
// the topology (the linking number with the clamps). A step that brings two of them within half
// the contact distance, R, is refused and retried shorter: a short step of a branch that does
// not pass through itself passes.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "kirchhoff/contact/self_contact.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/shooting/shooting.hpp"

namespace kirchhoff {

// The closest two cross-sections come while the rod moves from one configuration to another.
struct SelfPassage {
  double distance = INFINITY;  // INFINITY: no pair came within the reach looked at
  double s_first = NAN, s_second = NAN;  // their arclengths along the whole rod
  double t = NAN;  // where along the motion (0: the first configuration, 1: the second)
};

// `from` and `to` sample the whole rod at the same arclengths; every cross-section moves on the
// straight line between its two places. Pairs more than `apart` apart along the rod and closer
// than `reach` at some moment are looked at.
SelfPassage closest_approach_in_motion(const std::vector<WholeRodSection>& from,
                                       const std::vector<WholeRodSection>& to, double apart, double reach);

// A ContinuationOptions::step_check for a plectoneme problem (a HalfTurnSelfContact in its rod, or
// hard contact: half_turn_geometry, plectoneme.hpp): refuses a
// step along which two cross-sections more than pi R apart along the rod come within R of each
// other (the whole rod sampled R/2 apart, so a pair that meets between samples is still caught).
// Each point's samples cost one integration without sensitivities (the newest is kept for the
// next step). Throws std::invalid_argument when the rod has no half-turn self-contact.
class SelfPassageGuard {
 public:
  SelfPassageGuard(const ShootingProblem& problem, std::string parameter);
  // Empty when the step keeps the rod from passing through itself; otherwise why not.
  std::string operator()(const ContinuationPoint& from, const ContinuationPoint& to);

 private:
  // The half-turn geometry at a point (its parameter set on the guard's problem).
  HalfTurnGeometry geometry_at(const ContinuationPoint& point);
  // The whole rod of a point sampled at `intervals` equal intervals of the half rod.
  std::vector<WholeRodSection> whole_rod_at(const ContinuationPoint& point, int intervals);

  // The newest point's samples: the next step starts from it.
  struct Sampled {
    double parameter;
    Eigen::VectorXd x;
    int intervals;
    std::vector<WholeRodSection> rod;
  };
  std::shared_ptr<ShootingProblem> problem_;  // shared: std::function copies the guard
  std::string parameter_;
  std::shared_ptr<Sampled> newest_;
};

// Sets options->step_check to a SelfPassageGuard for a plectoneme problem; returns whether it did.
bool guard_self_passage(const ShootingProblem& problem, ContinuationOptions* options);

}  // namespace kirchhoff

// What a continuation of a rod records at each point: the rod layer's record hook
// (RecordOptions::recorder; BifurcationKit's record_from_solution is the model).
//
// The engine (continuation.hpp) knows the unknowns, the parameter and the tangent of a point, not
// what they mean. This hook describes a point as a rod: its derived quantities (the events' test
// values), the solution checks (verification.hpp: a profile with NaN, a rod beyond its soft wall),
// the invariants with the flatness of H, and, for points put on the branch only, the stability
// index.
#pragma once

#include "kirchhoff/continuation/rod_continuation.hpp"
#include "kirchhoff/equations/invariants.hpp"

namespace kirchhoff {

// What the rod layer keeps of a point beside the engine's fields (PointRecord::extra): the
// invariants along the rod and whether H is flat.
struct RodPointInvariants {
  InvariantReport invariants;
  bool H_flat = true;  // false flags a point whose H spread exceeds 1e-9 of its scale
};

// A point's invariants (none - every one not applying - where the recorder kept none, e.g. with
// compute_invariants off) and whether its H is flat (true where none were kept).
const InvariantReport& invariants_of(const PointRecord& point);
bool H_is_flat(const PointRecord& point);

// The recorder a RodContinuation uses when its options give none:
//   describe (once per corrected point, when compute_invariants is set or `derived` names any
//     quantity): one make_solution with `samples` profile points -> derived (and the parameters
//     solved for), the invariants and H's flatness (RodPointInvariants, in extra), check_failure;
//   record (once per point on the branch, with compute_stability): stability_index, zero_modes.
PointRecorder rod_point_recorder(const RodRecordOptions& options, const std::vector<std::string>& derived);

}  // namespace kirchhoff

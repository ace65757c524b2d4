// What a continuation of a rod records at each point: the rod layer's record hook
// (ContinuationOptions::recorder; BifurcationKit's record_from_solution is the model).
//
// The engine (continuation.hpp) knows the unknowns, the parameter and the tangent of a point, not
// what they mean. This hook describes a point as a rod: its derived quantities (the events' test
// values), the solution checks (verification.hpp: a profile with NaN, a rod beyond its soft wall),
// the invariants with the flatness of H, and, for points put on the branch only, the stability
// index.
#pragma once

#include "kirchhoff/continuation/continuation.hpp"

namespace kirchhoff {

// The recorder a Continuation uses when its options give none, from the options' rod fields:
//   describe (once per corrected point, when compute_invariants or derived is set): one
//     make_solution with `samples` profile points -> derived (and the parameters solved for),
//     invariants, H_flat, check_failure;
//   record (once per point on the branch, with compute_stability): stability_index, zero_modes.
PointRecorder rod_point_recorder(const ContinuationOptions& options);

}  // namespace kirchhoff

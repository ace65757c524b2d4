// The special points of a continuation as detector objects, run by one loop in
// Continuation::march (BifurcationKit's events are the model). Internal to the engine.
//
// A detector has a test value at each point; where it changes sign inside a step (or, for the
// branch points of even multiplicity, where it has a small local minimum) the detector locates the
// zero on the step and hands the located point to the march, which puts every point found inside
// the step on the branch in order along it and then lets the detector act on it (count it, end
// the run). The detectors, in the order they look at a step:
//   target        parameter - target               Endpoint     ends the run (reached_target)
//   bounds        parameter - parameter_min/max    Endpoint     ends the run (parameter_bounds)
//   fold          lambda component of the tangent  Fold         ends it with stop_at_fold
//   branch point  det [F_x F_lambda; t^T]          BranchPoint  counted; stop_at_branch_point
//   branch point  smallest singular value, minimal over two steps and below branch_point_tolerance
//                 (even multiplicity: the determinant keeps its sign)
//   events        a derived quantity - its value   Event        ends the run when `stop`
//   index change  the stability index, where no    IndexChange  (reported)
//                 fold or branch point in the step
//                 accounts for its change (bisection)
// (Contact continuations turn their changes of the active set into stopping events: contact.hpp.)
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kirchhoff/continuation/continuation.hpp"

namespace kirchhoff::detail {

using TestFunction = std::function<double(const ContinuationPoint&)>;
// Continuation::locate: the point on the step from `from` (of length at most h_max) where the
// test function vanishes (minimise = false) or is minimal (true), typed `type`.
using Locator = std::function<std::optional<ContinuationPoint>(const ContinuationPoint& from, double h_max,
                                                               const TestFunction& test, bool minimise, PointType type)>;
// Continuation::at_parameter: a located point corrected again at exactly that parameter value
// (empty if that fails).
using ParameterPin = std::function<std::optional<ContinuationPoint>(const ContinuationPoint& located, double value)>;
// The point a step h from the step's current point, corrected and recorded (its stability index
// computed), as the march's own would be; empty where the corrector fails.
using RecordedStep = std::function<std::optional<ContinuationPoint>(double h)>;

// One step of the march, current -> candidate, as the detectors see it.
struct StepView {
  const ContinuationPoint& current;
  const ContinuationPoint& candidate;
  const ContinuationPoint* before;  // the point before `current` (null at the start of a march)
  double h;                         // the step current -> candidate
  double previous_h;                // the step before -> current
  bool just_reported_branch_point;  // the step that reached `current` found a branch point
  bool can_shrink;                  // the step may still be halved (above the minimum step)
  Locator locate;
  ParameterPin pin;
  RecordedStep recorded_step;
};

// The counts the detectors' actions keep over a march (saved in MarchState).
struct MarchCounters {
  int branch_points_found = 0;
};

// Why a run ends, with its message.
using Stop = std::pair<StopReason, std::string>;

class Detector;
// A special point located inside a step, by `detector`; `stop`: a step holding it ends the run at
// its first end point (or, for events, event point) with this reason.
struct Detection {
  ContinuationPoint point;
  std::optional<StopReason> stop;
  const Detector* detector = nullptr;
  bool recorded = false;  // the detector recorded the point itself (and settled its index)
};

enum class Verdict {
  Nothing,       // no special point of this detector inside the step
  Found,         // located and appended
  RetryShorter,  // the step must be taken again, shorter (a location that missed)
};

class Detector {
 public:
  virtual ~Detector() = default;
  // Looks for this detector's special point inside the step; appends it, located, to `found`
  // (which holds those of the detectors that looked before).
  virtual Verdict detect(const StepView& step, std::vector<Detection>* found) const = 0;
  // What a point it found does once on the branch: a stop ends the run there.
  virtual std::optional<Stop> act(const ContinuationPoint& point, MarchCounters* counters) const;
};

// The detectors of a run with these options (n unknowns, the parameter last in a tangent).
std::vector<std::unique_ptr<Detector>> make_detectors(const ContinuationOptions& options, int n);

}  // namespace kirchhoff::detail

#include "kirchhoff/continuation/detail/continuation_detectors.hpp"

#include <algorithm>
#include <cmath>

namespace kirchhoff::detail {
namespace {

// The located end point of a run with a target is accepted this close to it (relative).
constexpr double kTargetTolerance = 1e-9;

// An even branch point's located minimum of the smallest singular value lies at least this far
// below the farther of the two steps' outer ends (which is at least one step from it, where a true
// branch point's singular value grows linearly away from zero). Below branch_point_tolerance alone is
// not enough: on a badly scaled problem (a column on a stiff foundation) the smallest singular value
// is ~1e-13 at every point, and its shallow ripples were reported as branch points.
constexpr double kBranchPointDrop = 1e-3;

// An index change (IndexChange) is located to this fraction of its step: 27 bisections.
constexpr double kIndexChangeBisection = 1e-8;

// Whether `located` lies kBranchPointDrop below the farther of the step's ends in the smallest
// singular value, as a branch point does; nullopt where the ends are below `tolerance` themselves
// (a badly scaled problem, ~1e-13 at every point on a stiff foundation, or plectoneme.toml's
// 20-segment matrix): the singular values then say nothing.
std::optional<bool> singular_against_ends(const ContinuationPoint& located, const StepView& step, double tolerance) {
  const double farther = std::max(step.current.smallest_singular, step.candidate.smallest_singular);
  if (!(farther >= tolerance)) return std::nullopt;
  return located.smallest_singular < kBranchPointDrop * farther;
}

// A sign change between a and b (a = 0 exactly is where the last point was located: none).
bool crossed(double a, double b) { return std::isfinite(a) && std::isfinite(b) && (a < 0) != (b < 0) && a != 0.0; }

// A branch point's multiplicity: how many more singular values of the bordered matrix are small
// (below branch_point_tolerance of the largest) at the located point than at the regular point
// beside it. Not their count alone: on a badly scaled problem (a stiff foundation in multiple
// shooting, whose matrix spans many orders of magnitude by nature) several are that small at every
// point, and each simple branch point counted 8 or 9.
int multiplicity(const ContinuationPoint& located, const ContinuationPoint& regular) {
  return std::max(1, located.small_count - regular.small_count);
}

// A detector whose test value changes sign inside the step: located by the secant method on h.
class SignChange : public Detector {
 public:
  Verdict detect(const StepView& step, std::vector<Detection>* found) const override {
    const TestFunction test = [this](const ContinuationPoint& p) { return value(p); };
    if (!crossed(value(step.current), value(step.candidate))) return Verdict::Nothing;
    auto p = step.locate(step.current, step.h, test, false, type());
    // A target or an event whose crossing could not be located (a corrector failed on the
    // locator's first trial) is not passed over (a run in log_b on the soft wall marched on past
    // its target): the step is retried shorter while it can be. A fold's or a branch point's is,
    // as before: their correctors fail where the bordered matrix is near singular, which a
    // shorter step approaches rather than avoids.
    if (!p) return must_locate() && step.can_shrink ? Verdict::RetryShorter : Verdict::Nothing;
    if (!close_enough(step, *p) && step.can_shrink) return Verdict::RetryShorter;
    refine(step, &*p);
    finish(step, &*p);
    found->push_back({std::move(*p), stop(), this});
    return Verdict::Found;
  }

 protected:
  virtual double value(const ContinuationPoint& p) const = 0;
  virtual PointType type() const = 0;
  virtual std::optional<StopReason> stop() const { return std::nullopt; }
  // False: the located point missed (a corrector failed inside the step, or left the branch) and
  // the step is retried shorter while it can be.
  virtual bool close_enough(const StepView&, const ContinuationPoint&) const { return true; }
  // True: a crossing whose location failed retries the step shorter instead of being passed over.
  virtual bool must_locate() const { return false; }
  // The located point made exact where the test function allows it (the parameter's value).
  virtual void refine(const StepView&, ContinuationPoint*) const {}
  virtual void finish(const StepView&, ContinuationPoint*) const {}
};

// The parameter reaching a value: the target, or a bound.
class ParameterValue : public SignChange {
 public:
  ParameterValue(double value, StopReason reason) : value_(value), reason_(reason) {}

 protected:
  double value(const ContinuationPoint& p) const override { return p.parameter - value_; }
  PointType type() const override { return PointType::Endpoint; }
  std::optional<StopReason> stop() const override { return reason_; }
  bool must_locate() const override { return true; }
  // A corrector that failed inside the step leaves the location short of the target (or the whole
  // step's point, beyond it): retried with a shorter step rather than stopped off the target.
  bool close_enough(const StepView&, const ContinuationPoint& p) const override {
    return reason_ != StopReason::ReachedTarget || near(p);
  }
  // The secant leaves the parameter within round-off of the value, on whichever side; corrected
  // again at the value itself, the end lies on it (a run started from it sets exactly that value).
  // Kept as located if that corrector fails.
  void refine(const StepView& step, ContinuationPoint* p) const override {
    if (p->parameter == value_ || !near(*p)) return;
    if (auto pinned = step.pin(*p, value_)) *p = std::move(*pinned);
  }

 private:
  bool near(const ContinuationPoint& p) const {
    return std::abs(p.parameter - value_) <= kTargetTolerance * std::max(1.0, std::abs(value_));
  }
  double value_;
  StopReason reason_;
};

class Fold : public SignChange {
 public:
  Fold(int n, bool stops, std::string parameter) : n_(n), stops_(stops), parameter_(std::move(parameter)) {}
  std::optional<Stop> act(const ContinuationPoint& p, MarchCounters*) const override {
    if (!stops_) return std::nullopt;
    return Stop{StopReason::FoldStop, "fold at " + parameter_ + " = " + std::to_string(p.parameter)};
  }

 protected:
  double value(const ContinuationPoint& p) const override { return p.tangent[n_]; }
  PointType type() const override { return PointType::Fold; }

 private:
  int n_;
  bool stops_;
  std::string parameter_;
};

// Both branch-point detectors count what they find against stop_at_branch_point.
std::optional<Stop> count_branch_point(int stop_at, MarchCounters* counters) {
  ++counters->branch_points_found;
  if (stop_at > 0 && counters->branch_points_found >= stop_at)
    return Stop{StopReason::BranchPointStop, "branch point " + std::to_string(counters->branch_points_found)};
  return std::nullopt;
}

class SimpleBranchPoint : public SignChange {
 public:
  SimpleBranchPoint(int stop_at, double tolerance) : stop_at_(stop_at), tolerance_(tolerance) {}
  std::optional<Stop> act(const ContinuationPoint&, MarchCounters* counters) const override {
    return count_branch_point(stop_at_, counters);
  }

 protected:
  double value(const ContinuationPoint& p) const override { return p.determinant; }
  PointType type() const override { return PointType::BranchPoint; }
  // The located point's smallest singular value lies kBranchPointDrop below the farther of the
  // step's ends, as a branch point's does. Where the secant's trials left the branch (near a
  // branch point a long step's corrector can land on the crossing branch, whose determinant
  // wrecks the bracket) it does not: the anisotropic turned rod of tests/continue_cli_test.cpp at
  // B1 = 2 and --max-step 5 had its branch point located at turns 0.506293 (singular value 1.1e-6,
  // ends 2.3e-5 and 1.5e-6) instead of 0.508580 (1.3e-17), and with --max-step 20 at 0.508476
  // (5.1e-8 against ends of 1.3e-5). The step is then taken again, shorter. Where the singular
  // values say nothing (singular_against_ends), the determinant's location stands.
  bool close_enough(const StepView& step, const ContinuationPoint& p) const override {
    return singular_against_ends(p, step, tolerance_).value_or(true);
  }
  void finish(const StepView& step, ContinuationPoint* p) const override {
    p->multiplicity = multiplicity(*p, step.current);
  }

 private:
  int stop_at_;
  double tolerance_;
};

// Branch points that keep the determinant's sign (even multiplicity): a local minimum of the
// smallest singular value over the last two steps that is, once located, tiny and far below the
// steps' ends (kBranchPointDrop). Skipped where the determinant found one in this step, and right
// after a branch point was reported (the minimum is that point again).
class EvenBranchPoint : public Detector {
 public:
  EvenBranchPoint(int stop_at, double tolerance) : stop_at_(stop_at), tolerance_(tolerance) {}
  Verdict detect(const StepView& step, std::vector<Detection>* found) const override {
    const bool simple = std::any_of(found->begin(), found->end(),
                                    [](const Detection& d) { return d.point.type == PointType::BranchPoint; });
    if (simple || !step.before || step.just_reported_branch_point ||
        !(step.current.smallest_singular < step.before->smallest_singular &&
          step.current.smallest_singular < step.candidate.smallest_singular))
      return Verdict::Nothing;
    auto p = step.locate(*step.before, step.previous_h + step.h,
                         [](const ContinuationPoint& q) { return q.smallest_singular; }, true,
                         PointType::BranchPoint);
    const double farther_end = std::max(step.before->smallest_singular, step.candidate.smallest_singular);
    if (!p || !(p->smallest_singular < tolerance_) || !(p->smallest_singular < kBranchPointDrop * farther_end))
      return Verdict::Nothing;
    // Of the step's two ends beside the minimum, the one with fewer small singular values.
    p->multiplicity = multiplicity(*p, step.before->small_count <= step.candidate.small_count ? *step.before : step.candidate);
    // It may lie just behind `current` (already recorded): points are in detection order.
    found->push_back({std::move(*p), std::nullopt, this});
    return Verdict::Found;
  }
  std::optional<Stop> act(const ContinuationPoint&, MarchCounters* counters) const override {
    return count_branch_point(stop_at_, counters);
  }

 private:
  int stop_at_;
  double tolerance_;
};

// A derived quantity crossing a value (the recorder's `derived`; NaN where it has none).
class Event : public SignChange {
 public:
  Event(ContinuationEvent event, int index) : event_(std::move(event)), index_(index) {}

 protected:
  double value(const ContinuationPoint& p) const override {
    const auto it = p.derived.find(event_.quantity);
    return it == p.derived.end() ? NAN : it->second - event_.value;
  }
  PointType type() const override { return PointType::Event; }
  bool must_locate() const override { return true; }
  std::optional<StopReason> stop() const override {
    return event_.stop ? std::optional<StopReason>(StopReason::EventStop) : std::nullopt;
  }
  void finish(const StepView&, ContinuationPoint* p) const override {
    p->event = event_.label.empty() ? event_.quantity + "=" + std::to_string(event_.value) : event_.label;
    p->event_index = index_;
  }

 private:
  ContinuationEvent event_;
  int index_;
};

// A change of the stability index inside the step that no fold or branch point found in it (by
// the detectors before this one) accounts for: a bifurcation that the problem's Jacobian does not
// see, such as one that breaks the symmetry of a problem posed on half a rod, or a branch point
// the branch-point tests missed. The index is an integer, so the change is located by bisection
// on the step, each trial corrected and recorded as the march's own point, to
// kIndexChangeBisection of the step. Near the change the crossing eigenvalue is within the
// index's resolution and a trial counts it as a zero mode (index min(a, b), the extra zero
// modes): that window is symmetric about the crossing (the eigenvalue is linear along the branch
// there), so where a trial falls inside it both its edges are located too and the point is taken
// at their middle (unless that trial is singular: the branch point below); otherwise at the
// bracket's far end. A trial whose index is undefined or another keeps the bracket it has.
//  - Where the located point's bordered matrix is singular (its smallest singular value far
//    below the step's ends, which are not below the tolerance themselves), it is the problem's
//    own branch point, which the tests missed: one of even multiplicity between two long steps'
//    samples of the singular value (the twisted rod's second Greenhill point at --max-step 20,
//    with a third one in the next step). It is reported as a branch point, its minimum located
//    as EvenBranchPoint does; a branch point reported in a step keeps EvenBranchPoint from
//    reporting it again from the next.
//  - Otherwise an index_change row, with the index of a singular point
//    (singular_point_index.hpp): the smaller of the two, and the eigenvalues that cross as zero
//    modes beside the ends' own.
// Not where either end's index is undefined, where the ends' zero modes differ (one side counts
// the crossing eigenvalue as a zero mode, still within its resolution, as just past a branch
// point the branch starts from: no other crossing), where the step starts at a special point
// (whose own index is its neighbours' business), or where a stopping event ends the run inside
// the step (a contact continuation's change of the active set, where the index may change by
// itself). Where the target or a bound of the parameter ends it, the change is looked for up to
// there, against the index at the run's end: the twisted rod's third Greenhill point (phi =
// 28.3507) in the last step of `--to 30 --max-step 20` from phi = 1 had no row, the index
// jumping 4 -> 6 at the endpoint.
class IndexChange : public Detector {
 public:
  // `singular_below`: where branch points are detected, their tolerance (0: they are not); the
  // step's ends below it leave the singular values nothing to say. `stop_at`: as the branch-point
  // detectors', for the branch points it finds.
  IndexChange(double singular_below, int stop_at) : singular_below_(singular_below), stop_at_(stop_at) {}
  Verdict detect(const StepView& step, std::vector<Detection>* found) const override {
    const std::optional<int> a = step.current.stability_index;
    if (!a || !step.candidate.stability_index || *a == *step.candidate.stability_index || !step.recorded_step)
      return Verdict::Nothing;
    if (step.current.type != PointType::Start && step.current.type != PointType::Regular) return Verdict::Nothing;
    const Detection* end = parameter_end(*found);
    if (std::any_of(found->begin(), found->end(), [&](const Detection& d) { return d.stop && &d != end; }))
      return Verdict::Nothing;
    // The crossings that the folds and branch points found inside the step account for: one at a
    // fold, the multiplicity at a branch point. Fewer than the index changes by leave one
    // unlocated - two simple branch points in one step, of which the tests saw one (the anisotropic
    // twisted rod, B2 = 2 B1, at --max-step 2: one row at phi = 14.9608 with index 0 and two zero
    // modes, the point at 13.6625 and the index 1 between them missing) - and the step is taken
    // again, shorter, while it can be.
    // (A branch point located just behind the step's start, as EvenBranchPoint may, leaves the
    // step to its rows, as before.)
    const bool singular = std::any_of(found->begin(), found->end(), [](const Detection& d) {
      return d.point.type == PointType::Fold || d.point.type == PointType::BranchPoint;
    });
    // The far side: the candidate, or the point where the run ends inside the step.
    double far = step.h;
    std::optional<ContinuationPoint> at_end;
    if (end) {
      far = end->point.arclength - step.current.arclength;
      if (!(far > 0.0 && far <= step.h) || !(at_end = step.recorded_step(far))) return Verdict::Nothing;
    }
    const ContinuationPoint& far_point = at_end ? *at_end : step.candidate;
    const std::optional<int> b = far_point.stability_index;
    if (singular) {
      const int crossings = explained_crossings(step, *found, step.current.arclength + far);
      const bool unexplained = crossings > 0 && b && std::abs(*a - *b) > crossings;
      return unexplained && step.can_shrink ? Verdict::RetryShorter : Verdict::Nothing;
    }
    if (!b || *a == *b || step.current.zero_modes != far_point.zero_modes) return Verdict::Nothing;
    // Where branch points are detected, a change at one of them (of even multiplicity, which the
    // determinant does not see, and which the two-step minimum misses with long steps) is looked
    // for first as the minimum of the smallest singular value over the step, whose trials are
    // corrected but not recorded: the index's bisection below records each of its trials with its
    // index (about 15 to reach the window at the twisted rod's Greenhill point). A minimum that is
    // not singular leaves the change to the bisection.
    if (singular_below_ > 0) {
      if (auto p = singular_minimum(step, far)) {
        if (std::max(1, p->multiplicity) >= std::abs(*a - *b)) {
          found->push_back({std::move(*p), std::nullopt, this});
          return Verdict::Found;
        }
        if (step.can_shrink) return Verdict::RetryShorter;  // another crossing in the step besides it
      }
    }
    const int crossing_zero_modes = step.current.zero_modes + std::abs(*a - *b);
    const Sides sides{*a, *b, crossing_zero_modes};
    const double tolerance = kIndexChangeBisection * far;
    Bracket outer{0.0, far};
    std::optional<ContinuationPoint> located;  // the nearest trial on b's side, or in the window
    double at = far;                           // where along the step
    double window = -1.0;                      // where a trial fell inside the window
    // The side of the change at h along the step (the trial kept in *trial), empty where its
    // corrector failed or its index is neither side's.
    const auto side_at = [&](double h, std::optional<ContinuationPoint>* trial) -> std::optional<int> {
      *trial = step.recorded_step(h);
      return *trial ? sides.of(**trial) : std::nullopt;
    };
    while (outer.width() > tolerance) {
      std::optional<ContinuationPoint> trial;
      const std::optional<int> side = side_at(outer.middle(), &trial);
      // A trial with an index strictly between the ends', decisively (no zero mode beyond theirs),
      // shows as many crossings in the step at different places: the anisotropic twisted rod's two
      // simple branch points at phi = 13.6625 and 14.9608 in one step of --max-step 2 (index 0, 1
      // between them, 2), whose determinant kept its sign. Each needs a step of its own.
      if (!side && trial && sides.strictly_between(*trial, step.current.zero_modes))
        return step.can_shrink ? Verdict::RetryShorter : Verdict::Nothing;
      if (!side) break;
      if (*side >= 0) located = std::move(trial), at = outer.middle();
      if (*side == 0) {
        window = outer.middle();
        break;
      }
      (*side < 0 ? outer.lo : outer.hi) = outer.middle();
    }
    // A window trial that is singular against the step's ends marks the problem's own branch point
    // (below): its edges, another two bisections of the index (31 trials at the twisted rod's first
    // Greenhill point, each corrected with its index), would only centre the point the minimum
    // of the singular value is located from, which brackets it from either side.
    const bool window_is_singular =
        window >= 0 && located && singular_against_ends(*located, step, singular_below_).value_or(false);
    if (window >= 0 && !window_is_singular) {
      // The window's edges: a's side against it below, b's side above.
      Bracket below{outer.lo, window}, above{window, outer.hi};
      for (Bracket* edge : {&below, &above})
        while (edge->width() > tolerance) {
          std::optional<ContinuationPoint> trial;
          const std::optional<int> side = side_at(edge->middle(), &trial);
          if (!side) break;
          const bool in_window = *side == 0;
          ((edge == &below) == in_window ? edge->hi : edge->lo) = edge->middle();
        }
      at = 0.5 * (below.lo + above.hi);
      if (auto middle = step.recorded_step(at)) located = std::move(middle);
    }
    if (!located) return Verdict::Nothing;  // not located inside the step: the rows show the change alone
    if (singular_against_ends(*located, step, singular_below_).value_or(false)) {
      found->push_back({branch_point(step, std::move(*located), at), std::nullopt, this});
      return Verdict::Found;
    }
    located->type = PointType::IndexChange;
    located->stability_index = std::min(*a, *b);
    located->zero_modes = crossing_zero_modes;
    found->push_back({std::move(*located), std::nullopt, this, true});
    return Verdict::Found;
  }
  std::optional<Stop> act(const ContinuationPoint& p, MarchCounters* counters) const override {
    if (p.type != PointType::BranchPoint) return std::nullopt;
    return count_branch_point(stop_at_, counters);
  }

 private:
  // The index changes that the folds and branch points in `found` between the step's start and
  // the arclength up_to account for (0 where they all lie behind the start).
  static int explained_crossings(const StepView& step, const std::vector<Detection>& found, double up_to) {
    int crossings = 0;
    for (const Detection& d : found) {
      if (!(d.point.arclength > step.current.arclength) || d.point.arclength > up_to) continue;
      if (d.point.type == PointType::Fold) crossings += 1;
      if (d.point.type == PointType::BranchPoint) crossings += std::max(1, d.point.multiplicity);
    }
    return crossings;
  }

  // The detection of the parameter's target or bound ending the run inside the step, if any.
  static const Detection* parameter_end(const std::vector<Detection>& found) {
    for (const Detection& d : found)
      if (d.stop == StopReason::ReachedTarget || d.stop == StopReason::ParameterBounds) return &d;
    return nullptr;
  }

  // The minimum of the smallest singular value over [0, h] of the step from its current point.
  static std::optional<ContinuationPoint> singular_value_minimum(const StepView& step, double h) {
    return step.locate(step.current, h, [](const ContinuationPoint& q) { return q.smallest_singular; }, true,
                       PointType::BranchPoint);
  }

  // p as a branch point, its multiplicity counted against the step's end with fewer small singular
  // values.
  static ContinuationPoint as_branch_point(const StepView& step, ContinuationPoint p) {
    p.type = PointType::BranchPoint;
    p.multiplicity = multiplicity(p, step.current.small_count <= step.candidate.small_count ? step.current : step.candidate);
    return p;
  }

  // The minimum of the smallest singular value over [0, far] of the step, as a branch point,
  // where it is singular against the step's ends; none otherwise.
  std::optional<ContinuationPoint> singular_minimum(const StepView& step, double far) const {
    auto minimum = singular_value_minimum(step, far);
    if (!minimum || !singular_against_ends(*minimum, step, singular_below_).value_or(false)) return std::nullopt;
    return as_branch_point(step, std::move(*minimum));
  }

  // The branch point near `near` (at h = at along the step): the minimum of the smallest singular
  // value over [0, 2 at] from the current point, which `near` brackets in its middle (as
  // EvenBranchPoint locates one), or `near` itself where that finds none lower. Recorded when put
  // on the branch, where its neighbours settle its index.
  ContinuationPoint branch_point(const StepView& step, ContinuationPoint near, double at) const {
    auto minimum = singular_value_minimum(step, 2.0 * at);
    return as_branch_point(step, minimum && minimum->smallest_singular < near.smallest_singular ? std::move(*minimum)
                                                                                                : std::move(near));
  }

  double singular_below_;
  int stop_at_;
  struct Bracket {
    double lo, hi;
    double width() const { return hi - lo; }
    double middle() const { return 0.5 * (lo + hi); }
  };
  // Which side of the change a recorded trial is on: -1 a's, +1 b's, 0 inside the window (the
  // smaller index with the crossing eigenvalues among its zero modes); empty: neither.
  struct Sides {
    int a, b, window_zero_modes;
    std::optional<int> of(const ContinuationPoint& p) const {
      if (!p.stability_index) return std::nullopt;
      const int index = *p.stability_index;
      if (index == std::min(a, b) && p.zero_modes >= window_zero_modes) return 0;
      if (index == a) return -1;
      if (index == b) return +1;
      return std::nullopt;
    }
    // Whether p's index lies strictly between a and b with no zero modes beyond `zero_modes`.
    bool strictly_between(const ContinuationPoint& p, int zero_modes) const {
      return p.stability_index && *p.stability_index > std::min(a, b) && *p.stability_index < std::max(a, b) &&
             p.zero_modes <= zero_modes;
    }
  };
};

}  // namespace

std::optional<Stop> Detector::act(const ContinuationPoint&, MarchCounters*) const { return std::nullopt; }

std::vector<std::unique_ptr<Detector>> make_detectors(const ContinuationOptions& o, int n) {
  std::vector<std::unique_ptr<Detector>> d;
  if (!std::isnan(o.target)) d.push_back(std::make_unique<ParameterValue>(o.target, StopReason::ReachedTarget));
  for (double bound : {o.parameter_min, o.parameter_max})
    if (std::isfinite(bound)) d.push_back(std::make_unique<ParameterValue>(bound, StopReason::ParameterBounds));
  if (o.detect_folds) d.push_back(std::make_unique<Fold>(n, o.stop_at_fold, o.parameter));
  if (o.detect_branch_points) {
    d.push_back(std::make_unique<SimpleBranchPoint>(o.stop_at_branch_point, o.branch_point_tolerance));
    d.push_back(std::make_unique<EvenBranchPoint>(o.stop_at_branch_point, o.branch_point_tolerance));
  }
  for (size_t k = 0; k < o.events.size(); ++k) d.push_back(std::make_unique<Event>(o.events[k], static_cast<int>(k)));
  if (o.detect_index_changes)
    d.push_back(std::make_unique<IndexChange>(o.detect_branch_points ? o.branch_point_tolerance : 0.0,
                                              o.stop_at_branch_point));
  return d;
}

}  // namespace kirchhoff::detail

#include "kirchhoff/contact/self_passage.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "kirchhoff/contact/detail/spatial_bins.hpp"
#include "kirchhoff/contact/plectoneme.hpp"

namespace kirchhoff {

SelfPassage closest_approach_in_motion(const std::vector<WholeRodSection>& from,
                                       const std::vector<WholeRodSection>& to, double apart, double reach) {
  if (from.size() != to.size()) throw std::invalid_argument("closest_approach_in_motion: different samplings");
  std::vector<Vec3> middle(from.size());
  double largest_move = 0.0;
  for (size_t i = 0; i < from.size(); ++i) {
    middle[i] = 0.5 * (from[i].r + to[i].r);
    largest_move = std::max(largest_move, (to[i].r - from[i].r).norm());
  }
  // Two sections within `reach` at some moment have midpoints within reach + half of each
  // one's move: cubes of that side hold every such pair.
  SelfPassage closest;
  for_each_near_pair(middle, reach + largest_move, 1, [&](size_t i, size_t j) {
    if (std::abs(from[j].s_whole - from[i].s_whole) <= apart) return;
    const Vec3 a = from[i].r - from[j].r;
    const Vec3 b = (to[i].r - from[i].r) - (to[j].r - from[j].r);
    const double bb = b.squaredNorm();
    const double t = bb > 0.0 ? std::clamp(-a.dot(b) / bb, 0.0, 1.0) : 0.0;
    const double d = (a + t * b).norm();
    if (d < reach && d < closest.distance) closest = {d, from[i].s_whole, from[j].s_whole, t};
  });
  return closest;
}

SelfPassageGuard::SelfPassageGuard(const ShootingProblem& problem, std::string parameter)
    : problem_(std::make_shared<ShootingProblem>(problem)), parameter_(std::move(parameter)) {
  if (!half_turn_geometry(problem, problem.parameters()))
    throw std::invalid_argument("the self-passage guard needs a rod with [rod.self_contact]");
}

HalfTurnGeometry SelfPassageGuard::geometry_at(const ContinuationPoint& point) {
  problem_->set_parameter(parameter_, point.parameter);
  return *half_turn_geometry(*problem_, problem_->parameters_at(point.x));
}

std::vector<WholeRodSection> SelfPassageGuard::whole_rod_at(const ContinuationPoint& point, int intervals) {
  if (newest_ && newest_->intervals == intervals && newest_->parameter == point.parameter && newest_->x == point.x)
    return newest_->rod;
  const HalfTurnGeometry half_turn = geometry_at(point);
  const double Lh = half_turn.symmetry_s;
  std::vector<double> s(intervals + 1);
  for (int k = 0; k <= intervals; ++k) s[k] = Lh * k / intervals;
  auto rod = half_turn.whole_rod(problem_->sample(point.x, s));
  newest_ = std::make_shared<Sampled>(Sampled{point.parameter, point.x, intervals, std::move(rod)});
  return newest_->rod;
}

std::string SelfPassageGuard::operator()(const ContinuationPoint& from, const ContinuationPoint& to) {
  // The thinner rod's radius (a step in the slenderness changes it) and its sampling for both.
  const double R_from = geometry_at(from).radius;
  const HalfTurnGeometry at_to = geometry_at(to);
  const double R = std::min(R_from, at_to.radius), Lh = at_to.symmetry_s;
  // R/2 apart: two sections that meet between samples have sampled neighbours within ~R/2.
  const int intervals = static_cast<int>(std::ceil(Lh / (0.5 * R)));
  const std::vector<WholeRodSection> a = whole_rod_at(from, intervals);
  const std::vector<WholeRodSection> b = whole_rod_at(to, intervals);
  const SelfPassage p = closest_approach_in_motion(a, b, M_PI * R, R);
  if (!(p.distance < R)) return "";
  std::ostringstream why;
  why << "the step from " << parameter_ << " = " << from.parameter << " to " << to.parameter
      << " carries the rod through itself: cross-sections at s = " << p.s_first << " and " << p.s_second
      << " (whole rod) come within " << p.distance / R << " R of each other on the way";
  return why.str();
}

bool guard_self_passage(const ShootingProblem& problem, ContinuationOptions* options) {
  if (!half_turn_geometry(problem, problem.parameters())) return false;
  options->step_check = SelfPassageGuard(problem, options->parameter);
  return true;
}

}  // namespace kirchhoff

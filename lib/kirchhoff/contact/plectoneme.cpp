#include "kirchhoff/contact/plectoneme.hpp"

#include <algorithm>
#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "kirchhoff/contact/detail/spatial_bins.hpp"
#include "kirchhoff/contact/self_contact.hpp"
#include "kirchhoff/equations/detail/rod_on_cylinder.hpp"
#include "kirchhoff/equations/invariants.hpp"

namespace kirchhoff {
namespace {

// Position on the whole rod at arclength s (exact, by integrating the half rod).
Vec3 whole_position(const ShootingProblem& problem, const Eigen::VectorXd& x, const HalfTurnGeometry& half_turn,
                    double Lh, double s) {
  if (s <= Lh) return problem.sample(x, {std::max(0.0, s)}).front().r;
  return half_turn.image(problem.sample(x, {std::max(0.0, 2.0 * Lh - s)}).front().r);
}

struct SampledPair {
  size_t i, j;
  double distance;
};

// Closest pair of every stride-th section closer than `cell` in space and more than `apart`
// along the rod, if any.
std::optional<SampledPair> closest_pair_within(const std::vector<WholeRodSection>& rod, double apart, double cell,
                                               size_t stride) {
  std::vector<Vec3> centres;
  centres.reserve(rod.size());
  for (const auto& section : rod) centres.push_back(section.r);
  std::optional<SampledPair> best;
  for_each_near_pair(centres, cell, stride, [&](size_t i, size_t j) {
    if (rod[j].s_whole - rod[i].s_whole <= apart) return;
    const double d = (rod[i].r - rod[j].r).norm();
    if (d < cell && (!best || d < best->distance)) best = SampledPair{i, j, d};
  });
  return best;
}

// Closest pair of sections more than `apart` apart along the rod: the closest sampled pair
// (cubes from 4R up, doubling until a pair is that close; wider cubes look at fewer sections,
// as the refinement makes up for the coarser sampling), then alternating Brent minimisations in
// each arclength on exact positions (sampling alone could miss the minimum between samples
// and overstate the distance).
double smallest_self_distance(const ShootingProblem& problem, const Eigen::VectorXd& x,
                              const HalfTurnGeometry& contact, const std::vector<WholeRodSection>& rod, double apart,
                              double radius) {
  const double spacing = rod[1].s_whole - rod[0].s_whole;
  double extent = 0.0;
  for (const auto& section : rod) extent = std::max(extent, (section.r - rod.front().r).norm());
  std::optional<SampledPair> best;
  size_t stride = 1;
  for (double cell = 4.0 * radius; !best && cell < 4.0 * extent + 4.0 * radius; cell *= 2.0) {
    stride = std::max<size_t>(1, static_cast<size_t>(cell / (40.0 * spacing)));
    best = closest_pair_within(rod, apart, cell, stride);
  }
  if (!best) return NAN;
  const double Lh = 0.5 * rod.back().s_whole;
  const double h = stride * spacing;
  double si = rod[best->i].s_whole, sj = rod[best->j].s_whole;
  // 24 bits locate each arclength to ~1e-7 of a sample spacing: the distance to ~1e-14 of it.
  for (int sweep = 0; sweep < 2; ++sweep) {
    const Vec3 rj = whole_position(problem, x, contact, Lh, sj);
    auto di = [&](double s) { return (whole_position(problem, x, contact, Lh, s) - rj).norm(); };
    const double lo_i = std::max(0.0, si - h), hi_i = std::min(sj - apart, si + h);
    if (hi_i > lo_i) si = boost::math::tools::brent_find_minima(di, lo_i, hi_i, 24).first;
    const Vec3 ri = whole_position(problem, x, contact, Lh, si);
    auto dj = [&](double s) { return (whole_position(problem, x, contact, Lh, s) - ri).norm(); };
    const double lo_j = std::max(si + apart, sj - h), hi_j = std::min(2.0 * Lh, sj + h);
    if (hi_j > lo_j) sj = boost::math::tools::brent_find_minima(dj, lo_j, hi_j, 24).first;
  }
  const double refined = (whole_position(problem, x, contact, Lh, si) - whole_position(problem, x, contact, Lh, sj)).norm();
  return std::min(refined, best->distance);
}

// The helix of eqs. (58)-(61) is the middle of the ply: its ends bend into the tails and the end
// loop, so the angle, radius and pressure are averaged over the central half of the contact
// region [first, last] (profile indices).
void measure_helix(const ShootingProblem& problem, const Eigen::VectorXd& x, const std::vector<RodPoint>& profile,
                   const HalfTurnGeometry& half_turn, const std::vector<double>& pressure, size_t first, size_t last,
                   PlectonemeMeasures* m) {
  const size_t quarter = (last - first) / 4;
  double angle_sum = 0.0, pressure_sum = 0.0, radius_sum = 0.0;
  for (size_t i = first + quarter; i <= last - quarter; ++i) {
    const RodPoint& p = profile[i];
    angle_sum += std::acos(std::min(1.0, std::abs(p.R.col(2).dot(half_turn.axis))));
    radius_sum += half_turn.distance_to_axis(p.r);
    pressure_sum += pressure[i];
  }
  const double count = static_cast<double>(last - quarter - (first + quarter) + 1);
  m->helix_angle = angle_sum / count;
  m->helix_radius = radius_sum / count;
  m->contact_pressure = pressure_sum / count;
  const RodModel& model = problem.equations(problem.parameters_at(x))->model();
  m->H_A = hamiltonian(model, problem.sample(x, {0.5 * (m->contact_start + m->contact_end)}).front());
}

// The barrier's contact region: the cross-sections pressed with at least kContactFraction of the
// largest force per length.
void measure_barrier_contact(const ShootingProblem& problem, const Eigen::VectorXd& x,
                             const std::vector<RodPoint>& profile, const HalfTurnSelfContact& contact,
                             PlectonemeMeasures* m) {
  const auto& o = contact.options();
  std::vector<double> pressure(profile.size(), 0.0);
  double largest = 0.0, smallest_gap = INFINITY;
  m->loop_clearance = INFINITY;
  for (size_t i = 0; i < profile.size(); ++i) {
    const RodPoint& p = profile[i];
    const double w = contact.weight(p.s);
    if (w == 0.0) continue;
    const double g = contact.gap(p.s, p.r);
    if (w < 1.0) m->loop_clearance = std::min(m->loop_clearance, g / o.range);
    smallest_gap = std::min(smallest_gap, g);
    pressure[i] = contact.force(p.s, p.r).norm();
    largest = std::max(largest, pressure[i]);
  }
  if (!(smallest_gap < o.range)) largest = 0.0;  // nothing within the barrier's range: no contact
  size_t first = profile.size(), last = 0;
  for (size_t i = 0; i < profile.size(); ++i)
    if (largest > 0.0 && pressure[i] >= kContactFraction * largest) first = std::min(first, i), last = i;
  if (first > last) return;
  m->contact_start = profile[first].s;
  m->contact_end = profile[last].s;
  measure_helix(problem, x, profile, contact.geometry(), pressure, first, last, m);
}

// The hard contact's region runs from its first contact to its last (the ply's ends are isolated
// contact points beside the line contact); the pressure is the cylinder's on the line contacts,
// the helix is measured over the central half of the region.
void measure_hard_contact(const ShootingProblem& problem, const Eigen::VectorXd& x, const std::vector<RodPoint>& profile,
                          const HalfTurnGeometry& half_turn, PlectonemeMeasures* m) {
  m->hard = true;
  const auto contacts = problem.contacts_at(x);
  if (contacts.empty()) return;
  m->contact_start = contacts.front().s;
  m->contact_end = contacts.back().extended ? contacts.back().s_end : contacts.back().s;
  const Parameters p = problem.parameters_at(x);
  const auto eq = problem.equations(p);
  const CylinderSupport support{half_turn.origin, half_turn.axis, half_turn.radius};
  auto on_a_line_contact = [&](double s) {
    return std::any_of(contacts.begin(), contacts.end(),
                       [&](const PointContact& c) { return c.extended && s > c.s && s < c.s_end; });
  };
  std::vector<double> pressure(profile.size(), 0.0);
  size_t first = profile.size(), last = 0;
  m->ply_clearance = NAN;
  for (size_t i = 0; i < profile.size(); ++i) {
    const double s = profile[i].s;
    if (s < m->contact_start || s > m->contact_end) continue;
    first = std::min(first, i), last = i;
    if (on_a_line_contact(s)) {
      pressure[i] = cylinder_pressure(eq->model(), support, eq->state(profile[i]));
      continue;
    }
    // Interior local minima of the gap between contacts: where a new contact would form.
    if (i == 0 || i + 1 == profile.size()) continue;
    const double g = half_turn.distance_to_axis(profile[i].r), before = half_turn.distance_to_axis(profile[i - 1].r),
                 after = half_turn.distance_to_axis(profile[i + 1].r);
    const bool next_to_contact = std::any_of(contacts.begin(), contacts.end(), [&](const PointContact& c) {
      return std::abs(c.s - s) < 2.0 * half_turn.radius || (c.extended && std::abs(c.s_end - s) < 2.0 * half_turn.radius);
    });
    if (g < before && g <= after && !next_to_contact) {
      const double clearance = (g - half_turn.radius) / half_turn.radius;
      m->ply_clearance = std::isnan(m->ply_clearance) ? clearance : std::min(m->ply_clearance, clearance);
    }
  }
  if (first < last) measure_helix(problem, x, profile, half_turn, pressure, first, last, m);
}

// Multiple shooting of the hard ply: segments of at most these lengths (in R) on the line contacts,
// the gaps between contacts, and the tail and the end loop. On the cylinder the equations grow
// errors like exp(0.7 s / R) (rod_on_cylinder_test), and the line lengthens as the turns grow (by
// 2.3 times from 5 to 10 turns at L/2R = 100) with its segments fixed: at L/2R = 100, 5 to 7 turns
// took 182 points (20 segments, 3 on the line) against 83 (43, 13 on the line), 5 to 10 turns
// 281 points with 26 on the line. Shorter is not better: the Jacobian is dense, and its size grows
// with the segments - at L/2R = 500 (5 -> 8 and 5 -> 4.5 turns, from the 200 ply) R apart on the
// line took 49 s against 70 s at R/2, the same end points to 1e-10.
constexpr double kLineSegment = 1.0, kGapSegment = 1.0, kFreeSegment = 5.0;

std::vector<int> hard_ply_segments(const std::vector<PointContact>& contacts, double length, double R) {
  std::vector<int> out;
  double from = 0.0;
  auto piece = [&](double to, double target) {
    out.push_back(std::max(1, static_cast<int>(std::ceil((to - from) / (target * R)))));
    from = to;
  };
  for (size_t k = 0; k < contacts.size(); ++k) {
    piece(contacts[k].s, k == 0 ? kFreeSegment : kGapSegment);
    if (contacts[k].extended) piece(contacts[k].s_end, kLineSegment);
  }
  piece(length, kFreeSegment);
  return out;
}

}  // namespace

std::optional<HalfTurnGeometry> half_turn_geometry(const ShootingProblem& problem, const Parameters& p) {
  if (const HalfTurnSelfContact* contact = find_half_turn_self_contact(problem.equations(p)->model()))
    return contact->geometry();
  const auto obstacles = problem.obstacles(p);
  if (obstacles.size() != 1 || obstacles.front().name != kHalfTurnContactName) return std::nullopt;
  const Obstacle& cylinder = obstacles.front();
  return HalfTurnGeometry{cylinder.point(), cylinder.direction(), cylinder.radius(), problem.length(p)};
}

ProblemDefinition hard_ply_definition(const ProblemDefinition& barrier, const std::vector<PointContact>& contacts) {
  const RodModel rod = barrier.model(barrier.parameters);
  const auto* sum = dynamic_cast<const FieldSum*>(rod.field.get());
  const bool only_the_barrier = find_half_turn_self_contact(rod) && (!sum || sum->fields().size() == 1);
  if (!only_the_barrier)
    throw std::invalid_argument(
        "hard self-contact replaces a rod's half-turn self-contact, and this rod has none or another field besides");
  double previous = 0.0;
  for (const auto& c : contacts) {
    if (!(c.s > previous && (!c.extended || c.s_end > c.s)) || c.obstacle != 0)
      throw std::invalid_argument("hard self-contact: contacts on the cylinder (obstacle 0), in order along the rod");
    previous = c.extended ? c.s_end : c.s;
  }
  if (contacts.empty() || !(previous < rod.length))
    throw std::invalid_argument("hard self-contact: the ply must lie inside the half rod");
  ProblemDefinition d = barrier;
  d.model = [inner = barrier.model](const Parameters& p) {
    RodModel m = inner(p);
    m.field = nullptr;
    return m;
  };
  d.moving_obstacles = [inner = barrier.model](const Parameters& p) {
    const RodModel m = inner(p);
    const HalfTurnGeometry g = find_half_turn_self_contact(m)->geometry();
    return std::vector<Obstacle>{Obstacle::cylinder(g.origin, g.axis, g.radius, kHalfTurnContactName)};
  };
  d.obstacle_parameters = barrier.model_parameters;
  d.obstacles = d.moving_obstacles(d.parameters);
  d.contacts = contacts;
  d.piece_segments = hard_ply_segments(contacts, rod.length, find_half_turn_self_contact(rod)->options().radius);
  d.options.segments = 0;
  for (int count : d.piece_segments) d.options.segments += count;
  return d;
}

namespace {

// The hard ply of `barrier` at source's parameters at x, with these contacts, its unknowns from
// source's solution at its nodes.
HardPlyStart hard_ply_sampling(const ProblemDefinition& barrier, const ShootingProblem& source,
                               const Eigen::VectorXd& x, const std::vector<PointContact>& contacts) {
  HardPlyStart start;
  ProblemDefinition at_x = barrier;
  at_x.parameters = source.parameters_at(x);
  start.definition = hard_ply_definition(at_x, contacts);
  const ShootingProblem hard(start.definition);
  start.x = hard.unknowns_from(source.sample(x, hard.node_arclengths()));
  return start;
}

}  // namespace

HardPlyStart hard_ply_from_barrier(const ShootingProblem& barrier, const Eigen::VectorXd& x,
                                   const std::vector<PointContact>& contacts) {
  return hard_ply_sampling(barrier.definition(), barrier, x, contacts);
}

HardPlyStart resegmented_hard_ply(const ProblemDefinition& barrier, const ShootingProblem& hard,
                                  const Eigen::VectorXd& x) {
  return hard_ply_sampling(barrier, hard, x, hard.contacts_at(x));
}

PlectonemeMeasures measure_plectoneme(const ShootingProblem& problem, const Eigen::VectorXd& x,
                                      const std::vector<RodPoint>& profile) {
  const Parameters p = problem.parameters_at(x);
  const auto half_turn = half_turn_geometry(problem, p);
  if (!half_turn) throw std::invalid_argument("plectoneme quantities need a rod with [rod.self_contact]");
  const RodModel& model = problem.equations(p)->model();
  PlectonemeMeasures m;
  const RodPoint& clamp = profile.front();
  m.T_ext = clamp.n.dot(clamp.R.col(2));
  m.m3 = clamp.m.dot(clamp.R.col(2));
  m.H_B = hamiltonian(model, clamp);
  if (const HalfTurnSelfContact* barrier = find_half_turn_self_contact(model))
    measure_barrier_contact(problem, x, profile, *barrier, &m);
  else
    measure_hard_contact(problem, x, profile, *half_turn, &m);
  m.self_distance =
      smallest_self_distance(problem, x, *half_turn, half_turn->whole_rod(profile), M_PI * half_turn->radius,
                             half_turn->radius) /
      (2.0 * half_turn->radius);
  return m;
}

const std::vector<PlectonemeQuantity>& plectoneme_quantities() {
  using M = PlectonemeMeasures;
  static const std::vector<PlectonemeQuantity> table = {
      {"T_ext", "plectoneme: tension n.d3 at the clamp (the end pull T_ext of Fig. 10)", &M::T_ext},
      {"m3", "plectoneme: twisting moment m.d3 at the clamp", &M::m3},
      {"helix_angle",
       "plectoneme: mean angle (rad) between d3 and the axis over the central half of the contact region (NaN "
       "without one)",
       &M::helix_angle},
      {"helix_radius",
       "plectoneme: mean distance to the axis over the central half of the contact region (R + gap; NaN without one)",
       &M::helix_radius},
      {"contact_pressure",
       "plectoneme: mean self-contact force per length over the central half of the contact region (NaN without "
       "one)",
       &M::contact_pressure},
      {"contact_start", "plectoneme: arclength where the contact region starts (half rod; NaN without one)",
       &M::contact_start},
      {"contact_end", "plectoneme: arclength where the contact region ends (half rod; NaN without one)",
       &M::contact_end},
      {"H_A", "plectoneme: H in the middle of the contact region (eq. 60; NaN without one)", &M::H_A},
      {"H_B", "plectoneme: H at the clamped end (eq. 59)", &M::H_B},
      {"self_distance", "plectoneme: smallest distance between non-neighbouring cross-sections / 2R (>= 1)",
       &M::self_distance},
      {"loop_clearance",
       "plectoneme: smallest gap / range where the contact is switched off (H drifts by ~exp(-it^2); NaN with hard "
       "contact)",
       &M::loop_clearance},
      {"ply_clearance",
       "plectoneme, hard contact: smallest (rho - R)/R between the ply's contacts (< 0: a new contact; NaN with the "
       "barrier or without such a gap)",
       &M::ply_clearance},
  };
  return table;
}

}  // namespace kirchhoff

#include "kirchhoff/analysis/discrete_seed.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace kirchhoff {
namespace {

[[noreturn]] void out_of_scope(const std::string& why) {
  throw std::invalid_argument("the Ipopt seed handles planar Kirchhoff rods clamped or pinned at both ends only: " +
                              why);
}

// The slots an end imposes (position, orientation, moment), each in every direction and nothing
// else; empty where it imposes anything other (a direction, a load, an unknown).
struct HeldSlots {
  bool position = false, orientation = false, moment = false;
};
std::optional<HeldSlots> held_slots(const EndCondition& end) {
  if (end.extra_count() != 0) return std::nullopt;
  HeldSlots held;
  for (const auto& c : end.conditions()) {
    if (c.directions != Directions::All) return std::nullopt;
    if (c.slot == Slot::Position) held.position = true;
    else if (c.slot == Slot::Orientation) held.orientation = true;
    else if (c.slot == Slot::Moment) held.moment = true;
    else return std::nullopt;
  }
  return held;
}

// Whether an end is clamped: position and frame imposed in every direction, nothing else.
bool is_clamped(const EndCondition& end) {
  const auto held = held_slots(end);
  return held && held->position && held->orientation && !held->moment;
}

// Whether an end is pinned without a couple: position imposed in every direction, the moment
// imposed zero, nothing else.
bool is_pinned(const RodEquations& eq, const EndCondition& end, bool at_start, const Parameters& p) {
  const auto held = held_slots(end);
  if (!held || !held->position || !held->moment || held->orientation) return false;
  RodPoint point;
  point.R = planar_reference_frame();
  end.impose_on(eq, at_start, p, &point);
  return point.m.norm() == 0.0;
}

// The end's position and, for a clamp, its tangent angle (NaN where the end is pinned: free to turn).
std::pair<Vec3, double> held_end(const RodEquations& eq, const EndCondition& end, bool at_start, const Parameters& p) {
  RodPoint point;
  point.R = planar_reference_frame();
  end.impose_on(eq, at_start, p, &point);
  if (!is_clamped(end)) return {point.r, NAN};
  const Vec3 t = point.R.col(2);
  return {point.r, std::atan2(t.y(), t.x())};
}

DiscreteClampedElastica discrete_rod(const ProblemDefinition& d, const ShootingProblem& problem) {
  if (d.kind != RodKind::Planar) out_of_scope("the case is spatial");
  if (!d.unknown_parameters.empty()) out_of_scope("the case solves for parameters");
  const auto eq = problem.equations(d.parameters);
  for (const bool at_start : {true, false}) {
    const EndCondition& end = at_start ? d.start : d.end;
    if (!is_clamped(end) && !is_pinned(*eq, end, at_start, d.parameters))
      out_of_scope(std::string(at_start ? "the start" : "the end") + " is neither clamped nor pinned without a couple");
  }
  const RodModel& model = eq->model();
  if (model.extensible) out_of_scope("the rod is extensible or shearable");
  if (model.field) out_of_scope("the rod carries an external field");
  for (int k = 0; k <= 20; ++k)
    if (model.u_hat[1](model.length * k / 20) != 0.0) out_of_scope("the rod has a natural curvature");
  DiscreteClampedElastica rod;
  rod.L = model.length;
  rod.EI = [B = model.B[1]](double s) { return B(s); };
  std::tie(rod.start, rod.start_angle) = held_end(*eq, d.start, true, d.parameters);
  std::tie(rod.end, rod.end_angle) = held_end(*eq, d.end, false, d.parameters);
  rod.obstacles = problem.obstacles(d.parameters);
  return rod;
}

// The stationarity a mirror-symmetric seed needs: it only starts Newton, whose solution is checked
// on its own. Held symmetric, the discrete rod's vertical force is carried by rows made redundant
// by the symmetry, whose multipliers Ipopt leaves undetermined; the check recovers the force from
// them by least squares (vertical_force_from_symmetry), which leaves the stationarity at 1e-5 ..
// 1e-4 where the minimiser itself is right: 3.5e-5 on clamped_clamped.toml, and on the
// pinned-pinned rod lying flat under a wall (discrete_seed_test.cpp) 1.5e-5, 2.5e-4 and 4.7e-8 at
// 100, 200 and 400 segments, its energies converging at second order to the shooting solution's
// all the same. 1e-3 takes such a minimiser as a seed; its constraints (ends, penetration, pulling
// forces, complementarity) must still hold to the check's tolerance.
constexpr double kSymmetricSeedStationarity = 1e-3;

bool usable_as_seed(const DiscreteElasticaResult& r, bool mirror_symmetric) {
  if (r.converged) return true;
  if (!mirror_symmetric) return false;
  const DiscreteKktCheck& k = r.kkt;
  return r.ipopt_status == "success" && k.stationarity <= kSymmetricSeedStationarity &&
         k.end_error <= kDiscreteKktTolerance && k.penetration <= kDiscreteKktTolerance &&
         k.negative_force <= kDiscreteKktTolerance && k.complementarity <= kDiscreteKktTolerance;
}

// The contacts of one obstacle from the nodes' forces and gaps (see the header).
void read_contacts(const std::vector<double>& force, const std::vector<double>& gap, int obstacle, bool flat,
                   double h, double L, double force_scale, std::vector<PointContact>* out) {
  // Inactive constraints keep multipliers ~1e-10 of the forces: a force counts above 1e-6 of
  // the rod's force scale.
  auto active = [&](size_t i) { return gap[i] < 1e-9 * L || force[i] > 1e-6 * force_scale; };
  for (size_t i = 0; i < force.size();) {
    if (!active(i)) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < force.size() && active(j + 1)) ++j;
    // Nodes i..j (arclengths (i + 1) h .. (j + 1) h).
    PointContact c;
    c.obstacle = obstacle;
    if (flat && j >= i + 2) {
      c.extended = true;
      c.s = (i + 1) * h;
      c.s_end = (j + 1) * h;
      for (size_t k = i; k <= j; ++k) (2 * k <= i + j ? c.force : c.force_end) += force[k];
    } else {
      double total = 0.0, moment = 0.0;
      for (size_t k = i; k <= j; ++k) {
        total += force[k];
        moment += force[k] * (k + 1) * h;
      }
      c.force = total;
      c.s = total > 0 ? moment / total : 0.5 * (i + j + 2) * h;
    }
    out->push_back(c);
    i = j + 1;
  }
}

}  // namespace

DiscreteSeed seed_from_discrete_energy(const ProblemDefinition& d, int segments, double amplitude) {
  DiscreteSolveOptions options;
  options.amplitude = amplitude;
  return seed_from_discrete_energy(d, segments, options);
}

DiscreteSeed seed_from_discrete_energy(const ProblemDefinition& d, int segments, const DiscreteSolveOptions& options) {
  const ShootingProblem problem(d);
  const DiscreteClampedElastica rod = discrete_rod(d, problem);
  DiscreteSeed seed;
  seed.discrete = solve_discrete_elastica(rod, segments, options);
  // Ipopt succeeded and its solution passed the library's own KKT check (stationarity, end
  // constraints, no penetration, no pulling force, complementarity), a mirror-symmetric one's
  // stationarity to a seed's accuracy (usable_as_seed); anything else is refused rather than read
  // off. (The seed needs no refinement check: the shooting solve that starts from it is checked
  // by its own residual and complementarity.)
  if (!usable_as_seed(seed.discrete, options.mirror_symmetric))
    throw std::runtime_error("the Ipopt seed did not converge (" + seed.discrete.status + ")");
  const double h = rod.L / segments;
  // Forces: the end reaction, or the Euler load's scale EI / L^2 when that is smaller.
  const double force_scale = seed.discrete.n_start.norm() + rod.EI(0.0) / (rod.L * rod.L);
  for (size_t o = 0; o < rod.obstacles.size(); ++o)
    read_contacts(seed.discrete.node_forces[o], seed.discrete.node_gaps[o], static_cast<int>(o),
                  rod.obstacles[o].is_flat(), h, rod.L, force_scale, &seed.contacts);
  std::sort(seed.contacts.begin(), seed.contacts.end(), [](const auto& a, const auto& b) { return a.s < b.s; });
  seed.start.r = rod.start;
  // A pinned start's tangent: the first two segments' angles (at h/2 and 3h/2) extrapolated to 0.
  const std::vector<double>& theta = seed.discrete.theta;
  const double start_angle =
      std::isfinite(rod.start_angle) ? rod.start_angle : 1.5 * theta[0] - 0.5 * theta[1];
  seed.start.R = Eigen::AngleAxisd(start_angle, Vec3::UnitZ()).toRotationMatrix() * planar_reference_frame();
  seed.start.n = seed.discrete.n_start;
  seed.start.m = Vec3(0.0, 0.0, seed.discrete.m_start);
  std::ostringstream summary;
  summary << "Ipopt on " << segments << " segments (" << seed.discrete.iterations << " iterations, energy "
          << seed.discrete.energy << ", KKT checked" << (seed.discrete.converged ? "" : " to a seed's accuracy")
          << ": stationarity " << seed.discrete.kkt.stationarity
          << ", complementarity " << seed.discrete.kkt.complementarity << "): " << seed.contacts.size() << " contact(s)";
  for (const auto& c : seed.contacts) {
    summary << (&c == &seed.contacts.front() ? ": " : ", ");
    if (c.extended)
      summary << "flat on obstacle " << c.obstacle << " over [" << c.s << ", " << c.s_end << "]";
    else
      summary << "obstacle " << c.obstacle << " at s = " << c.s << " (force " << c.force << ")";
  }
  seed.summary = summary.str();
  return seed;
}

ContactSolveResult solve_from_discrete_seed(const ProblemDefinition& definition, int segments, double amplitude,
                                            DiscreteSeed* seed_out) {
  DiscreteSolveOptions options;
  options.amplitude = amplitude;
  return solve_from_discrete_seed(definition, segments, options, seed_out);
}

ContactSolveResult solve_from_discrete_seed(const ProblemDefinition& definition, int segments,
                                            const DiscreteSolveOptions& options, DiscreteSeed* seed_out) {
  DiscreteSeed seed = seed_from_discrete_energy(definition, segments, options);
  ProblemDefinition seeded = definition;
  seeded.contacts = seed.contacts;
  ContactSolveResult out = solve_with_contacts(seeded, seed.start);
  if (seed_out) *seed_out = std::move(seed);
  return out;
}

}  // namespace kirchhoff

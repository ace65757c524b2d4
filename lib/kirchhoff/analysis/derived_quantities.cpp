// The derived quantities: one table of name, meaning and function (quantities()), and one rule for
// the plectoneme's family. derived_catalogue() and derived_values() both read that table.
#include "kirchhoff/analysis/detail/derived_quantities.hpp"

#include <algorithm>
#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "kirchhoff/analysis/detail/integral_along_rod.hpp"
#include "kirchhoff/contact/closest_approach.hpp"
#include "kirchhoff/contact/plectoneme.hpp"
#include "kirchhoff/equations/invariants.hpp"

namespace kirchhoff {
namespace {

using PointFunction = std::function<double(const RodPoint&)>;

// A double NaN (NAN is a float: a lambda returning it and a double elsewhere does not compile).
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What a quantity is computed from. The rod model and the plectoneme's measures are looked up on
// first use: the measures cost a search along the rod and exist only with half-turn self-contact.
class DerivedInputs {
 public:
  DerivedInputs(const ShootingProblem& problem, const Solution& sol) : problem(problem), sol(sol) {}

  const ShootingProblem& problem;
  const Solution& sol;

  const RodPoint& start() const { return sol.profile.front(); }
  const RodPoint& end() const { return sol.profile.back(); }
  const Eigen::VectorXd& x() const { return sol.result.x; }
  bool planar() const { return problem.definition().kind == RodKind::Planar; }
  const RodModel& model() {
    if (!equations_) equations_ = problem.equations(sol.result.parameters);
    return equations_->model();
  }
  const PlectonemeMeasures& plectoneme() {
    if (!plectoneme_) plectoneme_ = measure_plectoneme(problem, sol.result.x, sol.profile);
    return *plectoneme_;
  }

 private:
  std::shared_ptr<const RodEquations> equations_;
  std::optional<PlectonemeMeasures> plectoneme_;
};

struct DerivedQuantity {
  std::string name;
  std::string meaning;  // one line; says where the value is NaN
  std::function<double(DerivedInputs&)> value;
  // Reads nothing but the state at s = 0 (and the model): a solution described at the start alone
  // (make_start_solution) has it without integrating the rod.
  bool start_only = false;
};

// Maximum of f along the rod: the best sample, then Brent's method on the two neighbouring
// intervals using exact re-integration to the trial arclengths. Locating the maximiser to
// ~1e-8 gives its value to ~1e-16 relative (the error is quadratic at a smooth maximum).
double refined_maximum(const DerivedInputs& in, const PointFunction& f) {
  const auto& profile = in.sol.profile;
  size_t best = 0;
  for (size_t i = 1; i < profile.size(); ++i)
    if (f(profile[i]) > f(profile[best])) best = i;
  const double lo = profile[best == 0 ? 0 : best - 1].s;
  const double hi = profile[best + 1 < profile.size() ? best + 1 : best].s;
  if (!(hi > lo)) return f(profile[best]);
  auto negative = [&](double s) { return -f(in.problem.sample(in.x(), {s}).front()); };
  const auto [s_star, value] = boost::math::tools::brent_find_minima(negative, lo, hi, 40);
  (void)s_star;
  return std::max(-value, f(profile[best]));
}

// A soft wall's potential is peaked over a width ~sqrt(gap / kappa) ~ 1e-2 at b = 1e-6, which
// 4000 Simpson intervals resolve to ~1e-7 relative; smooth integrands (the elastic energy) come
// out to ~1e-12 (integral_along_rod.hpp: the stretches between jumps and contacts on their own).
double integral_along(DerivedInputs& in, const PointFunction& f) {
  constexpr int kIntervals = 4000;
  return integral_along_rod(in.problem, in.x(), in.model(), kIntervals, f);
}

// The smallest of a per-contact quantity, over the contacts where it is defined (NaN elsewhere);
// NaN when it is defined at none.
double smallest_over_contacts(const Solution& sol, const std::function<double(const PointContact&)>& value) {
  double out = kNaN;
  for (const auto& c : sol.contacts) {
    const double v = value(c);
    if (std::isfinite(v)) out = std::isnan(out) ? v : std::min(out, v);
  }
  return out;
}

double curvature(const RodPoint& p) { return std::hypot(p.u[0], p.u[1]); }
double tangent_angle(const RodPoint& p) { return std::atan2(p.R(1, 2), p.R(0, 2)); }

// The spread max - min of f over the profile samples.
double spread_along(const Solution& sol, const PointFunction& f) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& p : sol.profile) {
    lo = std::min(lo, f(p));
    hi = std::max(hi, f(p));
  }
  return hi - lo;
}

using In = DerivedInputs;

// The table, in three groups. A new quantity is one row in its group; its meaning says where it
// is NaN (the test tests/derived_quantities_test.cpp accepts a NaN only from a quantity that says
// so). Built on first use, not at static initialisation, which another file's statics may precede.

// The rod's ends, loads and shape.
std::vector<DerivedQuantity> shape_and_load_quantities() {
  return {
    {"P", "compressive end load -n_x(0)", [](In& in) { return -in.start().n.x(); }, true},
    {"theta0", "angle of the tangent d3(0) to the x axis, in the (x, y) plane",
     [](In& in) { return in.planar() ? in.start().turn_angle : tangent_angle(in.start()); }, true},
    {"theta_end", "angle of the tangent d3(L) to the x axis, in the (x, y) plane",
     [](In& in) { return in.planar() ? in.end().turn_angle : tangent_angle(in.end()); }},
    {"y_max", "largest |y(s)| along the rod",
     [](In& in) { return refined_maximum(in, [](const RodPoint& p) { return std::abs(p.r.y()); }); }},
    {"kappa_max", "largest bending curvature sqrt(u1^2 + u2^2) along the rod",
     [](In& in) { return refined_maximum(in, curvature); }},
    {"end_to_end", "distance |r(L) - r(0)|", [](In& in) { return (in.end().r - in.start().r).norm(); }},
    {"M", "twisting moment m3 = m.d3 at s = 0", [](In& in) { return in.start().m.dot(in.start().R.col(2)); }, true},
    {"tension", "axial force n.d3 at s = L", [](In& in) { return in.end().n.dot(in.end().R.col(2)); }},
    {"tip_x", "x(L)", [](In& in) { return in.end().r.x(); }},
    {"tip_y", "y(L)", [](In& in) { return in.end().r.y(); }},
    {"tip_z", "z(L)", [](In& in) { return in.end().r.z(); }},
    {"n_x", "n_x(0)", [](In& in) { return in.start().n.x(); }, true},
    {"n_y", "n_y(0)", [](In& in) { return in.start().n.y(); }, true},
    {"n_z", "n_z(0)", [](In& in) { return in.start().n.z(); }, true},
    {"m_start", "|m(0)|, the moment at the start (clamping moment)", [](In& in) { return in.start().m.norm(); }, true},
    {"kappa_mid", "curvature u2 at s = L/2 (signed, planar)",
     [](In& in) { return in.problem.sample(in.x(), {0.5 * in.end().s}).front().u[1]; }},
    {"kappa_end", "curvature u2 at s = L (signed, planar)", [](In& in) { return in.end().u[1]; }},
    {"kappa_start", "curvature u2 at s = 0 (signed, planar)", [](In& in) { return in.start().u[1]; }, true},
    {"stretch_max", "largest axial strain |v3 - 1| along the rod",
     [](In& in) {
       double worst = 0.0;
       for (const auto& p : in.sol.profile) worst = std::max(worst, std::abs(p.v[2] - 1.0));
       return worst;
     }},
  };
}

// The Hamiltonian, the energies and the external field.
std::vector<DerivedQuantity> energy_quantities() {
  return {
    {"H", "mean of the arclength Hamiltonian H = n.v + m.u - V along the rod (eq. 29)",
     [](In& in) { return in.sol.invariants.H.mean; }},
    {"H_spread", "max - min of H along the rod", [](In& in) { return in.sol.invariants.H.spread; }},
    {"H_start", "H at s = 0", [](In& in) { return hamiltonian(in.model(), in.start()); }, true},
    {"H_end", "H at s = L", [](In& in) { return hamiltonian(in.model(), in.end()); }},
    {"h_spread", "max - min of h = H + W_ext (eq. 67), not invariant under a field",
     [](In& in) {
       const RodModel& model = in.model();
       return spread_along(in.sol, [&](const RodPoint& p) { return hamiltonian_without_field(model, p); });
     }},
    {"E_wall", "integral of the external potential along the rod (eq. 69 for the soft wall)",
     [](In& in) {
       const RodModel& model = in.model();
       if (!model.field) return 0.0;
       return integral_along(in, [&](const RodPoint& p) { return model.field->potential(p.s, p.r); });
     }},
    {"elastic_energy", "integral of W_bend + W_shear along the rod",
     [](In& in) {
       const RodModel& model = in.model();
       return integral_along(in, [&](const RodPoint& p) {
         return energy_density(model, p) - (model.field ? model.field->potential(p.s, p.r) : 0.0);
       });
     }},
    {"gap", "smallest distance to a soft wall along the rod (eq. 64's a - y; NaN without a field)",
     [](In& in) {
       const RodModel& model = in.model();
       if (!model.field) return kNaN;
       return -refined_maximum(in, [&](const RodPoint& p) { return -model.field->gap(p.s, p.r); });
     }},
    {"ny_jump", "n_y(L) - n_y(0): the wall's total reaction (eq. 66)",
     [](In& in) { return in.end().n.y() - in.start().n.y(); }},
  };
}

// The contacts with obstacles.
std::vector<DerivedQuantity> contact_quantities() {
  return {
    {"contact_force", "sum of the point-contact forces",
     [](In& in) {
       double total = 0.0;
       for (const auto& c : in.sol.contacts) total += c.force + (c.extended ? c.force_end : 0.0);
       return total;
     }},
    {"contact_count", "number of point contacts", [](In& in) { return static_cast<double>(in.sol.contacts.size()); }},
    {"min_contact_force", "smallest point-contact force (NaN without contacts)",
     [](In& in) {
       return smallest_over_contacts(
           in.sol, [](const PointContact& c) { return c.extended ? std::min(c.force, c.force_end) : c.force; });
     }},
    {"contact_bending",
     "smallest g'' at the point contacts: how the rod curves away from the obstacle (0: it flattens; NaN without "
     "point contacts)",
     [](In& in) {
       return smallest_over_contacts(
           in.sol, [&](const PointContact& c) { return c.extended ? kNaN : in.problem.contact_bending(in.x(), c); });
     }},
    {"contact_length", "total length of the extended contacts",
     [](In& in) {
       double total = 0.0;
       for (const auto& c : in.sol.contacts) total += c.extended ? c.s_end - c.s : 0.0;
       return total;
     }},
    {"min_contact_length", "smallest s_end - s over extended contacts (NaN without): 0 where one shrinks to a point",
     [](In& in) {
       return smallest_over_contacts(in.sol, [](const PointContact& c) { return c.extended ? c.s_end - c.s : kNaN; });
     }},
    {"flat_contact_margin",
     "smallest 4 pi^2 B2 / l^2 - P_flat over extended contacts: < 0 once a flat part would buckle away (NaN "
     "without flat parts)",
     [](In& in) {
       return smallest_over_contacts(in.sol,
                                     [&](const PointContact& c) { return in.problem.flat_contact_margin(in.x(), c); });
     }},
    {"min_wrap_tension",
     "smallest tension n.d3 of the parts wrapped around discs (the disc's pressure is tension / radius; NaN without)",
     [](In& in) {
       return smallest_over_contacts(in.sol, [&](const PointContact& c) { return in.problem.wrap_tension(in.x(), c); });
     }},
    {"min_wrap_pressure",
     "smallest pressure (force per length) of the parts wrapped around discs or cylinders (NaN without)",
     [](In& in) {
       return smallest_over_contacts(
           in.sol, [&](const PointContact& c) { return in.problem.smallest_wrap_pressure(in.x(), c); });
     }},
    {"kappa_contact", "curvature u2 at the first point contact (signed, planar; NaN without contacts)",
     [](In& in) {
       return in.sol.contacts.empty() ? kNaN : in.problem.sample(in.x(), {in.sol.contacts.front().s}).front().u[1];
     }},
    {"contact_s", "arclength of the first point contact (NaN without contacts)",
     [](In& in) { return in.sol.contacts.empty() ? kNaN : in.sol.contacts.front().s; }},
    {"min_gap", "smallest distance to the obstacles along the rod (NaN without obstacles)",
     [](In& in) {
       if (in.problem.definition().obstacles.empty()) return kNaN;
       return closest_approach(in.problem, in.x(), static_cast<int>(in.sol.profile.size())).gap;
     }},
  };
}

const std::vector<DerivedQuantity>& quantities() {
  static const std::vector<DerivedQuantity> table = [] {
    std::vector<DerivedQuantity> all;
    for (auto group : {shape_and_load_quantities, energy_quantities, contact_quantities}) {
      std::vector<DerivedQuantity> part = group();
      all.insert(all.end(), std::make_move_iterator(part.begin()), std::make_move_iterator(part.end()));
    }
    return all;
  }();
  return table;
}

// The table by name: quantities(), and - the one family - every quantity of the plectoneme
// (plectoneme_quantities(), contact/plectoneme.hpp: its own table of name, meaning and measure),
// read off measure_plectoneme's measures. A name given twice is a programming error, caught on
// first use.
const std::map<std::string, DerivedQuantity>& quantities_by_name() {
  static const std::map<std::string, DerivedQuantity> table = [] {
    std::map<std::string, DerivedQuantity> out;
    const auto add = [&](DerivedQuantity q) {
      const std::string name = q.name;
      if (!out.emplace(name, std::move(q)).second)
        throw std::logic_error("derived quantity '" + name + "' is defined twice");
    };
    for (const auto& q : quantities()) add(q);
    for (const auto& q : plectoneme_quantities()) {
      const auto member = q.value;
      add({q.name, q.meaning, [member](In& in) { return in.plectoneme().*member; }});
    }
    return out;
  }();
  return table;
}

}  // namespace

const std::map<std::string, std::string>& derived_catalogue() {
  static const std::map<std::string, std::string> all = [] {
    std::map<std::string, std::string> out;
    for (const auto& [name, q] : quantities_by_name()) out[name] = q.meaning;
    return out;
  }();
  return all;
}

std::map<std::string, double> derived_values(const std::vector<std::string>& names, const ShootingProblem& problem,
                                             const Solution& sol) {
  const auto& table = quantities_by_name();
  DerivedInputs inputs(problem, sol);
  std::map<std::string, double> out;
  for (const auto& name : names) {
    const auto q = table.find(name);
    if (q == table.end()) throw std::invalid_argument("unknown derived quantity '" + name + "'");
    if (sol.profile.size() < 2 && !q->second.start_only)
      throw std::logic_error("derived quantity '" + name + "' reads the whole rod, not its start alone");
    out[name] = q->second.value(inputs);
  }
  return out;
}

bool derived_read_start_only(const std::vector<std::string>& names) {
  const auto& table = quantities_by_name();
  for (const auto& name : names) {
    const auto q = table.find(name);
    if (q == table.end() || !q->second.start_only) return false;
  }
  return true;
}

}  // namespace kirchhoff

#include "kirchhoff/analysis/solution.hpp"

#include <boost/math/tools/minima.hpp>
#include <cmath>
#include <fstream>
#include <functional>
#include <optional>
#include <stdexcept>

#include "kirchhoff/contact/closest_approach.hpp"
#include "kirchhoff/contact/plectoneme.hpp"
#include "kirchhoff/shooting/verification.hpp"

namespace kirchhoff {
namespace {

using PointFunction = std::function<double(const RodPoint&)>;

// Maximum of f along the rod: the best sample, then Brent's method on the two neighbouring
// intervals using exact re-integration to the trial arclengths. Locating the maximiser to
// ~1e-8 gives its value to ~1e-16 relative (the error is quadratic at a smooth maximum).
double refined_maximum(const ShootingProblem& problem, const Eigen::VectorXd& x,
                       const std::vector<RodPoint>& profile, const PointFunction& f) {
  size_t best = 0;
  for (size_t i = 1; i < profile.size(); ++i)
    if (f(profile[i]) > f(profile[best])) best = i;
  const double lo = profile[best == 0 ? 0 : best - 1].s;
  const double hi = profile[best + 1 < profile.size() ? best + 1 : best].s;
  if (!(hi > lo)) return f(profile[best]);
  auto negative = [&](double s) { return -f(problem.sample(x, {s}).front()); };
  const auto [s_star, value] = boost::math::tools::brent_find_minima(negative, lo, hi, 40);
  (void)s_star;
  return std::max(-value, f(profile[best]));
}

double curvature(const RodPoint& p) { return std::hypot(p.u[0], p.u[1]); }

// Composite Simpson on a fine sampling (one integration pass): a soft wall's potential is peaked
// over a width ~sqrt(gap / kappa) ~ 1e-2 at b = 1e-6, which 4000 intervals resolve to ~1e-7
// relative; smooth integrands (the elastic energy) come out to ~1e-12.
double integral_along(const ShootingProblem& problem, const Eigen::VectorXd& x, double L,
                      const PointFunction& f) {
  constexpr int kIntervals = 4000;
  std::vector<double> s(kIntervals + 1);
  for (int i = 0; i <= kIntervals; ++i) s[i] = L * i / kIntervals;
  s.back() = L;
  const auto points = problem.sample(x, s);
  double sum = 0.0;
  for (int i = 0; i <= kIntervals; ++i) sum += (i == 0 || i == kIntervals ? 1.0 : (i % 2 ? 4.0 : 2.0)) * f(points[i]);
  return sum * (L / kIntervals) / 3.0;
}

const std::map<std::string, std::string> kCatalogue = {
    {"P", "compressive end load -n_x(0)"},
    {"theta0", "angle of the tangent d3(0) to the x axis, in the (x, y) plane"},
    {"theta_end", "angle of the tangent d3(L) to the x axis, in the (x, y) plane"},
    {"y_max", "largest |y(s)| along the rod"},
    {"kappa_max", "largest bending curvature sqrt(u1^2 + u2^2) along the rod"},
    {"end_to_end", "distance |r(L) - r(0)|"},
    {"M", "twisting moment m3 = m.d3 at s = 0"},
    {"tension", "axial force n.d3 at s = L"},
    {"tip_x", "x(L)"}, {"tip_y", "y(L)"}, {"tip_z", "z(L)"},
    {"n_x", "n_x(0)"}, {"n_y", "n_y(0)"}, {"n_z", "n_z(0)"},
    {"m_start", "|m(0)|, the moment at the start (clamping moment)"},
    {"H", "mean of the arclength Hamiltonian H = n.v + m.u - V along the rod (eq. 29)"},
    {"H_spread", "max - min of H along the rod"},
    {"stretch_max", "largest axial strain |v3 - 1| along the rod"},
    {"E_wall", "integral of the external potential along the rod (eq. 69 for the soft wall)"},
    {"elastic_energy", "integral of W_bend + W_shear along the rod"},
    {"gap", "smallest distance to a soft wall along the rod (eq. 64's a - y)"},
    {"ny_jump", "n_y(L) - n_y(0): the wall's total reaction (eq. 66)"},
    {"kappa_mid", "curvature u2 at s = L/2 (signed, planar)"},
    {"kappa_end", "curvature u2 at s = L (signed, planar)"},
    {"kappa_start", "curvature u2 at s = 0 (signed, planar)"},
    {"H_start", "H at s = 0"},
    {"H_end", "H at s = L"},
    {"contact_force", "sum of the point-contact forces"},
    {"contact_count", "number of point contacts"},
    {"min_contact_force", "smallest point-contact force (NaN without contacts)"},
    {"contact_bending", "smallest g'' at the point contacts: how the rod curves away from the obstacle (0: it flattens)"},
    {"contact_length", "total length of the extended contacts"},
    {"min_contact_length", "smallest s_end - s over extended contacts (NaN without): 0 where one shrinks to a point"},
    {"flat_contact_margin", "smallest 4 pi^2 B2 / l^2 - P_flat over extended contacts: < 0 once a flat part would buckle away"},
    {"min_wrap_tension", "smallest tension n.d3 of the parts wrapped around discs (the disc's pressure is tension / radius; NaN without)"},
    {"min_wrap_pressure", "smallest pressure (force per length) of the parts wrapped around discs or cylinders (NaN without)"},
    {"kappa_contact", "curvature u2 at the first point contact (signed, planar)"},
    {"contact_s", "arclength of the first point contact"},
    {"min_gap", "smallest distance to the obstacles along the rod"},
    {"h_spread", "max - min of h = H + W_ext (eq. 67), not invariant under a field"},
};

double tangent_angle(const RodPoint& p) { return std::atan2(p.R(1, 2), p.R(0, 2)); }

double derived_value(const std::string& name, const ShootingProblem& problem, const Solution& sol) {
  const RodPoint& a = sol.profile.front();
  const RodPoint& b = sol.profile.back();
  const Eigen::VectorXd& x = sol.result.x;
  if (name == "P") return -a.n.x();
  if (name == "theta0") return problem.definition().kind == RodKind::Planar ? a.turn_angle : tangent_angle(a);
  if (name == "theta_end") return problem.definition().kind == RodKind::Planar ? b.turn_angle : tangent_angle(b);
  if (name == "y_max") return refined_maximum(problem, x, sol.profile, [](const RodPoint& p) { return std::abs(p.r.y()); });
  if (name == "kappa_max") return refined_maximum(problem, x, sol.profile, curvature);
  if (name == "end_to_end") return (b.r - a.r).norm();
  if (name == "M") return a.m.dot(a.R.col(2));
  if (name == "tension") return b.n.dot(b.R.col(2));
  if (name == "tip_x") return b.r.x();
  if (name == "tip_y") return b.r.y();
  if (name == "tip_z") return b.r.z();
  if (name == "n_x") return a.n.x();
  if (name == "n_y") return a.n.y();
  if (name == "n_z") return a.n.z();
  if (name == "m_start") return a.m.norm();
  if (name == "H") return sol.invariants.H.mean;
  if (name == "H_spread") return sol.invariants.H.spread;
  if (name == "E_wall") {
    const RodModel& model = problem.equations(sol.result.parameters)->model();
    if (!model.field) return 0.0;
    return integral_along(problem, x, b.s, [&](const RodPoint& p) { return model.field->potential(p.s, p.r); });
  }
  if (name == "elastic_energy") {
    const RodModel& model = problem.equations(sol.result.parameters)->model();
    return integral_along(problem, x, b.s, [&](const RodPoint& p) {
      return energy_density(model, p) - (model.field ? model.field->potential(p.s, p.r) : 0.0);
    });
  }
  if (name == "gap") {
    const RodModel& model = problem.equations(sol.result.parameters)->model();
    if (!model.field) return NAN;
    return -refined_maximum(problem, x, sol.profile, [&](const RodPoint& p) { return -model.field->gap(p.s, p.r); });
  }
  if (name == "ny_jump") return b.n.y() - a.n.y();
  if (name == "kappa_end") return b.u[1];
  if (name == "kappa_start") return a.u[1];
  if (name == "H_start" || name == "H_end") {
    const RodModel& model = problem.equations(sol.result.parameters)->model();
    return hamiltonian(model, name == "H_start" ? a : b);
  }
  if (name == "contact_force") {
    double total = 0.0;
    for (const auto& c : sol.contacts) total += c.force + (c.extended ? c.force_end : 0.0);
    return total;
  }
  if (name == "contact_length") {
    double total = 0.0;
    for (const auto& c : sol.contacts) total += c.extended ? c.s_end - c.s : 0.0;
    return total;
  }
  // The smallest of a per-contact quantity, over the contacts where it is defined (NaN elsewhere).
  const auto smallest = [&](const std::function<double(const PointContact&)>& value) {
    double out = NAN;
    for (const auto& c : sol.contacts) {
      const double v = value(c);
      if (std::isfinite(v)) out = std::isnan(out) ? v : std::min(out, v);
    }
    return out;
  };
  if (name == "min_contact_length")
    return smallest([](const PointContact& c) { return c.extended ? c.s_end - c.s : NAN; });
  if (name == "flat_contact_margin")
    return smallest([&](const PointContact& c) { return problem.flat_contact_margin(x, c); });
  if (name == "min_wrap_tension") return smallest([&](const PointContact& c) { return problem.wrap_tension(x, c); });
  if (name == "min_wrap_pressure")
    return smallest([&](const PointContact& c) { return problem.smallest_wrap_pressure(x, c); });
  if (name == "contact_bending")
    return smallest([&](const PointContact& c) { return c.extended ? NAN : problem.contact_bending(x, c); });
  if (name == "contact_count") return static_cast<double>(sol.contacts.size());
  if (name == "min_contact_force")
    return smallest([](const PointContact& c) { return c.extended ? std::min(c.force, c.force_end) : c.force; });
  if (name == "kappa_contact")
    return sol.contacts.empty() ? NAN : problem.sample(x, {sol.contacts.front().s}).front().u[1];
  if (name == "contact_s") return sol.contacts.empty() ? NAN : sol.contacts.front().s;
  if (name == "min_gap") {
    if (problem.definition().obstacles.empty()) return NAN;
    return closest_approach(problem, x, static_cast<int>(sol.profile.size())).gap;
  }
  if (name == "kappa_mid") return problem.sample(x, {0.5 * b.s}).front().u[1];
  if (name == "h_spread") {
    const RodModel& model = problem.equations(sol.result.parameters)->model();
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& p : sol.profile) {
      lo = std::min(lo, hamiltonian_without_field(model, p));
      hi = std::max(hi, hamiltonian_without_field(model, p));
    }
    return hi - lo;
  }
  if (name == "stretch_max") {
    double worst = 0.0;
    for (const auto& p : sol.profile) worst = std::max(worst, std::abs(p.v[2] - 1.0));
    return worst;
  }
  throw std::invalid_argument("unknown derived quantity '" + name + "'");
}

}  // namespace

const std::map<std::string, std::string>& derived_catalogue() {
  static const std::map<std::string, std::string> all = [] {
    auto names = kCatalogue;
    for (const auto& [name, meaning] : plectoneme_quantities()) names[name] = meaning;
    return names;
  }();
  return all;
}

std::vector<ContactReport> report_contacts(const ShootingProblem& problem, const Solution& sol) {
  std::vector<ContactReport> out;
  const auto obstacles = problem.obstacles(sol.result.parameters);
  const RodModel& model = problem.equations(sol.result.parameters)->model();
  for (const auto& c : sol.contacts) {
    ContactReport r;
    r.obstacle = c.obstacle;
    r.obstacle_name = obstacles[c.obstacle].name;
    r.extended = c.extended;
    r.s = c.s;
    r.s_end = c.extended ? c.s_end : c.s;
    r.force = c.force;
    r.force_end = c.extended ? c.force_end : 0.0;
    const auto sides = problem.sample(sol.result.x, {r.s - 1e-9, r.s_end + 1e-9});
    r.H_before = hamiltonian(model, sides[0]);
    r.H_after = hamiltonian(model, sides[1]);
    out.push_back(r);
  }
  return out;
}

Solution make_solution(const ShootingProblem& problem, ShootingResult result, int n_samples,
                       const std::vector<std::string>& derived_names) {
  if (n_samples < 2) throw std::invalid_argument("need at least 2 profile samples");
  Solution sol;
  sol.result = std::move(result);
  const double L = problem.length(sol.result.parameters);
  std::vector<double> s(n_samples);
  for (int i = 0; i < n_samples; ++i) s[i] = L * i / (n_samples - 1);
  s.back() = L;  // exactly: L * (n - 1) / (n - 1) may differ from L by an ulp
  sol.profile = problem.sample(sol.result.x, s);
  sol.contacts = problem.contacts_at(sol.result.x);
  const RodModel& model = problem.equations(sol.result.parameters)->model();
  mark_check_failure(&sol.result, profile_failure(model, sol.profile));
  sol.invariants = compute_invariants(model, sol.profile);
  std::optional<PlectonemeMeasures> plectoneme;  // measured once, when a quantity asks for it
  for (const auto& name : derived_names) {
    if (kCatalogue.count(name)) {
      sol.derived[name] = derived_value(name, problem, sol);
      continue;
    }
    if (!plectoneme) plectoneme = measure_plectoneme(problem, sol.result.x, sol.profile);
    sol.derived[name] = plectoneme_quantity(*plectoneme, name);
  }
  return sol;
}

double explicit_s_derivative_of_energy(const RodModel& model, const RodPoint& p) {
  double dV = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double du = p.u[i] - model.u_hat[i](p.s);
    dV += 0.5 * model.B[i].derivative(p.s) * du * du - model.B[i](p.s) * du * model.u_hat[i].derivative(p.s);
    if (model.extensible) {
      const double dv = p.v[i] - model.v_hat[i](p.s);
      dV += 0.5 * model.A[i].derivative(p.s) * dv * dv - model.A[i](p.s) * dv * model.v_hat[i].derivative(p.s);
    }
  }
  return dV;
}

void write_profile_csv(const std::string& path, const RodModel& model, const std::vector<RodPoint>& profile,
                       RodKind kind) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write profile file '" + path + "'");
  out.precision(17);
  const bool planar = kind == RodKind::Planar;
  out << "s,x,y,z,d1x,d1y,d1z,d2x,d2y,d2z,d3x,d3y,d3z,nx,ny,nz,mx,my,mz," << (planar ? "kappa" : "u1,u2,u3")
      << ",H,m3,n_dot_m,dH_ds_identity\n";
  for (const auto& p : profile) {
    out << p.s << ',' << p.r.x() << ',' << p.r.y() << ',' << p.r.z();
    for (int c = 0; c < 3; ++c) out << ',' << p.R(0, c) << ',' << p.R(1, c) << ',' << p.R(2, c);
    out << ',' << p.n.x() << ',' << p.n.y() << ',' << p.n.z() << ',' << p.m.x() << ',' << p.m.y() << ',' << p.m.z();
    if (planar) out << ',' << p.u[1];
    else out << ',' << p.u[0] << ',' << p.u[1] << ',' << p.u[2];
    out << ',' << hamiltonian(model, p) << ',' << p.m.dot(p.R.col(2)) << ',' << p.n.dot(p.m) << ','
        << -explicit_s_derivative_of_energy(model, p) << '\n';
  }
}

}  // namespace kirchhoff

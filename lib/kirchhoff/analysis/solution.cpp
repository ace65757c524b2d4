#include "kirchhoff/analysis/solution.hpp"

#include <fstream>
#include <stdexcept>

#include "kirchhoff/analysis/detail/derived_quantities.hpp"
#include "kirchhoff/shooting/verification.hpp"

namespace kirchhoff {

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
  sol.derived = derived_values(derived_names, problem, sol);
  return sol;
}

Solution make_start_solution(const ShootingProblem& problem, ShootingResult result,
                             const std::vector<std::string>& derived_names) {
  Solution sol;
  sol.result = std::move(result);
  sol.profile = problem.sample(sol.result.x, {0.0});
  sol.contacts = problem.contacts_at(sol.result.x);
  mark_check_failure(&sol.result, profile_failure(problem.equations(sol.result.parameters)->model(), sol.profile));
  sol.derived = derived_values(derived_names, problem, sol);
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

#include "kirchhoff/jobs/result_json.hpp"

#include <cmath>

namespace kirchhoff {
namespace {

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json stats_json(const InvariantStats& s) {
  return {{"mean", s.mean}, {"min", s.min}, {"max", s.max}, {"spread", s.spread},
          {"relative_spread", s.relative_spread()}, {"applies", s.applies}};
}
nlohmann::json vector_stats_json(const VectorInvariantStats& s) {
  return {{"mean", vec(s.mean)}, {"spread", s.spread}, {"applies", s.applies}};
}
nlohmann::json end_json(const RodPoint& p) { return {{"s", p.s}, {"r", vec(p.r)}, {"n", vec(p.n)}, {"m", vec(p.m)}}; }

// JSON has no infinity; a residual that could not be evaluated is null.
nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

}  // namespace

nlohmann::json parameters_json(const Parameters& p) {
  nlohmann::json out = nlohmann::json::object();
  for (int i = 0; i < p.size(); ++i) out[p.names()[i]] = p.values()[i];
  return out;
}

nlohmann::json path_json(const SolvePath& path) {
  nlohmann::json j = {{"method", path.method}};
  if (path.method == "ipopt_seed") j["seed"] = path.seed_summary;
  if (path.method != "homotopy") return j;
  const HomotopyResult& h = path.homotopy;
  const auto values_at = [&](double t) {
    nlohmann::json v = nlohmann::json::object();
    for (const auto& c : path.changes) v[c.name] = c.at(t);
    return v;
  };
  j["from"] = values_at(0.0);
  j["to"] = values_at(1.0);
  j["stop"] = h.stop;
  j["fraction"] = h.fraction;
  j["reached"] = values_at(h.fraction);
  j["points"] = h.points;
  j["branch_points_checked"] = h.branch_points_checked;
  j["branch_points"] = nlohmann::json::array();
  for (double t : h.branch_points) j["branch_points"].push_back(values_at(t));
  j["contact_changes"] = h.contact_changes;
  j["residual_evaluations"] = h.residual_evaluations;
  j["jacobian_evaluations"] = h.jacobian_evaluations;
  return j;
}

// Whether the discretised energy's index is the conjugate points': null where that is not decided
// (the check did not pass its own tests, or the index is undefined, or it is the check's own),
// so that false always means two indices that differ.
static nlohmann::json agreement(const StabilityReport& st, const DiscreteStability& discrete) {
  if (!discrete.trustworthy || !st.index || st.method == "discretised_energy") return nlohmann::json();
  return *st.index == *discrete.index;
}

nlohmann::json stability_json(const StabilityReport& st, const DiscreteStability* discrete) {
  nlohmann::json j;
  j["index"] = st.index ? nlohmann::json(*st.index) : nlohmann::json();
  // (false without an index where an admissible perturbation is known to lower the energy.)
  j["stable"] = st.index ? nlohmann::json(st.stable()) : st.unstable ? nlohmann::json(false) : nlohmann::json();
  // (Null with the index: a count that is not defined has no zero modes to report either.)
  j["zero_modes"] = st.index ? nlohmann::json(st.zero_modes) : nlohmann::json();
  j["conjugate_points"] = st.conjugate_points;
  // The conjugate-point count gives no eigenvalues; the planar discretised check does, once it
  // has passed its own checks.
  j["lowest_eigenvalues"] = nlohmann::json::array();
  if (discrete && discrete->defined()) {
    if (discrete->trustworthy) j["lowest_eigenvalues"] = discrete->lowest_eigenvalues;
    j["cross_check"] = {{"method", "discretised_energy"},
                        {"elements", discrete->elements},
                        {"index", *discrete->index},
                        {"zero_modes", discrete->zero_modes},
                        {"trustworthy", discrete->trustworthy},
                        {"check", discrete->check_message},
                        {"agrees", agreement(st, *discrete)}};
    // With a sliding length: the discrete d^2 E*/d ell^2, beside the conjugate points' S below.
    if (!discrete->sliding_length.empty() && std::isfinite(discrete->reduced_curvature))
      j["cross_check"]["reduced_energy_curvature"] = discrete->reduced_curvature;
  }
  j["method"] = st.method;
  if (!st.method_reason.empty()) j["method_reason"] = st.method_reason;
  if (st.reduced_energy_curvature) {
    j["sliding_length"] = st.sliding_length;
    j["fixed_length_index"] = *st.fixed_length_index;
    j["reduced_energy_curvature"] = *st.reduced_energy_curvature;
  }
  if (st.index && st.method == "discretised_energy") {
    // No conjugate points, so no load-controlled count or correction.
  } else if (st.index) {
    j["load_controlled_index"] = st.dead_load_index;
    j["held_chord_directions"] = st.constraint_count;
    j["constraint_correction"] = st.constraint_correction;
  } else {
    j["reason"] = st.reason;
  }
  return j;
}

nlohmann::json solution_json(const Case& c, const ShootingProblem& problem, const Solution& sol,
                             const StabilityReport& stability, const DiscreteStability* discrete) {
  nlohmann::json j;
  j["case"] = c.path;
  j["status"] = to_string(sol.result.summary.status);
  j["iterations"] = sol.result.summary.iterations;
  j["residual"] = sol.result.summary.residual_norm;
  // How Newton converged where it says ("step at round-off": its residual is the conditioning's floor).
  if (!sol.result.summary.message.empty()) j["message"] = sol.result.summary.message;
  j["parameters"] = parameters_json(sol.result.parameters);
  j["derived"] = nlohmann::json::object();
  for (const auto& [name, value] : sol.derived) j["derived"][name] = value;
  j["invariants"] = {{"H", stats_json(sol.invariants.H)},
                     {"m3", stats_json(sol.invariants.m3)},
                     {"n_dot_m", stats_json(sol.invariants.n_dot_m)},
                     {"n", vector_stats_json(sol.invariants.n)},
                     {"r_cross_n_plus_m", vector_stats_json(sol.invariants.moment_about_origin)}};
  j["ends"] = {{"start", end_json(sol.profile.front())}, {"end", end_json(sol.profile.back())}};
  j["rhs_evaluations"] = problem.rhs_evaluations();
  j["contacts"] = nlohmann::json::array();
  for (const auto& c : report_contacts(problem, sol))
    j["contacts"].push_back({{"obstacle", c.obstacle},
                             {"obstacle_name", c.obstacle_name},
                             {"extended", c.extended},
                             {"s", c.s},
                             {"s_end", c.s_end},
                             {"force", c.force},
                             {"force_end", c.force_end},
                             {"H_before", c.H_before},
                             {"H_after", c.H_after}});
  // Where the case's stated contacts ([[guess.contacts]]) went: moved, released, or kept.
  j["stated_contacts"] = nlohmann::json::array();
  for (const auto& o : stated_contact_outcomes(c.definition.contacts, sol.contacts, problem.obstacles(sol.result.parameters),
                                               problem.length(sol.result.parameters)))
    j["stated_contacts"].push_back({{"obstacle", o.stated.obstacle},
                                    {"extended", o.stated.extended},
                                    {"stated_s", o.stated.s},
                                    {"stated_s_end", o.stated.extended ? o.stated.s_end : o.stated.s},
                                    {"released", o.released},
                                    {"moved", o.moved},
                                    {"s", o.released ? nlohmann::json() : nlohmann::json(o.solved.s)},
                                    {"s_end", o.released ? nlohmann::json()
                                                         : nlohmann::json(o.solved.extended ? o.solved.s_end : o.solved.s)},
                                    {"message", o.message}});
  j["stability"] = stability_json(stability, discrete);
  if (sol.result.summary.used_fallback_search) j["note"] = "starting point from the NLopt fallback search";
  return j;
}

nlohmann::json failure_json(const Case& c, const std::string& status, int iterations, double residual,
                            const std::string& message) {
  return {{"case", c.path}, {"status", status}, {"iterations", iterations},
          {"residual", number_or_null(residual)}, {"message", message},
          {"parameters", parameters_json(c.definition.parameters)}};
}

}  // namespace kirchhoff

// Python bindings: `import kirchhoff` (pybind11). A thin layer over the library that mirrors the
// CLI's `solve`, `continue`, `vibrate` and `plectonemes` commands, returning plain dicts and numpy
// arrays.
//
// Conventions, as in the CLI:
//   - bad input (a case file that cannot be used, an unknown parameter or derived quantity, bad
//     options) raises kirchhoff.CaseError, a subclass of ValueError, with the CLI's message;
//   - a solve that does not converge is not an exception: Solution.status says why;
//   - a continuation run reports why it stopped in Branch.reason.
// The GIL is released while the solver runs; Ctrl-C interrupts a continuation between points.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "kirchhoff/analysis/analytic.hpp"
#include "kirchhoff/analysis/discrete_seed.hpp"
#include "kirchhoff/analysis/discrete_stability.hpp"
#include "kirchhoff/analysis/solution.hpp"
#include "kirchhoff/analysis/stability.hpp"
#include "kirchhoff/analysis/vibration.hpp"
#include "kirchhoff/contact/contact.hpp"
#include "kirchhoff/contact/self_passage.hpp"
#include "kirchhoff/continuation/continuation.hpp"
#include "kirchhoff/equations/invariants.hpp"
#include "kirchhoff/jobs/case_continue.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/jobs/continue_outputs.hpp"
#include "kirchhoff/jobs/deflated_continuation.hpp"
#include "kirchhoff/jobs/equilibria.hpp"
#include "kirchhoff/jobs/result_json.hpp"
#include "kirchhoff/jobs/run_state.hpp"
#include "kirchhoff/reproduce/reproduce.hpp"
#include "kirchhoff/shooting/shooting.hpp"
#include "kirchhoff/sweeps/plectoneme_sweep.hpp"
#include "kirchhoff/sweeps/sweep_run.hpp"

namespace py = pybind11;

namespace {

using namespace kirchhoff;

// ----- conversions -------------------------------------------------------------------------

// None, a mapping (its items()) or an iterable of (name, value) pairs.
std::vector<std::pair<std::string, double>> named_values(const py::object& obj) {
  std::vector<std::pair<std::string, double>> out;
  if (obj.is_none()) return out;
  const py::object items = py::hasattr(obj, "items") ? obj.attr("items")() : obj;
  for (const py::handle item : items) {
    const auto pair = item.cast<py::tuple>();
    if (pair.size() != 2) throw py::type_error("expected (name, value) pairs");
    out.emplace_back(pair[0].cast<std::string>(), pair[1].cast<double>());
  }
  return out;
}

py::dict parameters_dict(const Parameters& p) {
  py::dict d;
  for (int i = 0; i < p.size(); ++i) d[py::str(p.names()[i])] = p.values()[i];
  return d;
}

py::dict stats_dict(const InvariantStats& s) {
  py::dict d;
  d["mean"] = s.mean;
  d["min"] = s.min;
  d["max"] = s.max;
  d["spread"] = s.spread;
  d["relative_spread"] = s.relative_spread();
  d["applies"] = s.applies;
  return d;
}

py::dict vector_stats_dict(const VectorInvariantStats& s) {
  py::dict d;
  d["mean"] = py::make_tuple(s.mean.x(), s.mean.y(), s.mean.z());
  d["spread"] = s.spread;
  d["applies"] = s.applies;
  return d;
}

// The same keys as the CLI's JSON "invariants" object.
// The CLI's JSON "contacts" (report_contacts) as a list of dicts.
py::list contacts_list(const ShootingProblem& problem, const Solution& sol) {
  py::list out;
  for (const auto& contact : report_contacts(problem, sol)) {
    py::dict d;
    d["obstacle"] = contact.obstacle;
    d["obstacle_name"] = contact.obstacle_name;
    d["extended"] = contact.extended;
    d["s"] = contact.s;
    d["s_end"] = contact.s_end;
    d["force"] = contact.force;
    d["force_end"] = contact.force_end;
    d["H_before"] = contact.H_before;
    d["H_after"] = contact.H_after;
    out.append(d);
  }
  return out;
}

py::dict invariants_dict(const InvariantReport& r) {
  py::dict d;
  d["H"] = stats_dict(r.H);
  d["m3"] = stats_dict(r.m3);
  d["n_dot_m"] = stats_dict(r.n_dot_m);
  d["n"] = vector_stats_dict(r.n);
  d["r_cross_n_plus_m"] = vector_stats_dict(r.moment_about_origin);
  return d;
}

template <typename T, typename F>
py::array_t<T> column(size_t n, F&& f) {
  py::array_t<T> a(static_cast<py::ssize_t>(n));
  T* data = a.mutable_data();
  for (size_t i = 0; i < n; ++i) data[i] = f(i);
  return a;
}

py::dict profile_dict(const RodModel& model, const std::vector<RodPoint>& profile, RodKind kind) {
  const size_t n = profile.size();
  py::dict d;
  auto add = [&](const char* name, auto&& f) {
    d[name] = column<double>(n, [&](size_t i) { return f(profile[i]); });
  };
  add("s", [](const RodPoint& p) { return p.s; });
  add("x", [](const RodPoint& p) { return p.r.x(); });
  add("y", [](const RodPoint& p) { return p.r.y(); });
  add("z", [](const RodPoint& p) { return p.r.z(); });
  add("theta", [](const RodPoint& p) { return p.turn_angle; });
  add("nx", [](const RodPoint& p) { return p.n.x(); });
  add("ny", [](const RodPoint& p) { return p.n.y(); });
  add("nz", [](const RodPoint& p) { return p.n.z(); });
  add("mx", [](const RodPoint& p) { return p.m.x(); });
  add("my", [](const RodPoint& p) { return p.m.y(); });
  add("mz", [](const RodPoint& p) { return p.m.z(); });
  add("u1", [](const RodPoint& p) { return p.u[0]; });
  add("u2", [](const RodPoint& p) { return p.u[1]; });
  add("u3", [](const RodPoint& p) { return p.u[2]; });
  // A planar rod's curvature by its name, as the CLI's profile CSV has it (u2 stays for old scripts).
  if (kind == RodKind::Planar) add("kappa", [](const RodPoint& p) { return p.u[1]; });
  add("H", [&](const RodPoint& p) { return hamiltonian(model, p); });
  add("m3", [](const RodPoint& p) { return p.m.dot(p.R.col(2)); });
  return d;
}

// ----- Python-side objects -------------------------------------------------------------------

struct PySolution {
  std::string status;
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;
  std::string message;
  bool used_fallback_search = false;
  long rhs_evaluations = 0;
  std::vector<double> history;
  py::dict parameters, derived, invariants, profile;
  py::list contacts;  // as the CLI's JSON: report_contacts
  py::list stated_contacts;  // as the CLI's JSON: stated_contact_outcomes
  py::object stability = py::none();  // as the CLI's JSON "stability"; None when not converged
  double energy = NAN;                // Case.equilibria(): total potential energy (NaN from solve())
  std::string found_by;               // Case.equilibria(): which seed led to it
  py::object family = py::none();     // Case.equilibria(): its continuous family (1, 2, ...), None if isolated
  py::object path = py::none();       // as the CLI's JSON "path": how the equilibrium was reached
};

struct PyBranch {
  std::string parameter;
  std::string reason;
  std::string message;
  bool switched = false;
  bool ok = false;  // what the CLI turns into exit status 0 (ContinueRunResult::ok)
  std::vector<std::string> contact_changes;  // as the CLI's "contact:" lines
  py::dict points;
  size_t size = 0;
};

struct PyCase {
  Case c;
  std::string phase_condition;  // as given to load_case ("" = the case's own)
  // As given to load_case: continue_(start_from=..., resume=...) loads the case again with the
  // other run's parameter values.
  std::string path;
  ParameterOverrides overrides;
  SolverOverrides solver;
};

// A Python value as the TOML text of a [solver] value (the CLI's --solver KEY=VALUE): True,
// 7, 1e-10, "rk78", ["P"].
std::string toml_text(const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(value)) return py::str(value);
  if (py::isinstance<py::float_>(value)) return py::repr(value);  // shortest round-trip digits
  if (py::isinstance<py::str>(value)) {
    std::string out = "\"";
    for (const char ch : value.cast<std::string>()) {
      if (ch == '"' || ch == '\\') out += '\\';
      out += ch;
    }
    return out + "\"";
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    std::string out = "[";
    for (const py::handle item : value) out += (out.size() > 1 ? ", " : "") + toml_text(item);
    return out + "]";
  }
  throw py::type_error("solver values are bool, int, float, str or lists of them, got " +
                       std::string(py::str(value.get_type())));
}

SolverOverrides solver_values(const py::object& solver) {
  SolverOverrides out;
  if (solver.is_none()) return out;
  for (const auto& [key, value] : solver.cast<py::dict>()) out.emplace_back(key.cast<std::string>(), toml_text(value));
  return out;
}

PyCase py_load_case(const std::string& path, const py::object& set, const std::string& phase_condition,
                    const py::object& solver) {
  ParameterOverrides overrides = named_values(set);
  const SolverOverrides solver_overrides = solver_values(solver);
  PyCase out;
  {
    py::gil_scoped_release release;
    out.c = load_case(path, overrides, phase_condition, solver_overrides);
  }
  out.phase_condition = phase_condition;
  out.path = path;
  out.overrides = overrides;
  out.solver = solver_overrides;
  return out;
}

// The CLI's JSON "stability" block as a dict (index None where it is not defined).
py::dict stability_dict(const StabilityReport& st, const DiscreteStability& discrete) {
  py::dict d;
  d["index"] = st.index ? py::object(py::int_(*st.index)) : py::object(py::none());
  d["stable"] = st.index ? py::object(py::bool_(st.stable())) : py::object(py::none());
  d["zero_modes"] = st.zero_modes;
  d["conjugate_points"] = st.conjugate_points;
  d["lowest_eigenvalues"] = discrete.defined() && discrete.trustworthy ? py::cast(discrete.lowest_eigenvalues)
                                                                       : py::object(py::list());
  if (discrete.defined()) {
    py::dict check;
    check["method"] = "discretised_energy";
    check["elements"] = discrete.elements;
    check["index"] = *discrete.index;
    check["zero_modes"] = discrete.zero_modes;
    check["trustworthy"] = discrete.trustworthy;
    check["check"] = discrete.check_message;
    check["agrees"] = discrete.trustworthy && st.index && *st.index == *discrete.index;
    if (!discrete.sliding_length.empty() && std::isfinite(discrete.reduced_curvature))
      check["reduced_energy_curvature"] = discrete.reduced_curvature;
    d["cross_check"] = check;
  }
  d["method"] = st.method;
  if (!st.method_reason.empty()) d["method_reason"] = st.method_reason;
  if (st.reduced_energy_curvature) {
    d["sliding_length"] = st.sliding_length;
    d["fixed_length_index"] = *st.fixed_length_index;
    d["reduced_energy_curvature"] = *st.reduced_energy_curvature;
  }
  if (st.index && st.method == "discretised_energy") {
    // No conjugate points, so no load-controlled count or correction.
  } else if (st.index) {
    d["load_controlled_index"] = st.dead_load_index;
    d["held_chord_directions"] = st.constraint_count;
    d["constraint_correction"] = st.constraint_correction;
  } else {
    d["reason"] = st.reason;
  }
  return d;
}

PySolution py_solve(const PyCase& pc, const py::object& samples_arg, const std::string& seed, int seed_segments,
                    double max_seconds, bool direct) {
  Case c = pc.c;
  limit_wall_clock(c.definition.options, max_seconds);  // std::invalid_argument (ValueError) outside [0, 1e9]
  const int samples = samples_arg.is_none() ? c.samples : samples_arg.cast<int>();
  if (samples < 2 || samples > 100000)  // as a case file's [output] samples
    throw py::value_error("samples must be in [2, 100000] (got " + std::to_string(samples) + ")");
  if (seed != "guess" && seed != "ipopt") throw py::value_error("seed must be 'guess' or 'ipopt' (got '" + seed + "')");
  if (seed_segments < 4) throw py::value_error("seed_segments must be >= 4");
  std::string seed_refused;  // raised as ValueError once the GIL is back

  PySolution out;
  CaseSolve solved;
  bool integration_failed = false;
  ShootingResult failed;
  {
    py::gil_scoped_release release;
    try {
      // The library's solve of a case, as the CLI's: homotopy from the file's values when
      // parameters changed (or direct), the active-set loop with obstacles, Ipopt's seed; then
      // the solution at `samples` points, its checks, and its stability.
      CaseSolveOptions options;
      options.direct = direct;
      options.seed.ipopt = seed == "ipopt";
      options.seed.segments = seed_segments;
      options.samples = samples;
      solved = solve_case(c, options);
      if (!solved.failure.empty()) {
        integration_failed = true;
        failed.summary = solved.solved.result.summary;  // the failed start solve's, or no residual
        failed.summary.message = solved.message;
      } else if (!solved.converged()) {  // Newton's verdict, or the profile's checks' (verification.hpp)
        failed = solved.solution ? solved.solution->result : solved.solved.result;
      }
    } catch (const InfeasibleContact& e) {
      integration_failed = true;
      failed.summary.status = SolverStatus::MaxIterations;
      failed.summary.residual_norm = INFINITY;
      failed.summary.message = std::string("infeasible: ") + e.what();
    } catch (const IntegrationError& e) {
      integration_failed = true;
      failed.summary.status = SolverStatus::IntegrationFailed;
      failed.summary.iterations = 0;
      failed.summary.residual_norm = INFINITY;
      failed.summary.message = std::string("the initial guess cannot be integrated: ") + e.what();
    } catch (const std::invalid_argument& e) {  // a case the Ipopt seed does not model
      seed_refused = e.what();
    } catch (const std::runtime_error& e) {     // the seed's Ipopt did not converge
      integration_failed = true;
      failed.summary.status = SolverStatus::MaxIterations;
      failed.summary.residual_norm = INFINITY;
      failed.summary.message = e.what();
    }
  }
  const std::unique_ptr<ShootingProblem>& problem = solved.solved.problem;
  const Solution* sol = !integration_failed && seed_refused.empty() && solved.converged() ? &*solved.solution : nullptr;
  const std::string& path_failure = solved.failure;  // a homotopy that stopped short: its status word
  // As the CLI's JSON "path" (one builder for both).
  out.path = py::module_::import("json").attr("loads")(path_json(solved.path).dump());
  if (!seed_refused.empty()) throw py::value_error(seed_refused);
  const ShootingResult& r = sol ? sol->result : failed;
  out.status = path_failure.empty() ? to_string(r.summary.status) : path_failure;
  out.converged = r.summary.converged();
  out.iterations = r.summary.iterations;
  out.residual = r.summary.residual_norm;
  out.message = r.summary.message;
  out.used_fallback_search = r.summary.used_fallback_search;
  out.history = r.summary.history;
  out.rhs_evaluations = problem ? problem->rhs_evaluations() : 0;  // none when the guess failed
  if (!sol) {
    // As the CLI's failure JSON: the case's parameters, no results.
    out.parameters = parameters_dict(c.definition.parameters);
    return out;
  }
  out.parameters = parameters_dict(sol->result.parameters);
  for (const auto& name : c.derived) out.derived[py::str(name)] = sol->derived.at(name);
  out.invariants = invariants_dict(sol->invariants);
  out.profile = profile_dict(problem->equations(sol->result.parameters)->model(), sol->profile,
                             problem->definition().kind);
  out.stability = stability_dict(*solved.stability, *solved.stability_check);
  out.contacts = contacts_list(*problem, *sol);
  for (const auto& o : stated_contact_outcomes(c.definition.contacts, sol->contacts,
                                               problem->obstacles(sol->result.parameters),
                                               problem->length(sol->result.parameters))) {
    py::dict d;
    d["obstacle"] = o.stated.obstacle;
    d["extended"] = o.stated.extended;
    d["stated_s"] = o.stated.s;
    d["stated_s_end"] = o.stated.extended ? o.stated.s_end : o.stated.s;
    d["released"] = o.released;
    d["moved"] = o.moved;
    d["s"] = o.released ? py::object(py::none()) : py::object(py::float_(o.solved.s));
    d["s_end"] = o.released ? py::object(py::none())
                            : py::object(py::float_(o.solved.extended ? o.solved.s_end : o.solved.s));
    d["message"] = o.message;
    out.stated_contacts.append(d);
  }
  return out;
}

std::vector<ContinuationEvent> events_from(const py::object& obj, bool stop) {
  std::vector<ContinuationEvent> out;
  for (const auto& [name, value] : named_values(obj)) out.push_back({name, value, stop, ""});
  return out;
}

struct BranchPoint {
  ContinuationPoint point;
  int branch;
  int row;  // RunPoint::row: continuous across branches and across a resume
};

py::dict branch_points_dict(const std::vector<BranchPoint>& pts, const std::vector<std::string>& derived) {
  const size_t n = pts.size();
  py::dict d;
  auto f = [&](const char* name, auto&& g) { d[name] = column<double>(n, [&](size_t i) { return g(pts[i].point); }); };
  auto i = [&](const char* name, auto&& g) { d[name] = column<long>(n, [&](size_t k) { return static_cast<long>(g(pts[k])); }); };
  d["index"] = column<long>(n, [&](size_t k) { return static_cast<long>(pts[k].row); });
  i("branch", [](const BranchPoint& b) { return b.branch; });
  f("parameter", [](const ContinuationPoint& p) { return p.parameter; });
  f("arclength", [](const ContinuationPoint& p) { return p.arclength; });
  for (const auto& name : derived)
    d[py::str(name)] = column<double>(n, [&](size_t k) {
      const auto& dv = pts[k].point.derived;
      const auto it = dv.find(name);
      return it == dv.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
    });
  // Absolute spread (the catalogue's H_spread) and the relative spreads of the CLI's CSV.
  f("H_spread", [](const ContinuationPoint& p) { return p.invariants.H.spread; });
  f("H_relative_spread", [](const ContinuationPoint& p) { return p.invariants.H.relative_spread() + 0.0; });
  f("m3_relative_spread", [](const ContinuationPoint& p) { return p.invariants.m3.relative_spread() + 0.0; });
  f("n_dot_m_relative_spread", [](const ContinuationPoint& p) { return p.invariants.n_dot_m.relative_spread() + 0.0; });
  d["H_flat"] = column<bool>(n, [&](size_t k) { return pts[k].point.H_flat; });
  py::list types, events;
  for (const auto& b : pts) {
    types.append(py::str(to_string(b.point.type)));
    events.append(py::str(b.point.event));
  }
  d["type"] = types;
  d["event"] = events;
  i("multiplicity", [](const BranchPoint& b) { return b.point.multiplicity; });
  i("newton_iterations", [](const BranchPoint& b) { return b.point.newton_iterations; });
  // NaN where the index is not defined or was not computed (stability=False).
  f("stability_index", [](const ContinuationPoint& p) {
    return p.stability_index ? static_cast<double>(*p.stability_index) : std::numeric_limits<double>::quiet_NaN();
  });
  i("zero_modes", [](const BranchPoint& b) { return b.point.zero_modes; });
  return d;
}

// Vibrations about the case's equilibrium (the CLI's `vibrate`).
py::dict py_vibrate(const PyCase& pc, int modes, double rho_s, int samples) {
  const Case& c = pc.c;
  if (c.definition.kind != RodKind::Planar)
    throw py::value_error(c.path + ": vibrate handles planar rods only (eqs. B.4); this case is spatial");
  VibrationOptions options;
  options.modes = modes;
  options.rho_s = rho_s;
  options.profile_samples = samples;
  if (std::string e = options.validate(); !e.empty()) throw py::value_error(e);
  VibrationAnalysis analysis;
  Parameters at;  // the equilibrium's parameters, solved-for ones included
  {
    py::gil_scoped_release release;
    // The equilibrium as solve() and the CLI's `vibrate` reach it (homotopy from the file's
    // values when parameters changed); the vibrations need neither its profile nor its index.
    CaseSolveOptions solve_options;
    solve_options.solution = solve_options.stability = solve_options.stability_check = false;
    const CaseSolve solved = solve_case(c, solve_options);
    if (!solved.failure.empty())
      throw std::runtime_error(c.path + ": the equilibrium was not reached: " + solved.failure + ": " + solved.message);
    if (!solved.converged())
      throw std::runtime_error(c.path + ": the equilibrium did not converge: " + solved.summary().brief_report());
    const DefinitionSolve& equilibrium = solved.solved;
    analysis = VibrationProblem(*equilibrium.problem, equilibrium.result.x, options).analyse();  // invalid_argument -> ValueError
    at = equilibrium.result.parameters;
  }
  auto mode_dict = [](const VibrationMode& m) {
    py::dict d;
    d["omega"] = m.omega;
    d["omega2"] = m.omega2;
    d["growth_rate"] = m.growth_rate();
    d["H_vib"] = stats_dict(m.H_vib_stats);
    d["matching_residual"] = m.matching_residual;
    const size_t n = m.s.size();
    d["s"] = column<double>(n, [&](size_t i) { return m.s[i]; });
    // Planar state layout (x, y, theta, n_x, n_y, m).
    const std::pair<const char*, int> components[] = {{"xbar", 0}, {"ybar", 1}, {"thetabar", 2},
                                                      {"nbarx", 3}, {"nbary", 4}, {"mbar", 5}};
    for (const auto& [name, index] : components)
      d[name] = column<double>(n, [&, index = index](size_t i) { return m.state[i][index]; });
    d["H_vib_along_s"] = column<double>(n, [&](size_t i) { return m.H_vib[i]; });
    return d;
  };
  py::list mode_list, unstable_list;
  for (const VibrationMode& m : analysis.modes) mode_list.append(mode_dict(m));
  for (const VibrationMode& m : analysis.unstable_modes) unstable_list.append(mode_dict(m));
  py::dict out;
  // Imaginary frequencies: omega^2 < 0, their number the index under dead loads.
  out["unstable_modes"] = unstable_list;
  out["negative_omega2_count"] = analysis.negative_omega2_count();
  out["unstable_searched"] = analysis.unstable_searched;
  out["omega2"] = analysis.omega2();
  out["frequencies"] = column<double>(analysis.modes.size(), [&](size_t k) { return analysis.modes[k].omega; });
  out["straight_equilibrium"] = analysis.straight_equilibrium;
  out["parameters"] = parameters_dict(at);  // as the CLI's JSON "parameters"
  out["modes"] = mode_list;
  return out;
}

// The points of a run, for Branch.points; Ctrl-C stops a long run between points (the exception
// unwinds the continuation).
class CollectingSink : public ContinueSink {
 public:
  std::vector<BranchPoint> points;
  void point(const RunPoint& p) override {
    points.push_back({*p.point, p.branch, p.row});
    points.back().point.jacobian.reset();
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
};

// A path argument (str or os.PathLike) as text; "" for None.
std::string path_text(const py::object& path) {
  return path.is_none() ? "" : py::module_::import("os").attr("fspath")(path).cast<std::string>();
}

// What identifies a run for resume=True (ContinueRequest::identity; the CLI's run_arguments): the
// case file (path and content hash), how it was loaded, and the arguments that decide the points.
std::string python_run_identity(const PyCase& pc, const ContinueRequest& r, const std::string& start_from) {
  std::ifstream in(pc.path, std::ios::binary);
  std::uint64_t hash = 14695981039346656037ull;  // FNV-1a, as the CLI's
  for (char ch; in.get(ch);) hash = (hash ^ static_cast<unsigned char>(ch)) * 1099511628211ull;
  std::ostringstream o;
  o << std::setprecision(17) << "python case=" << pc.path << " case_hash=" << std::hex << hash << std::dec;
  for (const auto& entry : pc.overrides) o << " set=" << entry.first << "=" << entry.second;
  for (const auto& entry : pc.solver) o << " solver=" << entry.first << "=" << entry.second;
  o << " phase=" << pc.phase_condition << " param=" << r.parameter << " to=" << r.target << " direction=" << r.direction
    << " step=" << r.initial_step << " min_step=" << r.min_step << " max_step=" << r.max_step
    << " max_points=" << r.max_points << " switch_at_bp=" << r.switch_at_bp << " side=" << r.switch_side
    << " branch_points=" << r.detect_branch_points << " stability=" << r.compute_stability << " samples=" << r.samples;
  for (const auto& e : r.events) o << (e.stop ? " event=" : " record=") << e.quantity << "=" << e.value;
  if (!start_from.empty()) o << " start_from=" << start_from;
  return o.str();
}

// resume / start_from as the CLI's --resume / --start-from: where the run starts, and the case
// loaded again when the other run's parameter values differ from pc's (run_state.hpp).
Case plan_python_start(const PyCase& pc, const std::string& state_path, bool resume, const std::string& start_from,
                       const std::string& start_param, ContinueRequest* request) {
  ParameterOverrides overrides = pc.overrides;
  bool reload = false;
  if (resume) {
    if (state_path.empty()) throw CaseError("resume=True needs state=PATH, the state file of the run to resume");
    if (!std::filesystem::exists(state_path))
      throw CaseError("cannot resume: no state file " + state_path + " (a run saves it after its first point)");
    request->resume = resumable_state(state_path, request->identity);
    if (request->resume->has_set_parameters) overrides = request->resume->set_parameters, reload = true;
  } else if (!start_from.empty()) {
    const RunStart start = plan_start_from(start_from, start_param, pc.overrides);
    overrides = start.parameters, reload = true;
    request->start = start.at;
    request->start_name = start_from;
  }
  request->set_parameters = overrides;
  return reload ? load_case(pc.path, overrides, pc.phase_condition, pc.solver) : pc.c;
}

// The CLI's `continue` (continue_case: the same statuses and messages), its points in memory.
PyBranch py_continue(const PyCase& pc, const std::string& parameter, const py::object& to, double step,
                     double min_step, double max_step, int max_points, const py::object& events,
                     const py::object& record, int switch_at_bp, double side, int samples, double direction,
                     bool branch_points, bool stability, bool deflate, int deflate_max, double max_seconds,
                     const py::object& state, bool resume, const py::object& start_from,
                     const std::string& start_param) {
  ContinueRequest request;
  request.parameter = parameter;
  if (!to.is_none()) request.target = to.cast<double>();
  request.direction = direction;
  request.initial_step = step;
  request.min_step = min_step;
  request.max_step = max_step;
  request.max_points = max_points;
  request.samples = samples;
  request.detect_branch_points = branch_points;
  request.compute_stability = stability;
  request.events = events_from(events, true);
  for (auto& e : events_from(record, false)) request.events.push_back(e);
  request.switch_at_bp = switch_at_bp;
  request.switch_side = side;
  request.phase_condition = pc.phase_condition;
  request.deflate = deflate;
  request.deflate_max = deflate_max;
  request.max_seconds = max_seconds;
  const std::string state_path = path_text(state), from = path_text(start_from);
  if (deflate && !state_path.empty()) throw CaseError("state: a deflate run is not resumable, so it saves no state");
  request.identity = python_run_identity(pc, request, from);
  const Case c = plan_python_start(pc, state_path, resume, from, start_param, &request);
  if (std::string why = request.validate(c); !why.empty()) throw CaseError(why);
  CollectingSink collect;
  // The state after every point and at the end, as the CLI's --checkpoint 0.
  StateFileSink state_file(state_path, std::chrono::steady_clock::duration::zero());
  std::vector<ContinueSink*> sinks = {&collect};
  if (!state_path.empty()) sinks.push_back(&state_file);
  ContinueRunResult result;
  {
    py::gil_scoped_release release;
    result = continue_case(c, request, sinks);
  }
  PyBranch out;
  out.parameter = parameter;
  out.reason = result.status;
  out.message = result.message;
  out.switched = result.switched;
  out.ok = result.ok;
  out.contact_changes = result.contact_changes;
  out.size = collect.points.size();
  out.points = branch_points_dict(collect.points, result.derived);
  return out;
}

// kirchhoff.reproduce(out, full): the CLI's `reproduce` (reproduce.hpp), its report rows as dicts.
py::list py_reproduce(const py::object& out, bool full, const py::object& cases) {
  const ReproduceRequest request{path_text(out), cases.is_none() ? std::string(KIRCHHOFF_CASES_DIR) : path_text(cases),
                                 full};
  ReproduceResult result;
  {
    py::gil_scoped_release release;
    result = reproduce(request, [](const std::string& line) { std::cerr << "  " << line << "\n"; });  // as the CLI's
  }
  const auto optional = [](const std::optional<double>& v) { return v ? py::object(py::float_(*v)) : py::object(py::none()); };
  py::list rows;
  for (const ReportRow& r : result.rows) {
    py::dict d;
    d["id"] = r.id;
    d["quantity"] = r.quantity;
    d["paper"] = optional(r.paper);
    d["analytic"] = optional(r.analytic);
    d["numeric"] = r.numeric;
    d["rel_error"] = r.checked() ? py::object(py::float_(r.rel_error())) : py::object(py::none());
    d["tolerance"] = r.checked() ? py::object(py::float_(r.tolerance)) : py::object(py::none());
    d["status"] = r.status();
    d["stability"] = r.stability;
    d["note"] = r.note;
    rows.append(d);
  }
  return rows;
}

// A CSV the sweep wrote, as a dict of its columns: numpy arrays of numbers, lists of str for the
// text columns (numpy's own reader, so that the columns are what the CLI's users load).
py::dict csv_columns(const std::string& path) {
  const py::module_ np = py::module_::import("numpy");
  const py::object table = np.attr("genfromtxt")(path, py::arg("delimiter") = ",", py::arg("names") = true,
                                                 py::arg("dtype") = py::none(), py::arg("encoding") = "utf-8",
                                                 py::arg("ndmin") = 1);
  py::dict d;
  for (const py::handle name : table.attr("dtype").attr("names")) {
    const py::object values = table[name];
    d[name] = values.attr("dtype").attr("kind").cast<std::string>() == "U" ? values.attr("tolist")() : values;
  }
  return d;
}

// The Fig. 11 sweep (the CLI's `plectonemes`): each slenderness's branches, as the CSVs it wrote.
// kirchhoff.sweep(spec, out): the serial sweep (sweep_run.hpp), its index as columns: numbers
// (NaN where empty) in the numeric columns, text in the others.
py::dict py_sweep(const std::string& spec_path, const std::string& out, bool resume) {
  SweepSummary summary;
  try {
    const SweepSpec spec = load_sweep(spec_path);
    SweepRunOptions options;
    options.out_dir = out;
    options.resume = resume;
    py::gil_scoped_release release;
    summary = kirchhoff::run_sweep(spec, options);
  } catch (const SweepError& e) {
    throw CaseError(e.what());
  }
  py::dict columns;
  const SweepIndex& index = summary.index;
  for (std::size_t k = 0; k < index.columns.size(); ++k) {
    py::list column;
    for (const auto& row : index.rows) {
      if (!index.numeric[k]) column.append(row[k]);
      else column.append(row[k].empty() ? std::numeric_limits<double>::quiet_NaN() : std::stod(row[k]));
    }
    columns[py::str(index.columns[k])] = column;
  }
  return columns;
}

py::dict py_plectonemes(const std::string& out, const std::vector<double>& slenderness,
                        const std::vector<double>& turns, const py::object& case_path,
                        const std::vector<double>& from_ply, double turns_min, double hard_from, bool resume,
                        double sensitivity_tol) {
  PlectonemesArguments args;
  args.case_path = case_path.is_none() ? std::string(KIRCHHOFF_CASES_DIR) + "/plectoneme.toml"
                                       : case_path.cast<std::string>();
  args.out_dir = out;
  args.slenderness = slenderness;
  args.turns = turns;
  args.from_ply = from_ply;
  args.turns_min = turns_min;
  args.hard_from = hard_from;
  args.resume = resume;
  args.sensitivity_tol = sensitivity_tol;
  args.progress = [](const std::string& line) { std::cerr << line << "\n"; };  // as the CLI's
  if (hard_from < 0) throw CaseError("hard_from must be >= 0 (got " + std::to_string(hard_from) + ")");
  if (sensitivity_tol < 0) throw CaseError("sensitivity_tol must be >= 0");
  // Ctrl-C stops the sweep after its next point (the KeyboardInterrupt stays pending until the
  // GIL is back); resume=True then continues it.
  args.after_point = [] {
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw SweepStopped{};
  };
  PlectonemeSweep sweep;
  try {
    py::gil_scoped_release release;
    (void)load_case(args.case_path, {});  // a case file that cannot be used is a CaseError
    sweep = sweep_plectonemes(args, std::cout);  // so are arguments it refuses
  } catch (const SweepStopped&) {
    throw py::error_already_set();
  }
  py::dict branches;
  for (const auto& b : sweep.branches) {
    py::dict d;
    d["barrier"] = b.barrier_csv.empty() ? py::object(py::none()) : py::object(csv_columns(b.barrier_csv));
    d["exact"] = b.ply_csv.empty() ? py::object(py::none()) : py::object(csv_columns(b.ply_csv));
    d["barrier_csv"] = b.barrier_csv;
    d["exact_csv"] = b.ply_csv;
    d["stop"] = b.summary.stop;
    d["exact_stop"] = b.summary.hard_ply_stop;
    branches[py::float_(b.slenderness)] = d;
  }
  py::dict result;
  result["branches"] = branches;
  result["points"] = sweep.points;
  result["seconds"] = sweep.seconds;
  return result;
}

// One equilibrium of Case.equilibria() as a Solution, with the fields solve() fills (the
// stability without the discretised cross-check, as the CLI's `equilibria` JSON).
PySolution equilibrium_solution(const Case& c, const Equilibrium& e) {
  PySolution out;
  const Solution& sol = e.solution;
  out.status = to_string(sol.result.summary.status);
  out.converged = sol.result.summary.converged();
  out.residual = sol.result.summary.residual_norm;
  out.message = e.found_by;
  out.energy = e.energy;
  out.found_by = e.found_by;
  if (e.family > 0) out.family = py::int_(e.family);
  out.parameters = parameters_dict(sol.result.parameters);
  for (const auto& name : c.derived) out.derived[py::str(name)] = sol.derived.at(name);
  out.invariants = invariants_dict(sol.invariants);
  out.profile = profile_dict(e.problem->equations(sol.result.parameters)->model(), sol.profile,
                             e.problem->definition().kind);
  out.stability = stability_dict(e.stability, DiscreteStability{});
  out.contacts = contacts_list(*e.problem, sol);
  return out;
}

// The CLI's `equilibria`: distinct equilibria at the case's parameters, by increasing energy.
py::list py_equilibria(const PyCase& pc, int max, double max_seconds, const py::object& samples_arg) {
  const Case& c = pc.c;
  const int samples = samples_arg.is_none() ? c.samples : samples_arg.cast<int>();
  if (samples < 2 || samples > 100000) throw py::value_error("samples must be in [2, 100000]");
  if (max < 1) throw py::value_error("max must be >= 1");
  if (!(max_seconds >= 0)) throw py::value_error("max_seconds must be >= 0");
  EquilibriaOptions options;
  options.max_equilibria = max;
  options.max_seconds = max_seconds;
  EquilibriaSearch search;
  {
    py::gil_scoped_release release;
    search = find_equilibria(c.definition, c.start_guess, c.derived, samples, options);
  }
  py::list out;
  for (const auto& e : search.equilibria) out.append(equilibrium_solution(c, e));
  return out;
}

std::string repr_solution(const PySolution& s) {
  std::ostringstream o;
  o.precision(10);
  o << "<kirchhoff.Solution status=" << s.status << " iterations=" << s.iterations << " residual=" << s.residual;
  for (const auto& [k, v] : s.derived) o << " " << py::str(k).cast<std::string>() << "=" << v.cast<double>();
  o << ">";
  return o.str();
}

// Solution, the result of Case.solve() and of each of Case.equilibria().
void bind_solution(py::module_& m) {
  py::class_<PySolution>(m, "Solution", R"doc(The result of Case.solve().

Attributes:
    status (str): "converged", "max_iterations", "singular_jacobian", "integration_failed",
        "line_search_failed" or "unfolding_not_zero".
    converged (bool): status == "converged".
    iterations (int): Newton iterations.
    residual (float): max |F_i| at the returned point (inf if it could not be evaluated).
    message (str): the solver's reason when it stopped without converging.
    used_fallback_search (bool): the NLopt search supplied the starting point.
    rhs_evaluations (int): right-hand-side evaluations of the rod equations.
    history (list of float): residual after each Newton iteration.
    parameters (dict): parameter values at the solution (unknown ones solved for); the case's
        values when not converged.
    derived (dict): the case's derived quantities ([output] derived); empty when not converged.
    invariants (dict): as the CLI's JSON: "H", "m3", "n_dot_m" map to dicts with mean, min, max,
        spread, relative_spread, applies; "n" and "r_cross_n_plus_m" to mean (3-tuple), spread,
        applies. Empty when not converged.
    profile (dict of numpy arrays): equally spaced samples s, x, y, z, theta (frame turn angle),
        nx, ny, nz (force), mx, my, mz (moment), u1, u2, u3 (curvatures and twist), H (arclength
        Hamiltonian), m3 (m.d3). Empty when not converged.)doc")
      .def_readonly("status", &PySolution::status)
      .def_readonly("converged", &PySolution::converged)
      .def_readonly("iterations", &PySolution::iterations)
      .def_readonly("residual", &PySolution::residual)
      .def_readonly("message", &PySolution::message)
      .def_readonly("used_fallback_search", &PySolution::used_fallback_search)
      .def_readonly("rhs_evaluations", &PySolution::rhs_evaluations)
      .def_readonly("contacts", &PySolution::contacts, "Contacts: list of {obstacle, obstacle_name, extended, s, s_end, force, force_end, H_before, H_after}")
      .def_readonly("stated_contacts", &PySolution::stated_contacts,
                    "Where the case's [[guess.contacts]] went: list of {obstacle, extended, stated_s, stated_s_end, "
                    "released, moved, s, s_end, message} (message: 'stated at s = 0.5 converged at s = 0.557')")
      .def_readonly("history", &PySolution::history)
      .def_readonly("parameters", &PySolution::parameters)
      .def_readonly("derived", &PySolution::derived)
      .def_readonly("invariants", &PySolution::invariants)
      .def_readonly("profile", &PySolution::profile)
      .def_readonly("path", &PySolution::path,
                    "How the equilibrium was reached, as the CLI's JSON 'path': method ('direct', 'homotopy' or\n"
                    "'ipopt_seed'); for a homotopy from/to/reached values, points, branch_points crossed, stop")
      .def_readonly("stability", &PySolution::stability,
                    "Stability of the equilibrium (None when not converged): dict with index (None where not "
                    "defined, with reason), stable, zero_modes, conjugate_points, method, as the CLI's JSON.")
      .def_readonly("energy", &PySolution::energy,
                    "Total potential energy (Case.equilibria(): elastic energy plus the potential of the field\n"
                    "and of the given end loads, docs/equilibria.md; NaN from solve())")
      .def_readonly("found_by", &PySolution::found_by, "Case.equilibria(): which seed led to it ('' from solve())")
      .def_readonly("family", &PySolution::family,
                    "Case.equilibria(): the continuous family (1, 2, ...) of an equilibrium with zero modes, as the\n"
                    "CLI's JSON 'family' (members: equal energies and a rigid motion between them,\n"
                    "docs/equilibria.md); None for an isolated one and from solve()")
      .def("__bool__", [](const PySolution& s) { return s.converged; }, "True when converged.")
      .def("__repr__", &repr_solution);
}

// Branch, the result of Case.continue_().
void bind_branch(py::module_& m) {
  py::class_<PyBranch>(m, "Branch", R"doc(The result of Case.continue_().

Attributes:
    parameter (str): the continued parameter.
    reason (str): why the (last) run stopped: "reached_target", "max_points",
        "parameter_bounds", "step_too_small", "event", "branch_point", "start_failed",
        "inadmissible", "time_limit" (deflate=True: "no_equilibrium" too), the CLI's word.
    message (str): details (the event, why the start failed, or "no branch point K before the
        run stopped (...)" when switch_at_bp found too few branch points).
    switched (bool): the bifurcating branch was followed (switch_at_bp > 0 and found).
    contact_changes (list of str): cases with obstacles: each change of the active set, where and
        what ("Delta = 0.0250667: a contact appears with obstacle 0 at s = 0.5"), as the CLI's
        "contact:" lines; the point's `event` holds the event's name (obstacle_reached,
        contact_lifts_off, contact_flattens, ...) as the CLI's CSV does.
    ok (bool): what the CLI reports with exit status 0 (kirchhoff::ended_normally): not
        start_failed, step_too_small, inadmissible or time_limit, and the requested branch switch
        happened.
    points (dict): one entry per point, in order; numpy arrays unless said otherwise:
        index, branch (0 = starting branch, 1 = after the switch), parameter, arclength, each
        derived quantity (the case's [output] derived plus event quantities; NaN where
        unavailable), H_spread (max - min of H along the rod), H_relative_spread,
        m3_relative_spread, n_dot_m_relative_spread (spreads over their scale, as in the CLI's
        CSV), H_flat (bool), type (list of str: start, regular, fold, branch_point, event,
        endpoint), event (list of str), multiplicity, newton_iterations, stability_index (float:
        the index, NaN where it is not defined or stability=False), zero_modes.
        With a switch, the branch point ends branch 0 and starts branch 1.)doc")
      .def_readonly("parameter", &PyBranch::parameter)
      .def_readonly("reason", &PyBranch::reason)
      .def_readonly("message", &PyBranch::message)
      .def_readonly("switched", &PyBranch::switched)
      .def_readonly("ok", &PyBranch::ok)
      .def_readonly("contact_changes", &PyBranch::contact_changes)
      .def_readonly("points", &PyBranch::points)
      .def("__len__", [](const PyBranch& b) { return b.size; })
      .def("__repr__", [](const PyBranch& b) {
        return "<kirchhoff.Branch " + b.parameter + ": " + std::to_string(b.size) + " points, reason=" + b.reason +
               (b.message.empty() ? "" : " (" + b.message + ")") + ">";
      });
}

// Case.continue_().
void bind_case_continuation(py::class_<PyCase>& cls) {
  cls.def("continue_", &py_continue, py::arg("param"), py::arg("to") = py::none(), py::kw_only(),
          py::arg("step") = 0.05, py::arg("min_step") = 1e-7, py::arg("max_step") = 0.5,
          py::arg("max_points") = 500, py::arg("events") = py::none(), py::arg("record") = py::none(),
          py::arg("switch_at_bp") = 0, py::arg("side") = 1.0, py::arg("samples") = 101,
          py::arg("direction") = 1.0, py::arg("branch_points") = true, py::arg("stability") = true,
          py::arg("deflate") = false, py::arg("deflate_max") = 16, py::arg("max_seconds") = 0.0,
          py::arg("state") = py::none(), py::arg("resume") = false, py::arg("start_from") = py::none(),
          py::arg("start_param") = "",
          R"doc(Pseudo-arclength continuation in one parameter (the CLI's `continue`).

Args:
    param (str): the continued parameter; its value in the case is the starting one.
    to (float, optional): stop on reaching this value (None: no target, go along `direction`).
    step, min_step, max_step (float): initial, smallest and largest pseudo-arclength step.
    max_points (int): points per branch.
    events (dict name -> value): stop when a derived quantity crosses the value.
    record (dict name -> value): record such crossings without stopping.
    switch_at_bp (int): > 0: stop at that branch point and follow the bifurcating branch
        (a double branch point of a spatial rod switches with the axial phase condition).
    side (float): +1 / -1, which side of the bifurcating branch.
    samples (int): profile points per point for invariants and derived quantities.
    direction (float): +1 / -1, initial direction when there is no target.
    branch_points (bool): look for branch points (an SVD per point: most of the cost of a run on
        a multiple-shooting case of hundreds of unknowns, such as plectoneme.toml); folds are
        found either way.
    stability (bool): the stability index of every point (column stability_index: NaN where
        it is not defined; zero_modes beside it), as the CLI's CSV.
    deflate (bool): follow every branch through the equilibria found at the start by deflation
        (as equilibria() lists them, at most deflate_max): branch k starts at the k-th by energy.
    max_seconds (float): wall-clock limit of the whole run (0: none); past it the run stops
        with reason 'time_limit', resumable with state= and resume=True.
    state (str or path, optional): the run's state file (the CLI's OUT.csv.state.json), saved
        after every point and at the end.
    resume (bool): go on from the state file `state` of an interrupted run (time_limit, Ctrl-C)
        made with the same case and arguments (another run's state is refused): the Branch
        holds the points after the last one saved, their `index` continuing the run's, so the
        two Branches together are the uninterrupted run's points.
    start_from (str or path, optional): another run's state file: start at its last point
        (its unknowns, active contacts and parameter values, then this case's `set`), as the
        CLI's --start-from. start_param names that run's parameter for files too old to say.

Returns:
    Branch (points of all branches concatenated, with a `branch` column; `index` is the row of
    the run, as in the CLI's CSV).

Raises:
    CaseError (ValueError): unknown parameter or derived quantity, invalid options.)doc");
}

// Case.equilibria() and Case.vibrate().
void bind_case_equilibria_and_vibrations(py::class_<PyCase>& cls) {
  cls.def("equilibria", &py_equilibria, py::kw_only(), py::arg("max") = 16, py::arg("max_seconds") = 120.0,
          py::arg("samples") = py::none(),
          R"doc(The distinct equilibria at the case's parameters (the CLI's `equilibria`), by deflated Newton.

Starts from the case's guess, its mirror images, the low modes of every equilibrium found and,
for planar rods clamped at both ends, Ipopt's discretised minimisers (docs/equilibria.md).

Args:
    max (int): stop once this many distinct equilibria are found.
    max_seconds (float): wall-clock limit of the search (0: none).
    samples (int, optional): profile points; default the case's [output] samples.

Returns:
    list of Solution, by increasing energy: each converged and admissible, with the fields
    solve() gives (derived, invariants, profile, contacts, stability) and energy, found_by,
    family (the continuous family of an equilibrium with zero modes, None when isolated).)doc")
      .def("vibrate", &py_vibrate, py::kw_only(), py::arg("modes") = 3, py::arg("rho_s") = 1.0,
           py::arg("samples") = 201,
           R"doc(Small-amplitude vibrations about the case's equilibrium (the CLI's `vibrate`, eqs. B.4).

The equilibrium is solved as solve() does; the ends keep the case's conditions with imposed
positions and angles held and end loads dead (nbar = 0, mbar = 0 along them).

Args:
    modes (int): number of lowest frequencies.
    rho_s (float): mass per unit length.
    samples (int): points per mode shape.

Returns:
    dict: "frequencies" (numpy array, increasing), "straight_equilibrium" (bool), "modes": a list
    of dicts with "omega", "H_vib" (mean, min, max, spread, relative_spread, applies: invariant of
    eq. 95b only on a straight equilibrium), "matching_residual", and numpy arrays "s", "xbar",
    "ybar", "thetabar", "nbarx", "nbary", "mbar", "H_vib_along_s" (and "omega2", "growth_rate").
    "unstable_modes": the same for omega^2 < 0 (imaginary frequencies: the equilibrium is unstable
    under dead loads; their number, "negative_omega2_count", is its index), most negative first;
    "unstable_searched" (bool) and "omega2" (every mode's omega^2, increasing). "parameters": the
    equilibrium's (those solved for included), as solve() gives them.

Raises:
    ValueError: a spatial case, bad options, or a rod the vibration equations do not cover.
    RuntimeError: the equilibrium does not converge.)doc");
}

// Case: the loaded case, its properties and what can be done with it.
void bind_case(py::module_& m) {
  py::class_<PyCase> cls(m, "Case", R"doc(A loaded case file (see load_case).

Attributes:
    path, title, description (str)
    kind (str): "planar" or "spatial".
    parameters (dict): [parameters] after the overrides given to load_case.
    unknowns (list of str): parameters solved for ([solver] unknowns).
    derived_names (list of str): the derived quantities reported ([output] derived).
    samples (int): default profile samples ([output] samples).
    phase_condition (str): the override given to load_case ("" for the case's own).)doc");
  cls.def_property_readonly("path", [](const PyCase& p) { return p.c.path; })
      .def_property_readonly("title", [](const PyCase& p) { return p.c.title; })
      .def_property_readonly("description", [](const PyCase& p) { return p.c.description; })
      .def_property_readonly("kind", [](const PyCase& p) {
        return p.c.definition.kind == RodKind::Planar ? "planar" : "spatial";
      })
      .def_property_readonly("parameters", [](const PyCase& p) { return parameters_dict(p.c.definition.parameters); })
      .def_property_readonly("unknowns", [](const PyCase& p) { return p.c.definition.unknown_parameters; })
      .def_property_readonly("derived_names", [](const PyCase& p) { return p.c.derived; })
      .def_property_readonly("samples", [](const PyCase& p) { return p.c.samples; })
      .def_readonly("phase_condition", &PyCase::phase_condition);
  cls.def("solve", &py_solve, py::arg("samples") = py::none(), py::kw_only(), py::arg("seed") = "guess",
          py::arg("seed_segments") = 200, py::arg("max_seconds") = kDefaultSolveSeconds, py::arg("direct") = false,
          R"doc(Solves the case by shooting.

Parameters changed from the file's values (load(..., set=...)) are reached by continuation from
the file's own values (a homotopy in all of them together), so the equilibrium lies on the branch
the case's guess starts; a fold on the way gives status 'fold' with where it is in `message`.

Args:
    samples (int, optional): profile points (>= 2); default the case's [output] samples.
    seed (str): 'guess' starts from the case's [guess]; 'ipopt' from Ipopt's minimum of the
        discretised energy, its shape and contact set (planar clamped-clamped rods; ValueError
        for other cases).
    seed_segments (int): segments of that discretised rod.
    max_seconds (float): wall-clock limit of the solve (0: none); past it the result's status
        is 'time_limit'.
    direct (bool): Newton from the case's guess at the requested values instead of the homotopy.

Returns:
    Solution. Non-convergence is reported in Solution.status, not raised.)doc");
  bind_case_continuation(cls);
  bind_case_equilibria_and_vibrations(cls);
  cls.def("__repr__", [](const PyCase& p) {
        return "<kirchhoff.Case " + (p.c.title.empty() ? p.c.path : "'" + p.c.title + "'") + ">";
      });
}

// The whole jobs: load_case, reproduce, sweep, plectonemes.
void bind_jobs(py::module_& m) {
  m.def("load_case", &py_load_case, py::arg("path"), py::arg("set") = py::none(), py::arg("phase_condition") = "",
        py::arg("solver") = py::none(),
        R"doc(Reads and checks a TOML case file.

Args:
    path (str): the case file.
    set (dict name -> value, optional): replaces [parameters] values (names must exist; one
        computed from others, A = "pi*r^2", is refused: set r).
    phase_condition (str): "" (the case's own), "none" or "axial".
    solver (dict key -> value, optional): replaces or adds [solver] keys, checked as in the file,
        as the CLI's --solver KEY=VALUE: {"tolerance": 1e-10, "stepper": "dopri5", "unknowns": ["P"]}.

Returns:
    Case.

Raises:
    CaseError (ValueError): the file cannot be used; the message names the key and the reason.)doc");

  m.def("reproduce", &py_reproduce, py::arg("out"), py::arg("full") = false, py::kw_only(), py::arg("cases") = py::none(),
        R"doc(Recompute the reference paper's results (the CLI's `kirchhoff reproduce`, the same files).

Writes out/report.md, out/report.json and the figure data in out/profiles/ (and with full=True
out/wall_phase/); progress on stderr. A few minutes; full=True about 20.

Args:
    out (str or path): output folder (created).
    full (bool): add Fig. 11's L/2R = 500 and 1000 and the hard wall's phase diagram.
    cases (str or path, optional): the cases folder (default: the shipped cases/).

Returns:
    list of dict, one per report row: id, quantity, paper and analytic (None where there is
    none), numeric, rel_error and tolerance (None for rows with nothing exact to check),
    status ('pass', 'FAIL' or 'info'), stability, note.

Raises:
    RuntimeError: a result that could not be computed (the report is then not written).)doc");

  m.def("sweep", &py_sweep, py::arg("spec"), py::arg("out"), py::kw_only(), py::arg("resume") = false,
        R"doc(Runs a sweep file serially (the CLI's `kirchhoff sweep SPEC --out OUT`, the same files:
OUT/jobs/<id>/, OUT/index.csv, OUT/times.csv; docs/sweeps.md) and returns the index as columns:
{"job": [...], "kind": [...], <each swept parameter>: [float], "status", "reason",
"contact_state", "stable_states": [str], "stability_index", "equilibria", "energy", <derived>:
[float, NaN where not defined]}. A failing job is a row with its status, not an exception.

Args:
    spec (str): the sweep file.
    out (str): output folder (created); one holding results is refused unless resume.
    resume (bool): keep the finished jobs in `out`, run the others.

Raises:
    CaseError (ValueError): the sweep file or the folder is refused (file, line, key, reason).)doc");

  m.def("plectonemes", &py_plectonemes, py::arg("out"), py::arg("slenderness") = std::vector<double>{100},
        py::arg("turns") = std::vector<double>{10}, py::kw_only(), py::arg("case") = py::none(),
        py::arg("from_ply") = std::vector<double>{}, py::arg("turns_min") = 4.0, py::arg("hard_from") = 0.0,
        py::arg("resume") = false, py::arg("sensitivity_tol") = kPlectonemeSensitivityTol,
        R"doc(The Fig. 11 sweep of cases/plectoneme.toml (the CLI's `kirchhoff plectonemes`, the same
files into `out`; progress on stderr, a line per slenderness on stdout).

Each slenderness L/2R is followed in the end rotation from the untwisted rod (a self-contact
barrier) through the loop's closing into the ply, up to its `turns`; with `hard_from` > 0 the
barrier branch stops at that many turns and its ply is re-solved with exact contact in the
shooting core (the strands touching: rho = R, complementarity checked) and followed up to
`turns` and down to `turns_min`. Slendernesses in `from_ply` are reached from the ply of the one
before them in `slenderness` (with `hard_from`: from its exact ply, no barrier branch).

Args:
    out (str): output folder (created).
    slenderness, turns (lists of float): L/2R and the largest turns, one each.
    case (str, optional): the case file (default: the source tree's cases/plectoneme.toml).
    from_ply (list of float): slendernesses reached from the previous one's ply.
    turns_min (float): where the legs from a ply end on the way down.
    hard_from (float): exact contact from this many turns (0: the barrier throughout).
    resume (bool): continue a sweep that was stopped (killed, or Ctrl-C): finished branches are
        kept, an unfinished one continues from its last saved point.
    sensitivity_tol (float): tolerance of the variational equations (0: the case's).

Returns:
    dict: "branches": {slenderness: {"barrier": columns or None, "exact": columns or None,
    "barrier_csv", "exact_csv" (paths, "" when absent), "stop", "exact_stop" (why each ended)}},
    "points" (computed by this call), "seconds". Columns are the CSV's: numpy arrays (index, turns,
    T_ext, helix_angle, helix_radius, T_rho2_over_EI beside eq61, m3 beside m3_eq58b, H_A, H_B,
    self_distance, and on the exact ply min_contact_force, min_wrap_pressure, ply_clearance,
    contact_count, ...) and "type" as a list of str.

Raises:
    CaseError (ValueError): arguments the sweep refuses (lists of different lengths, a
        slenderness from a ply the sweep would not have) or a case file that cannot be used.
    RuntimeError: a branch failed (its message says which and why; the CSVs so far are kept).
    KeyboardInterrupt: Ctrl-C (the sweep stops after its current point).)doc");
}

// derived_catalogue and the closed forms the tests and notebooks compare with.
void bind_reference(py::module_& m) {
  m.def("derived_catalogue", &derived_catalogue,
        "The derived quantities a case or an event may name, with a one-line meaning each (dict).");

  m.def(
      "analytic_pinned_load",
      [](double L, double EI, double theta0) { return analytic::PinnedElastica{L, EI, theta0}.load(); },
      py::arg("L"), py::arg("EI"), py::arg("theta0"),
      R"doc(Load P = 4 K(k)^2 EI / L^2, k = sin(theta0 / 2), of the pinned-pinned Elastica whose end
slope is theta0 (Love's elliptic-function solution, first mode; K from GSL).

Raises ValueError outside L > 0, EI > 0, 0 < theta0 < pi.)doc");

  m.def("analytic_pinned_column_frequency", &analytic::pinned_column_frequency, py::arg("EI"), py::arg("P"),
        py::arg("rho_s"), py::arg("L"), py::arg("mode") = 1,
        R"doc(Frequency of mode k of a pinned-pinned column under the compressive dead load P (eq. 96):
omega^2 = (EI (k pi/L)^4 - P (k pi/L)^2) / rho_s.)doc");
  m.def("analytic_plectoneme_end_tension", &analytic::plectoneme_end_tension, py::arg("theta"), py::arg("EI"),
        py::arg("R"),
        R"doc(Eq. (61): the end pull of a plectoneme of helical angle theta (rad, < pi/4) and helix radius R:
T_ext = EI/(2 R^2) sin^4 theta (1 + 2/cos 2theta).)doc");
  m.def("analytic_helix_twisting_moment", &analytic::helix_twisting_moment, py::arg("theta"), py::arg("EI"),
        py::arg("R"), R"doc(Eq. (58b): m3 = 2 EI sin^3 theta cos theta / (R cos 2theta) in a ply of radius R.)doc");
}

}  // namespace

namespace kirchhoff {
void bind_system_continuation(py::module_& m);  // system_continuation.cpp
}

PYBIND11_MODULE(kirchhoff, m) {
  m.doc() = R"doc(Elastic-rod equilibria by shooting and pseudo-arclength continuation.

    >>> import kirchhoff
    >>> case = kirchhoff.load_case("cases/simply_supported.toml", set={"theta0": 1.0})
    >>> sol = case.solve(samples=201)
    >>> sol.status, sol.derived["P"]            # ('converged', 11.2224...)
    >>> sol.profile["x"], sol.profile["y"]      # numpy arrays along the rod
    >>> branch = kirchhoff.load_case("cases/euler_column.toml", set={"P": 1, "theta_guess": 0}) \
    ...     .continue_("P", to=12, switch_at_bp=1, events={"theta0": 3.0})
    >>> branch.points["parameter"], branch.points["theta0"], branch.points["type"]

Bad input raises kirchhoff.CaseError (a ValueError) with the message the command-line tool
prints; a solve that does not converge returns a Solution whose status says why.)doc";

  auto& case_error = py::register_exception<CaseError>(m, "CaseError", PyExc_ValueError);
  case_error.attr("__doc__") = "A case file or option that cannot be used (a subclass of ValueError).";
  // Solution and Branch first: the signatures of Case's methods name them.
  bind_solution(m);
  bind_branch(m);
  bind_case(m);
  bind_jobs(m);
  bind_reference(m);
  kirchhoff::bind_system_continuation(m);

  m.attr("__version__") = KIRCHHOFF_VERSION;
}

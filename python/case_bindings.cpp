// kirchhoff.Case: load_case, solve, continue_, equilibria, vibrate - each maps its arguments onto
// the library's job (case_solve.hpp, case_continue.hpp, equilibria.hpp, vibration.hpp).
#include "bindings.hpp"

namespace kirchhoff::python_bindings {
PyCase py_load_case(const std::string& path, const py::object& set, const std::string& phase_condition,
                    const py::object& solver) {
  ParameterOverrides overrides;
  try {
    overrides = named_values(set);
  } catch (const CaseError& e) {  // (the CLI's --set words, with the file, as its other refusals)
    throw CaseError(path + ": set: " + e.what());
  }
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

namespace {

// An optional count given as a Python object (None: the case's own), by Count's rule.
int samples_or(const py::object& samples, int fallback) {
  if (samples.is_none()) return fallback;
  py::detail::make_caster<Count> count;
  if (!count.load(samples, true)) throw py::type_error("samples must be an int, not a bool or a float");
  return py::detail::cast_op<Count>(count);
}

PySolution py_solve(const PyCase& pc, const py::object& samples_arg, const std::string& seed, Count seed_segments,
                    double seed_amplitude, double max_seconds, bool direct) {
  Case c = pc.c;
  // Bad arguments are CaseError (a ValueError), as the module's other bad input.
  try {
    limit_wall_clock(c.definition.options, max_seconds);
  } catch (const std::invalid_argument& e) {
    throw CaseError(std::string("max_seconds: ") + e.what());
  }
  const int samples = samples_or(samples_arg, c.samples);
  if (samples < 2 || samples > 100000)  // as a case file's [output] samples
    throw CaseError("samples must be in [2, 100000] (got " + std::to_string(samples) + ")");
  const StartSeed start = start_seed(seed, seed_segments, seed_amplitude);
  std::string seed_refused;  // raised as ValueError once the GIL is back

  PySolution out;
  CaseSolve solved;
  {
    py::gil_scoped_release release;
    try {
      // The library's solve of a case, as the CLI's: homotopy from the file's values when
      // parameters changed (or direct), the active-set loop with obstacles, Ipopt's seed; then
      // the solution at `samples` points, its checks, and its stability. A solve that cannot
      // start, or a path that stopped short, is a failure with the CLI's status word.
      CaseSolveOptions options;
      options.direct = direct;
      options.seed = start;
      options.samples = samples;
      solved = solve_case(c, options);
    } catch (const std::invalid_argument& e) {  // a case the Ipopt seed does not model
      seed_refused = e.what();
    }
  }
  if (!seed_refused.empty()) throw CaseError(seed_refused);
  const std::unique_ptr<ShootingProblem>& problem = solved.solved.problem;
  const Solution* sol = solved.converged() ? &*solved.solution : nullptr;
  ShootingResult failed;  // Newton's verdict, the profile's checks' (verification.hpp), or the failure's
  if (!solved.failure.empty()) {
    failed.summary = solved.solved.result.summary;
    failed.summary.message = solved.message;
  } else if (!sol) {
    failed = solved.solution ? solved.solution->result : solved.solved.result;
  }
  // As the CLI's JSON "path" (one builder for both).
  out.path = python_object(path_json(solved.path));
  const ShootingResult& r = sol ? sol->result : failed;
  out.status = solved.failure.empty() ? to_string(r.summary.status) : solved.failure;
  out.converged = r.summary.converged();
  out.iterations = r.summary.iterations;
  out.residual = r.summary.residual_norm;
  out.message = out.converged ? r.summary.message : r.summary.why_stopped();  // as the CLI's JSON
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
  out.stability = python_object(stability_json(*solved.stability, &*solved.stability_check));
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

// Vibrations about the case's equilibrium (the CLI's `vibrate`).
py::dict py_vibrate(const PyCase& pc, Count modes, double rho_s, Count samples) {
  Case c = pc.c;
  VibrationOptions options;
  options.modes = modes;
  options.rho_s = rho_s;
  options.profile_samples = samples;
  // Refused before the equilibrium is solved for, as the CLI's `vibrate`, which also limits the
  // solve to its default wall clock.
  if (std::string why = vibration_refusal(c.definition, options); !why.empty())
    throw CaseError(c.path + ": " + why);
  limit_wall_clock(c.definition.options, kDefaultSolveSeconds);
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
  out["H_vib_not_conserved"] = analysis.H_vib_not_conserved;
  out["parameters"] = parameters_dict(at);  // as the CLI's JSON "parameters"
  out["modes"] = mode_list;
  return out;
}

// One equilibrium of Case.equilibria() as a Solution, with the fields solve() fills (the
// stability without the discretised cross-check, as the CLI's `equilibria` JSON).
PySolution equilibrium_solution(const Case& c, const Equilibrium& e) {
  PySolution out;
  const Solution& sol = e.solution;
  out.status = to_string(sol.result.summary.status);
  out.converged = sol.result.summary.converged();
  out.residual = sol.result.summary.residual_norm;
  const std::string& how = e.solution.result.summary.message;  // "step at round-off", or empty
  out.message = how.empty() ? e.found_by : e.found_by + "; converged with " + how;
  out.energy = e.energy;
  out.found_by = e.found_by;
  if (e.family > 0) out.family = py::int_(e.family);
  out.parameters = parameters_dict(sol.result.parameters);
  for (const auto& name : c.derived) out.derived[py::str(name)] = sol.derived.at(name);
  out.invariants = invariants_dict(sol.invariants);
  out.profile = profile_dict(e.problem->equations(sol.result.parameters)->model(), sol.profile,
                             e.problem->definition().kind);
  out.stability = python_object(stability_json(e.stability));
  out.contacts = contacts_list(*e.problem, sol);
  return out;
}

// The CLI's `equilibria`: distinct equilibria at the case's parameters, by increasing energy.
py::list py_equilibria(const PyCase& pc, Count max, double max_seconds, const py::object& samples_arg) {
  const Case& c = pc.c;
  const int samples = samples_or(samples_arg, c.samples);
  if (samples < 2 || samples > 100000) throw CaseError("samples must be in [2, 100000]");
  EquilibriaOptions options;
  options.max_equilibria = max;
  options.max_seconds = max_seconds;
  if (const std::string why = options.validate(); !why.empty()) throw CaseError(why);
  EquilibriaSearch search;
  {
    py::gil_scoped_release release;
    search = find_case_equilibria(c, samples, options);
  }
  py::list out;
  for (const auto& e : search.equilibria) out.append(equilibrium_solution(c, e));
  // None found is the CLI's failure (exit 1): here an empty list, with the CLI's message and the
  // search's last word as a warning, so that it is not silent.
  if (search.equilibria.empty()) {
    std::string message = c.path + ": no equilibrium found (" + search.stopped_because + ")";
    if (!search.log.empty()) message += "; the search's last line: " + search.log.back();
    if (PyErr_WarnEx(PyExc_RuntimeWarning, message.c_str(), 1) != 0) throw py::error_already_set();
  }
  return out;
}

// Case.equilibria() and Case.vibrate().
void bind_case_equilibria_and_vibrations(py::class_<PyCase>& cls) {
  cls.def("equilibria", &py_equilibria, py::kw_only(), py::arg("max") = 16, py::arg("max_seconds") = 120.0,
          py::arg("samples") = py::none(),
          R"doc(The distinct equilibria at the case's parameters (the CLI's `equilibria`), by deflated Newton.

Starts from the case's guess, its mirror images, the low modes of every equilibrium found and,
for planar rods clamped or pinned at both ends, Ipopt's discretised minimisers (docs/equilibria.md).

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
    "unstable_searched" (bool) and "omega2" (every mode's omega^2, increasing).
    "H_vib_not_conserved": why H_vib varies along the modes ("" where it is conserved: a straight
    equilibrium of a uniform rod in no field). "parameters": the
    equilibrium's (those solved for included), as solve() gives them.

Raises:
    ValueError: a spatial case, bad options, or a rod the vibration equations do not cover.
    RuntimeError: the equilibrium does not converge.)doc");
}

}  // namespace

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
          py::arg("seed_segments") = 200, py::arg("seed_amplitude") = 0.05,
          py::arg("max_seconds") = kDefaultSolveSeconds, py::arg("direct").noconvert() = false,
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
    seed_amplitude (float): amplitude of the buckling mode Ipopt starts from, as a fraction of L;
        its sign picks the side (the CLI's --seed-amplitude).
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

}  // namespace kirchhoff::python_bindings

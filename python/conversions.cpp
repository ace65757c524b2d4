// Conversions of the library's results into Python dicts and numpy arrays, and of Python
// arguments into the library's (bindings.hpp).
#include "bindings.hpp"
#include "kirchhoff/analysis/point_record.hpp"

namespace kirchhoff::python_bindings {
// None, a mapping (its items()) or an iterable of (name, value) pairs.
std::vector<std::pair<std::string, double>> named_values(const py::object& obj) {
  std::vector<std::pair<std::string, double>> out;
  if (obj.is_none()) return out;
  const py::object items = py::hasattr(obj, "items") ? obj.attr("items")() : obj;
  for (const py::handle item : items) {
    const auto pair = item.cast<py::tuple>();
    if (pair.size() != 2) throw py::type_error("expected (name, value) pairs");
    const auto name = pair[0].cast<std::string>();
    try {
      // (pybind11 casts True to 1.0: a bool is not a number a case's value can be.)
      if (py::isinstance<py::bool_>(pair[1])) throw py::cast_error();
      out.emplace_back(name, pair[1].cast<double>());
    } catch (const py::cast_error&) {
      // The CLI's words for `--set NAME=abc` (a CaseError, so a ValueError).
      throw CaseError("'" + py::str(pair[1]).cast<std::string>() + "' given for '" + name + "' is not a number");
    }
  }
  return out;
}

StartSeed start_seed(const std::string& seed, int segments, double amplitude) {
  if (seed != "guess" && seed != "ipopt") throw CaseError("seed must be 'guess' or 'ipopt' (got '" + seed + "')");
  StartSeed out;
  out.ipopt = seed == "ipopt";
  out.segments = segments;
  out.amplitude = amplitude;
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

namespace {

py::dict vector_stats_dict(const VectorInvariantStats& s) {
  py::dict d;
  d["mean"] = py::make_tuple(s.mean.x(), s.mean.y(), s.mean.z());
  d["spread"] = s.spread;
  d["applies"] = s.applies;
  return d;
}

}  // namespace

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

// The same keys as the CLI's JSON "invariants" object.
py::dict invariants_dict(const InvariantReport& r) {
  py::dict d;
  d["H"] = stats_dict(r.H);
  d["m3"] = stats_dict(r.m3);
  d["n_dot_m"] = stats_dict(r.n_dot_m);
  d["n"] = vector_stats_dict(r.n);
  d["r_cross_n_plus_m"] = vector_stats_dict(r.moment_about_origin);
  return d;
}

namespace {

}  // namespace

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

namespace {

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

}  // namespace

SolverOverrides solver_values(const py::object& solver) {
  SolverOverrides out;
  if (solver.is_none()) return out;
  for (const auto& [key, value] : solver.cast<py::dict>()) out.emplace_back(key.cast<std::string>(), toml_text(value));
  return out;
}

py::object python_object(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

std::vector<ContinuationEvent> events_from(const py::object& obj, bool stop) {
  std::vector<ContinuationEvent> out;
  for (const auto& [name, value] : named_values(obj)) out.push_back({name, value, stop, ""});
  return out;
}

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
  f("H_spread", [](const ContinuationPoint& p) { return invariants_of(p).H.spread; });
  f("H_relative_spread", [](const ContinuationPoint& p) { return invariants_of(p).H.relative_spread() + 0.0; });
  f("m3_relative_spread", [](const ContinuationPoint& p) { return invariants_of(p).m3.relative_spread() + 0.0; });
  f("n_dot_m_relative_spread", [](const ContinuationPoint& p) { return invariants_of(p).n_dot_m.relative_spread() + 0.0; });
  d["H_flat"] = column<bool>(n, [&](size_t k) { return H_is_flat(pts[k].point); });
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
  f("zero_modes", [](const ContinuationPoint& p) {
    return p.stability_index ? static_cast<double>(p.zero_modes) : std::numeric_limits<double>::quiet_NaN();
  });
  return d;
}

// A path argument (str or os.PathLike) as text; "" for None.
std::string path_text(const py::object& path) {
  return path.is_none() ? "" : py::module_::import("os").attr("fspath")(path).cast<std::string>();
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

}  // namespace kirchhoff::python_bindings

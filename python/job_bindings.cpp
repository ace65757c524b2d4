// The module's functions: load_case, reproduce, sweep, plectonemes, and the closed forms and
// catalogue the tests and notebooks compare with.
#include "bindings.hpp"

namespace kirchhoff::python_bindings {
namespace {

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
  // Ctrl-C stops the sweep after its next point (the KeyboardInterrupt stays pending until the
  // GIL is back); resume=True then continues it.
  args.after_point = [] {
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw SweepStopped{};
  };
  PlectonemeSweep sweep;
  try {
    py::gil_scoped_release release;
    sweep = sweep_plectonemes(args, std::cout);  // CaseError: a case file or arguments it refuses
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

}  // namespace

// The whole jobs: load_case, reproduce, sweep, plectonemes (and the heap setting long ones want).
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

  m.def("reproduce", &py_reproduce, py::arg("out"), py::arg("full").noconvert() = false, py::kw_only(), py::arg("cases") = py::none(),
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
    CaseError (ValueError): a case file missing from `cases` or refused (the CLI's exit 2).
    RuntimeError: a result that could not be computed (the report is then not written).)doc");

  m.def("sweep", &py_sweep, py::arg("spec"), py::arg("out"), py::kw_only(), py::arg("resume").noconvert() = false,
        R"doc(Runs a sweep file serially (the CLI's `kirchhoff sweep SPEC --out OUT`, the same files:
OUT/jobs/<id>/, OUT/index.csv, OUT/times.csv; docs/sweeps.md) and returns the index as columns:
{"job": [...], "kind": [...], <each swept parameter>: [float], "status", "reason",
"contact_state", "stable_states": [str], "stability_index", "zero_modes", "equilibria", "energy", <derived>:
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
        py::arg("resume").noconvert() = false, py::arg("sensitivity_tol") = kPlectonemeSensitivityTol,
        R"doc(The Fig. 11 sweep of cases/plectoneme.toml (the CLI's `kirchhoff plectonemes`, the same
files into `out`; progress on stderr, a line per slenderness on stdout).

Each slenderness L/2R is followed in the end rotation from the untwisted rod (a self-contact
barrier) through the loop's closing into the ply, up to its `turns`; with `hard_from` > 0 the
barrier branch stops at that many turns and its ply is re-solved with exact contact in the
shooting core (the strands touching: rho = R, complementarity checked) and followed up to
`turns` and down to `turns_min`. Slendernesses in `from_ply` are reached from the ply of the one
before them in `slenderness` (with `hard_from`: from its exact ply, no barrier branch).
The long exact plies (L/2R = 500 and 1000) run about 1.5 times faster after
kirchhoff.keep_freed_memory(), which the CLI calls at its start.

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

  m.def("keep_freed_memory", &keep_freed_memory_for_reuse,
        R"doc(Keep freed memory blocks of up to 1 GiB in the process's heap for reuse (what the CLI does
when it starts). Long multiple-shooting rods (the exact plies of `plectonemes` at L/2R = 500
and 1000) allocate Jacobians of 100 MB and more several times per point; by default each is
mapped afresh and page-faulted in by the system, a third of such a run's time. Process-wide and
for the rest of the process: its resident memory then stays at its peak.

Returns:
    bool: False where the C library has no such setting (nothing changed).)doc");
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

}  // namespace kirchhoff::python_bindings

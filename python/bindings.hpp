// What the Python module's files share (kirchhoff_module.cpp defines the module): the
// Python-side objects (Solution, Branch, Case), the conversions of the library's results into
// dicts and numpy arrays, and the functions each file binds. Argument mapping only: the library
// does the work.
#pragma once

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
#include "kirchhoff/jobs/case_equilibria.hpp"
#include "kirchhoff/jobs/case_file.hpp"
#include "kirchhoff/jobs/case_solve.hpp"
#include "kirchhoff/jobs/continue_outputs.hpp"
#include "kirchhoff/jobs/deflated_continuation.hpp"
#include "kirchhoff/jobs/equilibria.hpp"
#include "kirchhoff/jobs/process_memory.hpp"
#include "kirchhoff/jobs/result_json.hpp"
#include "kirchhoff/jobs/run_state.hpp"
#include "kirchhoff/reproduce/reproduce.hpp"
#include "kirchhoff/shooting/shooting.hpp"
#include "kirchhoff/sweeps/plectoneme_sweep.hpp"
#include "kirchhoff/sweeps/sweep_run.hpp"

#include "count_argument.hpp"

namespace kirchhoff::python_bindings {

namespace py = pybind11;

// ----- the Python-side objects -----

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
  std::vector<std::string> notes;            // the run's notes, as the CLI prints them
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

struct BranchPoint {
  ContinuationPoint point;
  int branch;
  int row;  // RunPoint::row: continuous across branches and across a resume
};

// ----- conversions (conversions.cpp) -----

// A numpy array of n values f(0), ..., f(n - 1).
template <typename T, typename F>
py::array_t<T> column(size_t n, F&& f) {
  py::array_t<T> a(static_cast<py::ssize_t>(n));
  T* data = a.mutable_data();
  for (size_t i = 0; i < n; ++i) data[i] = f(i);
  return a;
}

py::dict stats_dict(const InvariantStats& s);

// None, a mapping (its items()) or an iterable of (name, value) pairs.
std::vector<std::pair<std::string, double>> named_values(const py::object& obj);
// The Ipopt seed of solve() and continue_() from their seed= ('guess' or 'ipopt', else CaseError),
// seed_segments= and seed_amplitude= (checked by the library, as the CLI's --seed options are).
StartSeed start_seed(const std::string& seed, int segments, double amplitude);

py::dict parameters_dict(const Parameters& p);

// The CLI's JSON "contacts" (report_contacts) as a list of dicts.
py::list contacts_list(const ShootingProblem& problem, const Solution& sol);

// The same keys as the CLI's JSON "invariants" object.
py::dict invariants_dict(const InvariantReport& r);

py::dict profile_dict(const RodModel& model, const std::vector<RodPoint>& profile, RodKind kind);

SolverOverrides solver_values(const py::object& solver);

// A JSON value of the CLI's output (result_json.hpp) as the Python object json.loads makes of it,
// so that Python and the CLI report the same blocks from one builder (stability_json, path_json).
py::object python_object(const nlohmann::json& j);

std::vector<ContinuationEvent> events_from(const py::object& obj, bool stop);

py::dict branch_points_dict(const std::vector<BranchPoint>& pts, const std::vector<std::string>& derived);

// A path argument (str or os.PathLike) as text; "" for None.
std::string path_text(const py::object& path);

// A CSV the sweep wrote, as a dict of its columns: numpy arrays of numbers, lists of str for the
// text columns (numpy's own reader, so that the columns are what the CLI's users load).
py::dict csv_columns(const std::string& path);

// ----- the module's parts -----

// kirchhoff.load_case (case_bindings.cpp).
PyCase py_load_case(const std::string& path, const py::object& set, const std::string& phase_condition,
                    const py::object& solver);

void bind_solution(py::module_& m);  // result_bindings.cpp
void bind_branch(py::module_& m);  // result_bindings.cpp
void bind_case(py::module_& m);  // case_bindings.cpp
// Case.continue_ (continue_bindings.cpp), bound by bind_case.
void bind_case_continuation(py::class_<PyCase>& cls);
void bind_jobs(py::module_& m);  // job_bindings.cpp
// derived_catalogue and the closed forms the tests and notebooks compare with.
void bind_reference(py::module_& m);  // job_bindings.cpp

}  // namespace kirchhoff::python_bindings

namespace kirchhoff {
void bind_system_continuation(pybind11::module_& m);  // system_continuation.cpp
}  // namespace kirchhoff

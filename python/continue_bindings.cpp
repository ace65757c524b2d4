// Case.continue_: maps its arguments onto a ContinueRequest and runs the library's continue_case
// (case_continue.hpp), as the CLI's `continue` does; the points come back as Branch.points.
#include "bindings.hpp"
#include "kirchhoff/jobs/run_plan.hpp"

namespace kirchhoff::python_bindings {
namespace {

// The points of a run, for Branch.points; Ctrl-C stops a long run between points (the exception
// unwinds the continuation).
class CollectingSink : public ContinueSink {
 public:
  std::vector<BranchPoint> points;
  std::vector<std::string> notes;  // the run's notes, as the CLI prints them
  void note(const std::string& line) override { notes.push_back(line); }
  void point(const RunPoint& p) override {
    points.push_back({*p.point, p.branch, p.row});
    points.back().point.jacobian.reset();
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
};

// The CLI's `continue` (continue_case: the same statuses and messages), its points in memory.
PyBranch py_continue(const PyCase& pc, const std::string& parameter, const py::object& to, double step,
                     double min_step, double max_step, Count max_points, const py::object& events,
                     const py::object& record, Count switch_at_bp, double side, Count samples, double direction,
                     bool branch_points, bool stability, bool deflate, Count deflate_max, double max_seconds,
                     const py::object& state, bool resume, const py::object& start_from,
                     const std::string& start_param, const std::string& seed, Count seed_segments,
                     double seed_amplitude, double checkpoint) {
  const StartSeed start = start_seed(seed, seed_segments, seed_amplitude);
  if (!(checkpoint >= 0 && checkpoint <= 1e6)) throw CaseError("checkpoint must be in [0, 1e6] seconds");
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
  request.seed = start;
  const std::string state_path = path_text(state), from = path_text(start_from);
  if (deflate && !state_path.empty()) throw CaseError("state: a deflate run is not resumable, so it saves no state");
  RunPlanInputs inputs;  // the case loaded again where the run's parameter values differ from pc's
  inputs.case_path = pc.path;
  inputs.overrides = pc.overrides;
  inputs.phase_condition = pc.phase_condition;
  inputs.solver = pc.solver;
  inputs.resume = resume;
  inputs.state_path = state_path;
  inputs.start_from = from;
  inputs.start_param = start_param;
  const Case c = plan_run(inputs, &request, &pc.c).c;
  CollectingSink collect;
  // The state at most once per `checkpoint` seconds and at the end, as the CLI's --checkpoint.
  StateFileSink state_file(state_path, std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                           std::chrono::duration<double>(checkpoint)));
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
  out.notes = collect.notes;
  out.size = collect.points.size();
  out.points = branch_points_dict(collect.points, result.derived);
  return out;
}

}  // namespace

// Case.continue_().
void bind_case_continuation(py::class_<PyCase>& cls) {
  cls.def("continue_", &py_continue, py::arg("param"), py::arg("to") = py::none(), py::kw_only(),
          py::arg("step") = 0.05, py::arg("min_step") = 1e-7, py::arg("max_step") = 0.5,
          py::arg("max_points") = 500, py::arg("events") = py::none(), py::arg("record") = py::none(),
          py::arg("switch_at_bp") = 0, py::arg("side") = 1.0, py::arg("samples") = 101,
          py::arg("direction") = 1.0, py::arg("branch_points").noconvert() = true, py::arg("stability").noconvert() = true,
          py::arg("deflate").noconvert() = false, py::arg("deflate_max") = 16, py::arg("max_seconds") = 0.0,
          py::arg("state") = py::none(), py::arg("resume").noconvert() = false, py::arg("start_from") = py::none(),
          py::arg("start_param") = "", py::arg("seed") = "guess", py::arg("seed_segments") = 200,
          py::arg("seed_amplitude") = 0.05, py::arg("checkpoint") = 0.0,
          R"doc(Pseudo-arclength continuation in one parameter (the CLI's `continue`).

Args:
    param (str): the continued parameter; its value in the case is the starting one.
    to (float, optional): stop on reaching this value on the starting branch (None: no target, go
        along `direction`); a branch switched onto runs to an event or `max_points`.
    step, min_step, max_step (float): initial, smallest and largest pseudo-arclength step (the
        first step is `step` within [min_step, max_step]).
    max_points (int): points per branch.
    events (dict name -> value): stop when a derived quantity crosses the value.
    record (dict name -> value): record such crossings without stopping.
    switch_at_bp (int): > 0: stop at that branch point and follow the bifurcating branch
        (a double branch point of a spatial rod switches with the axial phase condition).
    side (float): +1 / -1, which side of the bifurcating branch.
    samples (int): profile points per point for invariants and derived quantities.
    direction (float): +1 / -1, initial direction when there is no target (with one, the
        target gives it, and a direction pointing away from it is refused).
    branch_points (bool): look for branch points (an SVD per point: most of the cost of a run on
        a multiple-shooting case of hundreds of unknowns, such as plectoneme.toml); folds are
        found either way.
    stability (bool): the stability index of every point (column stability_index: NaN where
        it is not defined; zero_modes beside it, NaN there too), as the CLI's CSV.
    deflate (bool): follow every branch through the equilibria found at the start by deflation
        (as equilibria() lists them, at most deflate_max): branch k starts at the k-th by energy.
    max_seconds (float): wall-clock limit of the whole run (0: none); past it the run stops
        with reason 'time_limit', resumable with state= and resume=True.
    state (str or path, optional): the run's state file (the CLI's OUT.csv.state.json), saved
        at most once per `checkpoint` seconds (0: after every point) and at the end; a resumed
        run recomputes the points after the last save, the same points.
    checkpoint (float): as the CLI's --checkpoint, in seconds.
    resume (bool): go on from the state file `state` of an interrupted run (time_limit, Ctrl-C)
        made with the same case and arguments (another run's state is refused): the Branch
        holds the points after the last one saved, their `index` continuing the run's, so the
        two Branches together are the uninterrupted run's points.
    start_from (str or path, optional): another run's state file: start at its last point
        (its unknowns, active contacts and parameter values, then this case's `set`), as the
        CLI's --start-from. start_param names that run's parameter for files too old to say.
    seed (str): 'guess' (the case's [guess]) or 'ipopt': the first point from Ipopt's minimum of
        the discretised energy, its shape and contact set (as solve(seed='ipopt'); not with
        resume, start_from or deflate). seed_segments, seed_amplitude: as solve()'s.

Returns:
    Branch (points of all branches concatenated, with a `branch` column; `index` is the row of
    the run, as in the CLI's CSV).

Raises:
    CaseError (ValueError): unknown parameter or derived quantity, invalid options.)doc");
}


}  // namespace kirchhoff::python_bindings

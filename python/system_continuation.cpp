// kirchhoff.continue_system(): the continuation engine on any system F(x, lambda) = 0 given as
// Python functions (continuation/parameterised_system.hpp), with the folds, branch points,
// switching and events of a rod's continuation. Argument mapping only: the engine does the work.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "count_argument.hpp"
#include "kirchhoff/continuation/continuation.hpp"

namespace py = pybind11;

namespace kirchhoff {
namespace {

// F and [F_x F_lambda] from Python callables. Exceptions they raise reach the caller unchanged;
// a non-finite or ill-shaped value is a failed evaluation (the step is shortened).
class PythonSystem final : public ParameterisedSystem {
 public:
  PythonSystem(py::function F, py::function J, int n, double lambda0)
      : F_(std::move(F)), J_(std::move(J)), n_(n), lambda0_(lambda0) {}

  int size() const override { return n_; }
  double parameter() const override { return lambda0_; }

  bool residual(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, std::string* failure) override {
    *F = F_(x, lambda).cast<Eigen::VectorXd>();
    if (F->size() != n_) return fail(failure, "F returned " + std::to_string(F->size()) + " values, not " + std::to_string(n_));
    if (!F->allFinite()) return fail(failure, "F is not finite");
    return true;
  }

  bool matrix(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd* F, Eigen::MatrixXd* A, std::string* failure,
              bool) override {
    if (!residual(x, lambda, F, failure)) return false;
    *A = J_(x, lambda).cast<Eigen::MatrixXd>();
    if (A->rows() != n_ || A->cols() != n_ + 1)
      return fail(failure, "J returned a " + std::to_string(A->rows()) + " x " + std::to_string(A->cols()) +
                               " matrix, not " + std::to_string(n_) + " x " + std::to_string(n_ + 1) +
                               " ([F_x F_lambda])");
    if (!A->allFinite()) return fail(failure, "J is not finite");
    return true;
  }

 private:
  static bool fail(std::string* failure, const std::string& why) {
    if (failure) *failure = why;
    return false;
  }

  py::function F_, J_;
  int n_;
  double lambda0_;
};

// Events on components of x: "x0", "x1", ... (the recorder fills them as derived quantities).
PointRecorder component_recorder() {
  PointRecorder recorder;
  recorder.describe = [](ParameterisedSystem&, ContinuationPoint* p) {
    for (int i = 0; i < p->x.size(); ++i) p->derived["x" + std::to_string(i)] = p->x[i];
  };
  return recorder;
}

std::vector<ContinuationEvent> component_events(const py::object& events, int n) {
  std::vector<ContinuationEvent> out;
  if (events.is_none()) return out;
  for (const auto& [key, value] : events.cast<py::dict>()) {
    const std::string name = py::str(key);
    bool known = false;
    for (int i = 0; i < n && !known; ++i) known = name == "x" + std::to_string(i);
    if (!known) throw py::value_error("event '" + name + "': events are on components of x, named x0 .. x" + std::to_string(n - 1));
    out.push_back({name, value.cast<double>(), true, ""});
  }
  return out;
}

py::dict branch_dict(const std::vector<ContinuationPoint>& points, const std::vector<int>& branch, int n) {
  const auto m = static_cast<py::ssize_t>(points.size());
  py::array_t<double> parameter(m), arclength(m), x({m, static_cast<py::ssize_t>(n)});
  py::array_t<int> index(m), branch_of(m), multiplicity(m), iterations(m);
  std::vector<std::string> type, event;
  auto P = parameter.mutable_unchecked<1>();
  auto S = arclength.mutable_unchecked<1>();
  auto X = x.mutable_unchecked<2>();
  auto I = index.mutable_unchecked<1>();
  auto B = branch_of.mutable_unchecked<1>();
  auto M = multiplicity.mutable_unchecked<1>();
  auto N = iterations.mutable_unchecked<1>();
  for (py::ssize_t k = 0; k < m; ++k) {
    const ContinuationPoint& p = points[k];
    P(k) = p.parameter;
    S(k) = p.arclength;
    for (int i = 0; i < n; ++i) X(k, i) = p.x[i];
    I(k) = static_cast<int>(k);
    B(k) = branch[k];
    M(k) = p.multiplicity;
    N(k) = p.newton_iterations;
    type.emplace_back(to_string(p.type));
    event.push_back(p.event);
  }
  py::dict d;
  d["index"] = index;
  d["branch"] = branch_of;
  d["parameter"] = parameter;
  d["arclength"] = arclength;
  d["x"] = x;
  d["type"] = type;
  d["event"] = event;
  d["multiplicity"] = multiplicity;
  d["newton_iterations"] = iterations;
  return d;
}

py::dict continue_system(py::function F, py::function J, const Eigen::VectorXd& x0, double lambda0, py::object to,
                         double step, double min_step, double max_step, python_bindings::Count max_points,
                         double direction, bool branch_points, py::object events,
                         python_bindings::Count switch_at_bp, double side, double tolerance) {
  const int n = static_cast<int>(x0.size());
  if (n == 0) throw py::value_error("x0 is empty");
  if (side != 1.0 && side != -1.0) throw py::value_error("side must be 1 or -1");
  ContinuationOptions o;
  o.parameter = "lambda";
  if (!to.is_none()) {
    o.target = to.cast<double>();
    // (NaN is the options' "no target": given, it is a mistake, as --to nan is.)
    if (!std::isfinite(o.target)) throw py::value_error("to must be a finite number (None: no target)");
  }
  o.initial_step = step;
  o.min_step = min_step;
  o.max_step = max_step;
  o.max_points = max_points;
  o.direction = direction;
  o.detect_branch_points = branch_points || switch_at_bp > 0;
  o.stop_at_branch_point = switch_at_bp;
  o.corrector_tolerance = tolerance;
  o.events = component_events(events, n);
  o.recorder = component_recorder();
  auto make = [&](double lambda) { return std::make_unique<PythonSystem>(F, J, n, lambda); };
  Continuation first(make(lambda0), o);  // throws std::invalid_argument (ValueError) on bad options
  ContinuationResult r = first.run(x0);
  std::vector<ContinuationPoint> points = r.points;
  std::vector<int> branch(points.size(), 0);
  bool switched = false;
  if (switch_at_bp > 0 && r.reason == StopReason::BranchPointStop) {
    const ContinuationPoint bp = r.points.back();
    ContinuationOptions b = o;
    b.target = NAN;
    b.stop_at_branch_point = 0;
    Continuation next(make(bp.parameter), b);
    r = next.switch_branch(bp, {}, side);
    switched = true;
    for (const auto& p : r.points) {
      points.push_back(p);
      branch.push_back(1);
    }
  }
  py::dict out;
  out["reason"] = std::string(to_string(r.reason));
  out["message"] = r.message;
  out["switched"] = switched;
  out["points"] = branch_dict(points, branch, n);
  return out;
}

}  // namespace

void bind_system_continuation(py::module_& m) {
  m.def("continue_system", &continue_system, py::arg("F"), py::arg("J"), py::arg("x0"), py::arg("parameter"),
        py::arg("to") = py::none(), py::kw_only(), py::arg("step") = 0.05, py::arg("min_step") = 1e-7,
        py::arg("max_step") = 0.5, py::arg("max_points") = 500, py::arg("direction") = 1.0,
        py::arg("branch_points").noconvert() = true, py::arg("events") = py::none(), py::arg("switch_at_bp") = 0,
        py::arg("side") = 1.0, py::arg("tolerance") = 1e-10,
        R"doc(Pseudo-arclength continuation of any system F(x, lambda) = 0 (the engine of Case.continue_()).

Args:
    F (callable): F(x, lam) -> n values (x a numpy array of n, lam a float).
    J (callable): J(x, lam) -> the n x (n + 1) matrix [F_x F_lambda].
    x0 (array of n): the start's unknowns, corrected by Newton at lambda = parameter first.
    parameter (float): lambda at the start.
    to (float, optional): stop on reaching this lambda (None: go along `direction`).
    step, min_step, max_step (float): initial, smallest and largest pseudo-arclength step.
    max_points (int): points per branch.
    direction (float): +1 / -1, initial direction of lambda when there is no target.
    branch_points (bool): look for branch points (folds are found either way).
    events (dict "x<i>" -> value): stop where component i of x crosses the value.
    switch_at_bp (int): > 0: stop at that branch point and follow the branch crossing there.
    side (float): +1 / -1, which way along the crossing branch.
    tolerance (float): the corrector's tolerance on max |F|.

Returns:
    dict: reason (the stop reason of the last run, as Branch.reason), message, switched (bool),
    points (dict of numpy arrays: index, branch (0, 1 after a switch), parameter, arclength,
    x (points x n), multiplicity, newton_iterations; lists type and event).

Raises:
    ValueError: invalid options or events; exceptions raised by F or J pass through.)doc");
}

}  // namespace kirchhoff

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

#include "bindings.hpp"

PYBIND11_MODULE(kirchhoff, m) {
  using namespace kirchhoff;
  using namespace kirchhoff::python_bindings;
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

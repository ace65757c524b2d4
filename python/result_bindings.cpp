// kirchhoff.Solution and kirchhoff.Branch: what a solve and a continuation return.
#include "bindings.hpp"

namespace kirchhoff::python_bindings {
namespace {

std::string repr_solution(const PySolution& s) {
  std::ostringstream o;
  o.precision(10);
  o << "<kirchhoff.Solution status=" << s.status << " iterations=" << s.iterations << " residual=" << s.residual;
  for (const auto& [k, v] : s.derived) o << " " << py::str(k).cast<std::string>() << "=" << v.cast<double>();
  o << ">";
  return o.str();
}

}  // namespace

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
    notes (list of str): the run's notes, as the CLI prints them: how the branch started (where
        Newton from the guess failed and it started from solve's equilibrium, reached by
        homotopy), the self-contact guard, a seed, a branch switch.
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
      .def_readonly("notes", &PyBranch::notes)
      .def_readonly("points", &PyBranch::points)
      .def("__len__", [](const PyBranch& b) { return b.size; })
      .def("__repr__", [](const PyBranch& b) {
        return "<kirchhoff.Branch " + b.parameter + ": " + std::to_string(b.size) + " points, reason=" + b.reason +
               (b.message.empty() ? "" : " (" + b.message + ")") + ">";
      });
}

}  // namespace kirchhoff::python_bindings

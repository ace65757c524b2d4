#!/usr/bin/env python3
"""Tests of the `kirchhoff` Python module (python/kirchhoff_module.cpp and its parts).

Run by ctest (python_bindings) with PYTHONPATH=<build>/python and KIRCHHOFF_CASES_DIR=<source>/cases;
by hand:
    PYTHONPATH=build/python KIRCHHOFF_CASES_DIR=cases /usr/bin/python3 tests/python_bindings_test.py -v
"""
import contextlib
import json
import math
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import threading
import _thread
import unittest

import numpy as np

import kirchhoff

CASES = pathlib.Path(os.environ.get("KIRCHHOFF_CASES_DIR", pathlib.Path(__file__).resolve().parent.parent / "cases"))

PROFILE_KEYS = {"s", "x", "y", "z", "theta", "nx", "ny", "nz", "mx", "my", "mz", "u1", "u2", "u3", "H", "m3"}


@contextlib.contextmanager
def captured_stderr():
    """What the library writes on file descriptor 2 inside the block, in .text after it."""
    holder = type("Captured", (), {"text": ""})()
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+") as f:
        os.dup2(f.fileno(), 2)
        try:
            yield holder
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            f.seek(0)
            holder.text = f.read()


def case_path(name):
    return str(CASES / name)


class AnalyticTest(unittest.TestCase):
    def test_pinned_load_matches_gsl_value(self):
        # P = 4 K(k)^2 EI / L^2 with k = sin(1/2), K from GSL.
        self.assertAlmostEqual(kirchhoff.analytic_pinned_load(1.0, 1.0, 1.0), 11.22241847578908, places=12)

    def test_pinned_load_rejects_bad_arguments(self):
        with self.assertRaises(ValueError):
            kirchhoff.analytic_pinned_load(1.0, 1.0, 4.0)


class HomotopyTest(unittest.TestCase):
    def test_set_values_are_reached_along_the_cases_branch(self):
        # Fig. 3 at theta0 = 3.1: P = 4 K(k)^2 EI / L^2; Newton from the guess lands elsewhere.
        case = kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": 3.1})
        sol = case.solve()
        self.assertEqual(sol.status, "converged")
        exact = kirchhoff.analytic_pinned_load(1.0, 1.0, 3.1)
        self.assertLess(abs(sol.parameters["P"] / exact - 1.0), 1e-9)  # as tests/homotopy_test.cpp
        self.assertEqual(sol.path["method"], "homotopy")
        self.assertEqual(sol.path["from"], {"theta0": 1.0})
        np.testing.assert_array_equal(sol.profile["kappa"], sol.profile["u2"])  # planar: kappa named
        self.assertEqual(sol.path["stop"], "reached")
        self.assertEqual(len(sol.path["branch_points"]), 1)  # where the supports meet
        self.assertAlmostEqual(sol.path["branch_points"][0]["theta0"], 2.2814, delta=2e-3)
        direct = case.solve(direct=True)
        self.assertEqual(direct.path["method"], "direct")
        self.assertGreater(abs(direct.parameters["P"] / exact - 1.0), 1e-3)

    def test_values_far_above_the_files_are_reached_in_tens_of_points(self):
        # Fig. 3 in units far from 1 (EI = 2e4, L = 3 from 1 and 1): P = 4 K(k)^2 EI / L^2 = 3.9e4.
        # The path's steps grow with its unknowns (as tests/homotopy_test.cpp; measured 73 points).
        sol = kirchhoff.load_case(case_path("simply_supported.toml"),
                                  set={"EI": 2e4, "L": 3.0, "theta0": 2.0}).solve()
        self.assertEqual(sol.status, "converged", sol.message)
        exact = kirchhoff.analytic_pinned_load(3.0, 2e4, 2.0)
        self.assertLess(abs(sol.parameters["P"] / exact - 1.0), 1e-9)
        self.assertEqual(sol.path["stop"], "reached")
        self.assertLess(sol.path["points"], 500)

    def test_a_fold_on_the_way_is_a_status_with_where(self):
        sol = kirchhoff.load_case(case_path("shallow_arch.toml"), set={"w": 150.0}).solve()
        self.assertFalse(sol.converged)
        self.assertEqual(sol.status, "fold")
        self.assertIn("fold at w = ", sol.message)
        self.assertLess(sol.path["reached"]["w"], 150.0)
        self.assertEqual(sol.derived, {})


class LoadCaseTest(unittest.TestCase):
    def test_case_attributes(self):
        case = kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": 2.0})
        self.assertIn("Simply supported", case.title)
        self.assertEqual(case.parameters["theta0"], 2.0)
        self.assertEqual(case.parameters["L"], 1.0)
        self.assertEqual(case.derived_names, ["P", "y_max", "kappa_max", "end_to_end"])
        self.assertEqual(case.unknowns, ["P"])
        self.assertEqual(case.kind, "planar")

    def test_unknown_parameter_raises_value_error_naming_it(self):
        with self.assertRaises(ValueError) as cm:
            kirchhoff.load_case(case_path("simply_supported.toml"), set={"no_such_key": 1.0})
        self.assertIn("no_such_key", str(cm.exception))
        self.assertIsInstance(cm.exception, kirchhoff.CaseError)
        # The CLI's message.
        self.assertIn("--set no_such_key: no parameter 'no_such_key' in [parameters]", str(cm.exception))

    def test_non_finite_parameter_is_refused_in_the_clis_words(self):
        # tests/cli_test.cpp (NonFiniteOverrideExitsTwo) expects the same text from `--set theta0=nan`.
        with self.assertRaises(kirchhoff.CaseError) as cm:
            kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": math.nan})
        self.assertIn("simply_supported.toml: --set theta0: nan is not a finite number with magnitude <= 1e+100",
                      str(cm.exception))

    def test_bad_key_in_file_raises_value_error_naming_it(self):
        text = pathlib.Path(case_path("simply_supported.toml")).read_text()
        text = text.replace("[solver]\n", "[solver]\nbogus_setting = 3\n")
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "bad.toml"
            path.write_text(text)
            with self.assertRaises(ValueError) as cm:
                kirchhoff.load_case(str(path))
        self.assertIn("bogus_setting", str(cm.exception))

    def test_value_that_is_no_number_is_refused_by_name(self):
        with self.assertRaises(kirchhoff.CaseError) as cm:
            kirchhoff.load_case(case_path("wall.toml"), set={"Delta": "abc"})
        self.assertIn("'abc' given for 'Delta' is not a number", str(cm.exception))

    def test_a_bool_is_no_number(self):
        # pybind11 would read True as 1.0; the CLI has no such value (a probe's).
        with self.assertRaises(kirchhoff.CaseError) as cm:
            kirchhoff.load_case(case_path("euler_column.toml"), set={"P": True})
        self.assertIn("euler_column.toml: set: 'True' given for 'P' is not a number", str(cm.exception))

    def test_a_phase_condition_that_is_none_of_them_is_refused_without_a_line(self):
        with self.assertRaises(kirchhoff.CaseError) as cm:
            kirchhoff.load_case(case_path("euler_column.toml"), phase_condition="bogus")
        self.assertIn("euler_column.toml: --phase-condition (Python: phase_condition): 'bogus'", str(cm.exception))

    def test_a_direction_away_from_the_target_is_refused(self):
        case = kirchhoff.load_case(case_path("euler_column.toml"))
        with self.assertRaisesRegex(kirchhoff.CaseError, "points away from --to"):
            case.continue_("P", to=20.0, direction=-1)
        down = case.continue_("P", None, direction=-1, max_points=3)
        self.assertLess(down.points["parameter"][-1], 12.0)

    def test_target_at_the_starting_value_is_refused(self):
        # tests/cli_test.cpp (TargetAtTheStartingValueIsRefused) expects the same text.
        case = kirchhoff.load_case(case_path("euler_column.toml"))
        with self.assertRaises(kirchhoff.CaseError) as cm:
            case.continue_("P", to=12)
        self.assertIn("--to 12 is P's starting value: nothing to continue", str(cm.exception))

    def test_target_that_is_not_a_finite_number_is_refused(self):
        # tests/cli_test.cpp (TargetThatIsNotAFiniteNumberIsRefused) expects the same text.
        case = kirchhoff.load_case(case_path("euler_column.toml"))
        for to in (float("nan"), float("inf"), 1e300):
            with self.assertRaises(kirchhoff.CaseError) as cm:
                case.continue_("P", to=to, max_points=5)
            self.assertIn("--to must be a finite number within +-1e100", str(cm.exception))

    def test_side_that_is_not_one_or_minus_one_is_refused(self):
        # tests/cli_test.cpp (SideThatIsNotOneOrMinusOneIsRefused) expects the same text.
        case = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": 1.0})
        for side in (0.0, 2.0, float("nan")):
            with self.assertRaises(kirchhoff.CaseError) as cm:
                case.continue_("P", to=12.0, switch_at_bp=1, side=side, max_points=5)
            self.assertIn("--side must be 1 or -1", str(cm.exception))
        with self.assertRaises(ValueError):
            kirchhoff.continue_system(lambda x, lam: [x[0] * (lam - x[0] ** 2)], lambda x, lam: [[lam - 3 * x[0] ** 2, x[0]]],
                                      [0.1], -1.0, to=1.0, switch_at_bp=1, side=0.0)

    def test_missing_file_raises_value_error(self):
        with self.assertRaises(ValueError):
            kirchhoff.load_case(case_path("does_not_exist.toml"))


class CaseOptionsTest(unittest.TestCase):
    """Computed parameters and solver settings, as the CLI's --set and --solver take them."""

    def test_solver_overrides_are_checked_as_in_the_file(self):
        case = kirchhoff.load_case(case_path("simply_supported.toml"),
                                   solver={"stepper": "dopri5", "tolerance": 1e-11, "unknowns": ["P"]})
        sol = case.solve()
        self.assertTrue(sol.converged, sol.message)
        self.assertLess(sol.residual, 1e-11)
        # Love's P for theta0 = 1 (eq. 54); the 1e-11 residual and the 1e-12 integrator leave ~1e-10
        self.assertAlmostEqual(sol.derived["P"], 11.2224184758, delta=1e-8)
        with self.assertRaises(kirchhoff.CaseError) as cm:
            kirchhoff.load_case(case_path("simply_supported.toml"), solver={"tolerance": 1})
        self.assertIn("--solver tolerance=1: key 'solver.tolerance': must be in (0, 0.01]", str(cm.exception))
        with self.assertRaises(kirchhoff.CaseError) as cm:
            kirchhoff.load_case(case_path("simply_supported.toml"), solver={"stepper": "rk4"})
        self.assertIn("'rk4' is not 'rk78' or 'dopri5'", str(cm.exception))

    def test_closed_form_and_march_give_the_same_elastica(self):
        # The Elastica of Fig. 3 at theta0 = 2.8 flows in closed form by default (no right-hand
        # sides); marched, the same rod to the march's accuracy (P to 1e-9 of itself, the residual
        # 1e-10 and the integrator's 1e-12 amplified by the shooting's conditioning there).
        closed = kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": 2.8}).solve()
        marched = kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": 2.8},
                                      solver={"closed_form": False}).solve()
        self.assertTrue(closed.converged, closed.message)
        self.assertTrue(marched.converged, marched.message)
        self.assertAlmostEqual(closed.derived["P"] / marched.derived["P"], 1.0, delta=1e-9)
        with self.assertRaises(kirchhoff.CaseError):
            kirchhoff.load_case(case_path("simply_supported.toml"), solver={"closed_form": "yes"})

    def test_computed_parameter_follows_its_inputs(self):
        text = pathlib.Path(case_path("simply_supported.toml")).read_text()
        self.assertIn("\nEI = 1.0", text)
        text = text.replace("\nEI = 1.0", '\nr = 0.5\nEI = "pi*r^2"')
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "computed.toml"
            path.write_text(text)
            case = kirchhoff.load_case(str(path), set={"r": 0.6})
            self.assertAlmostEqual(case.parameters["EI"], math.pi * 0.36, places=14)
            sol = case.solve()
            self.assertTrue(sol.converged, sol.message)
            self.assertAlmostEqual(sol.parameters["EI"], math.pi * 0.36, places=14)
            P = kirchhoff.analytic_pinned_load(1.0, math.pi * 0.36, 1.0)
            self.assertLess(abs(sol.derived["P"] - P), 1e-8 * P)
            with self.assertRaises(kirchhoff.CaseError) as cm:
                kirchhoff.load_case(str(path), set={"EI": 2.0})
            self.assertIn("EI is computed from r", str(cm.exception))
            self.assertIn("set r instead", str(cm.exception))
            with self.assertRaises(kirchhoff.CaseError) as cm:
                case.continue_("EI", to=2.0)
            self.assertIn("--param EI: EI is computed from r", str(cm.exception))
            self.assertIn("continue in r instead", str(cm.exception))


class SolveTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.case = kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": 1.0})
        cls.solution = cls.case.solve(samples=201)

    def test_converges_to_the_elliptic_load(self):
        sol = self.solution
        self.assertEqual(sol.status, "converged")
        self.assertTrue(sol.converged)
        self.assertTrue(sol)
        self.assertGreater(sol.iterations, 0)
        self.assertLess(sol.residual, 1e-9)
        P = kirchhoff.analytic_pinned_load(1.0, 1.0, 1.0)
        self.assertAlmostEqual(P, 11.22241847578908, places=12)
        self.assertLess(abs(sol.derived["P"] - P), 1e-8 * P)
        self.assertLess(abs(sol.parameters["P"] - P), 1e-8 * P)
        self.assertEqual(set(sol.derived), set(self.case.derived_names))

    def test_stability(self):
        # Fig. 3's Elastica under imposed end shortening (P is the multiplier of the chord): stable.
        st = self.solution.stability
        self.assertEqual(st["index"], 0)
        self.assertTrue(st["stable"])
        self.assertEqual(st["zero_modes"], 0)
        self.assertEqual(st["method"], "conjugate_points")
        straight = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": 50.0, "theta_guess": 0.0}).solve()
        self.assertEqual(straight.stability["index"], 2)  # pi^2 and 4 pi^2 below P = 50
        self.assertTrue(straight.stability["cross_check"]["agrees"])
        # pi^2 - P to the 400-element discretisation's O(h^2) error (pi^4 h^2 / 12 = 5e-5)
        self.assertAlmostEqual(straight.stability["lowest_eigenvalues"][0], np.pi ** 2 - 50.0, places=3)
        # A sliding length: the discretised energy covers it, with ell among its unknowns; its
        # d2E*/dell2 is S to the 400-element O(h^2) error (measured 0.029 of S = -565.5).
        sleeve = kirchhoff.load_case(case_path("sleeve.toml")).solve().stability
        self.assertEqual(sleeve["index"], 1)
        self.assertEqual(sleeve["cross_check"]["index"], 1)
        self.assertTrue(sleeve["cross_check"]["agrees"])
        self.assertLess(abs(sleeve["cross_check"]["reduced_energy_curvature"] - sleeve["reduced_energy_curvature"]),
                        1e-4 * abs(sleeve["reduced_energy_curvature"]))
        couple = kirchhoff.load_case(case_path("reissner.toml")).solve()  # a dead couple on a 3D end
        self.assertIsNone(couple.stability["index"])
        self.assertIsNone(couple.stability["zero_modes"])
        self.assertIn("not conservative", couple.stability["reason"])

    def test_michells_ring_turns_unstable_at_michells_twist(self):
        # A twisted ring is stable while C tau R < sqrt(3) B (Michell), then two modes at once; the
        # ring's turn about its tangent at the weld is a zero mode throughout. Here R = 1.2, C = B:
        # the branch point at sqrt(3) / 1.2 to the continuation's location (1e-10; 1e-8 allowed).
        def ring(tau):
            return kirchhoff.load_case(case_path("michell_ring.toml"), set={"R": 1.2, "C": 1.0, "tau": tau})
        tau_c = np.sqrt(3.0) / 1.2
        below = ring(0.97 * tau_c).solve().stability
        above = ring(1.03 * tau_c).solve().stability
        self.assertEqual((below["index"], below["zero_modes"]), (0, 1))
        self.assertEqual((above["index"], above["zero_modes"]), (2, 1))
        branch = ring(0.5).continue_("tau", to=1.8, max_step=0.2)
        self.assertEqual(branch.reason, "reached_target")
        at = [t for t, kind in zip(branch.points["parameter"], branch.points["type"]) if kind == "branch_point"]
        self.assertEqual(len(at), 1)
        self.assertLess(abs(at[0] - tau_c), 1e-8)

    def test_the_discretised_energy_decides_where_the_conjugate_points_do_not(self):
        # A pinned column on a stiff Winkler foundation (k = 1e6: a soft wall balanced by a uniform
        # weight towards it): the conjugate points call its held end degenerate, the discretised
        # energy passes its own tests and finds it stable, (10 pi)^2 + k / (10 pi)^2 - P = 800.2 to
        # its O(h^2) error at 400 elements (measured 1.55; cli_test has the same case).
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "foundation.toml")
            with open(path, "w") as f:
                f.write('model = "planar"\n[parameters]\nP = 1200.0\nk = 1e6\nb = "k/2"\n'
                        '[rod]\nlength = 1.0\nB = 1.0\nbarrier = { b = "b", a = 1.0, normal = [0, 1, 0] }\n'
                        'gravity = { weight = "b", up = [0, -1, 0] }\n'
                        '[start]\ntype = "pinned"\nposition = [0, 0]\n'
                        '[end]\ntype = "sliding"\naxis = [1, 0, 0]\nposition = [0, 0]\nforce = ["-P", 0]\n'
                        '[guess]\nforce = ["-P", 0]\n')
            case = kirchhoff.load_case(path)
            st = case.solve(direct=True).stability
            # A branch's points likewise (their stability_index was NaN): stable up to P_10.
            branch = case.continue_("P", to=1900.0, max_step=20.0)
        self.assertEqual(branch.reason, "reached_target")
        self.assertGreater(len(branch.points["stability_index"]), 20)
        self.assertTrue(all(i == 0 for i in branch.points["stability_index"]))
        self.assertEqual(st["index"], 0)
        self.assertTrue(st["stable"])
        self.assertEqual(st["method"], "discretised_energy")
        self.assertIn("degenerate constraint", st["method_reason"])
        self.assertIsNone(st["cross_check"]["agrees"])
        self.assertLess(abs(st["lowest_eigenvalues"][0] - ((10 * np.pi) ** 2 + 1e6 / (10 * np.pi) ** 2 - 1200.0)), 5.0)

    def test_profile_arrays(self):
        profile = self.solution.profile
        self.assertEqual(set(profile), PROFILE_KEYS | {"kappa"})  # a planar rod: its curvature named too
        for name, values in profile.items():
            self.assertIsInstance(values, np.ndarray, name)
            self.assertEqual(values.shape, (201,), name)
            self.assertTrue(np.all(np.isfinite(values)), name)
        self.assertAlmostEqual(profile["s"][0], 0.0)
        self.assertAlmostEqual(profile["s"][-1], 1.0)
        self.assertAlmostEqual(profile["theta"][0], 1.0, places=9)  # imposed end slope
        self.assertEqual(len(self.case.solve(samples=11).profile["x"]), 11)

    def test_hamiltonian_is_flat(self):
        H = self.solution.profile["H"]
        self.assertLess(np.ptp(H), 1e-9 * abs(H.mean()))
        # Planar Elastica: H = -P cos(theta0).
        P = kirchhoff.analytic_pinned_load(1.0, 1.0, 1.0)
        self.assertAlmostEqual(H.mean(), -P * math.cos(1.0), places=8)

    def test_invariants_like_the_cli_json(self):
        inv = self.solution.invariants
        for name in ("H", "m3", "n_dot_m"):
            self.assertEqual(set(inv[name]), {"mean", "min", "max", "spread", "relative_spread", "applies"}, name)
        self.assertTrue(inv["H"]["applies"])
        self.assertLess(inv["H"]["relative_spread"], 1e-9)
        self.assertAlmostEqual(inv["H"]["mean"], self.solution.profile["H"].mean(), places=12)

    def test_bad_sample_count_raises_value_error(self):
        with self.assertRaises(ValueError):
            self.case.solve(samples=1)

    def test_non_convergence_is_a_status(self):
        text = pathlib.Path(case_path("simply_supported.toml")).read_text()
        self.assertIn("[solver]\n", text)
        text = text.replace("[solver]\n", "[solver]\nmax_iterations = 1\nfallback_search = false\n")
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "one_iteration.toml"
            path.write_text(text)
            case = kirchhoff.load_case(str(path), set={"theta0": 2.5})
        sol = case.solve()  # must not raise
        self.assertNotEqual(sol.status, "converged")
        self.assertFalse(sol.converged)
        self.assertFalse(sol)
        self.assertEqual(sol.derived, {})
        self.assertEqual(sol.profile, {})
        self.assertEqual(sol.parameters["theta0"], 2.5)
        # Why, as the CLI's JSON says it (Newton gave no message of its own: out of iterations).
        self.assertIn("after 1 iterations, residual", sol.message)


class CheckedResultTest(unittest.TestCase):
    """What the CLI refuses to call converged, Python does not either (docs/reliability.md)."""

    def test_dopri5_gives_the_elastica(self):
        text = pathlib.Path(case_path("simply_supported.toml")).read_text()
        # (Marched: the Elastica's closed-form flow would take no steps of either stepper.)
        text = text.replace("[solver]\n", "[solver]\nstepper = \"dopri5\"\nclosed_form = false\n")
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "dopri5.toml"
            path.write_text(text)
            sol = kirchhoff.load_case(str(path)).solve()
        self.assertTrue(sol.converged, sol.message)
        # Love's P for theta0 = 1 (eq. 54); the residual and the 1e-12 integrator leave ~1e-10
        self.assertAlmostEqual(sol.derived["P"], 11.2224184758, delta=1e-8)
        self.assertTrue(all(np.isfinite(sol.profile["nx"])))

    def test_rod_beyond_its_soft_wall_is_check_failed(self):
        # Directly, Newton converges beyond the wall and the check refuses it (by homotopy the
        # path stalls as the wall stiffens: step_too_small, not converged either).
        sol = kirchhoff.load_case(case_path("soft_wall.toml"), set={"log_b": -20}).solve(direct=True)
        self.assertFalse(sol.converged)
        self.assertEqual(sol.status, "check_failed")
        self.assertIn("soft wall", sol.message)
        self.assertEqual(sol.derived, {})

    def test_stated_contact_that_moved_says_where(self):
        # wrapped_indenter.toml states its wrap over [0.45, 0.55]; it converges over the closed
        # form's interval, and the solution says where the stated contact went.
        sol = kirchhoff.load_case(case_path("wrapped_indenter.toml")).solve()
        self.assertTrue(sol.converged, sol.message)
        [stated] = sol.stated_contacts
        self.assertTrue(stated["moved"])
        self.assertFalse(stated["released"])
        self.assertEqual(stated["stated_s"], 0.45)
        self.assertAlmostEqual(stated["s"], sol.contacts[0]["s"], places=12)
        self.assertIn("stated over [0.45, 0.55] converged over [0.377472, 0.622528]", stated["message"])

    def test_flat_contact_found_as_two_point_contacts_is_extended(self):
        # wall.toml at Delta = 0.032 as the file's own value: the active-set loop from the free arch
        # settles on two point contacts with the rod flat on the wall between them, which the
        # solution reports as the one extended contact it is (H = -P on it, section 7.2).
        text = pathlib.Path(case_path("wall.toml")).read_text().replace("Delta = 0.026", "Delta = 0.032")
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "wall_flat.toml")
            pathlib.Path(path).write_text(text)
            sol = kirchhoff.load_case(path).solve()
        self.assertTrue(sol.converged, sol.message)
        [flat] = sol.contacts
        self.assertTrue(flat["extended"])
        self.assertAlmostEqual(sol.derived["contact_length"], flat["s_end"] - flat["s"], places=12)
        self.assertGreater(sol.derived["contact_length"], 0.03)
        self.assertAlmostEqual(sol.derived["H"] / -sol.derived["P"], 1.0, places=9)

    def test_whole_turns_away_is_check_failed(self):
        # Directly from the untwisted guess: Newton converges two turns away and the check refuses it.
        sol = kirchhoff.load_case(case_path("plectoneme.toml"), set={"turns": 2}).solve(direct=True)
        self.assertEqual(sol.status, "check_failed")
        self.assertIn("whole turns", sol.message)

    def test_counts_refuse_bools_and_floats(self):
        # bool is an int in Python: max_points=True used to run one point, samples=True asked
        # for 1 sample. Counts are ints (numpy's too); a bool or a float is a TypeError.
        case = kirchhoff.load_case(case_path("simply_supported.toml"))
        for bad in ({"max_points": True}, {"max_points": 3.5}, {"samples": False}, {"switch_at_bp": True}):
            with self.assertRaises(TypeError, msg=str(bad)):
                case.continue_(param="theta0", to=1.2, **bad)
        with self.assertRaises(TypeError):
            case.solve(samples=True)
        with self.assertRaises(TypeError):
            case.vibrate(modes=True)
        with self.assertRaises(TypeError):
            case.equilibria(max=True)
        branch = case.continue_(param="theta0", to=1.2, max_points=np.int64(5))
        self.assertEqual(len(branch.points["parameter"]), 5)
        self.assertEqual(branch.reason, "max_points")

    def test_max_seconds_ends_the_solve(self):
        # As the CLI's test: Newton from the guess at theta0 = 1e6 with the flows marched takes
        # ~3.4 s without a limit. (The homotopy there now stops sooner, its step too small near
        # theta0 = pi, since its steps grow with its unknowns.)
        case = kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": 1e6},
                                   solver={"closed_form": False})
        sol = case.solve(max_seconds=0.5, direct=True)
        self.assertEqual(sol.status, "time_limit")
        with self.assertRaises(ValueError):
            case.solve(max_seconds=-1)


class ContactTest(unittest.TestCase):
    def test_wall_contact_like_the_cli(self):
        sol = kirchhoff.load_case(case_path("wall.toml")).solve()
        self.assertEqual(sol.status, "converged")
        self.assertEqual(len(sol.contacts), 1)
        # The elliptic-function value (tests/contact_test.cpp): F_c = 18.2038121699.
        self.assertAlmostEqual(sol.contacts[0]["force"], 18.2038121699, places=8)
        self.assertAlmostEqual(sol.contacts[0]["s"], 0.5, places=9)
        self.assertEqual(sol.contacts[0]["obstacle_name"], "wall")
        self.assertFalse(sol.contacts[0]["extended"])
        self.assertAlmostEqual(sol.contacts[0]["H_before"] / sol.contacts[0]["H_after"], 1.0, places=9)
        self.assertGreaterEqual(sol.derived["min_gap"], -1e-10)

    def test_ipopt_seed_reaches_what_the_guess_cannot(self):
        case = kirchhoff.load_case(case_path("cavity.toml"), set={"Delta": 0.05})
        self.assertFalse(case.solve(direct=True).converged)  # Newton from the free-arch guess
        sol = case.solve(seed="ipopt")
        self.assertEqual(sol.status, "converged")
        self.assertEqual(len(sol.contacts), 1)
        self.assertGreater(sol.contacts[0]["force"], 0.0)
        self.assertGreaterEqual(sol.derived["min_gap"], -1e-10)
        with self.assertRaisesRegex(ValueError, "seed must be"):
            case.solve(seed="ipop")
        # The side Ipopt's first mode starts on, as the CLI's --seed-amplitude picks it.
        clamped = kirchhoff.load_case(case_path("clamped_clamped.toml"))
        up, down = (clamped.solve(seed="ipopt", seed_amplitude=a, samples=101) for a in (0.05, -0.05))
        self.assertAlmostEqual(up.profile["y"][50], 0.19492431, places=7)
        self.assertAlmostEqual(down.profile["y"][50], -up.profile["y"][50], places=10)
        branch = clamped.continue_("D", to=0.85, seed="ipopt", seed_amplitude=-0.05, max_points=20)
        self.assertEqual(branch.reason, "reached_target")
        self.assertTrue(any("Ipopt" in n for n in branch.notes), branch.notes)
        with self.assertRaisesRegex(ValueError, "neither clamped nor pinned"):  # a roller
            kirchhoff.load_case(case_path("indenter.toml")).solve(seed="ipopt")

    def test_the_first_point_without_an_index_is_noted_with_why(self):
        b = kirchhoff.load_case(case_path("reissner.toml")).continue_("F", to=2.5)
        undefined = [n for n in b.notes if "stability index undefined" in n]
        self.assertEqual(len(undefined), 1, b.notes)
        self.assertIn("not conservative", undefined[0])

    def test_infeasible_wall_is_a_status(self):
        case = kirchhoff.load_case(case_path("wall.toml"), set={"a": -0.01})
        sol = case.solve(direct=True)
        self.assertFalse(sol.converged)
        # The CLI's status word and message (one library solve for both front ends).
        self.assertEqual(sol.status, "infeasible")
        self.assertIn("inside obstacle 'wall'", sol.message)
        self.assertEqual(sol.iterations, 0)
        self.assertEqual(sol.path["method"], "direct")
        # By homotopy too, at once: the requested values are checked before the path starts (it
        # brought the wall down onto the arch until the branch turned back, and reported that fold).
        sol = case.solve()
        self.assertFalse(sol.converged)
        self.assertEqual(sol.status, "infeasible")
        self.assertIn("inside obstacle 'wall'", sol.message)
        self.assertEqual(sol.path["method"], "homotopy")

    def test_continuation_records_the_first_contact(self):
        branch = kirchhoff.load_case(case_path("wall.toml"), set={"Delta": 0.005, "m_guess": 0.9}).continue_(
            "Delta", to=0.026, max_step=2.0)
        self.assertEqual(branch.reason, "reached_target")
        events = [e for e in branch.points["event"] if e]
        self.assertEqual(len(events), 1)
        # The event's name, as the CLI's CSV has it; what changed, as the CLI's "contact:" lines.
        self.assertEqual(events[0], "obstacle_reached")
        self.assertEqual(len(branch.contact_changes), 1)
        self.assertIn("a contact appears", branch.contact_changes[0])

    def test_switch_at_a_branch_point_of_a_case_with_obstacles(self):
        # The Euler column below a wall at y = 0.2 (as tests/continue_cli_test.cpp): the buckled
        # branch leaves the straight one at P = pi^2 and reaches the wall on the way to P = 40.
        with open(case_path("euler_column.toml")) as f:
            text = f.read().replace("[output]", '[[obstacles]]\ntype = "plane"\npoint = [0, 0.2]\n'
                                    'normal = [0, -1, 0]\n\n[output]')
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "column_wall.toml"
            path.write_text(text)
            case = kirchhoff.load_case(str(path), set={"P": 1.0, "theta_guess": 0.0})
            b = case.continue_("P", to=12.0, switch_at_bp=1, events={"P": 40.0}, max_step=0.5)
        self.assertTrue(b.switched, b.message)
        self.assertEqual(b.reason, "event", b.message)
        types, branches = b.points["type"], b.points["branch"]
        first_bp = list(types).index("branch_point")
        self.assertAlmostEqual(b.points["parameter"][first_bp], np.pi ** 2, places=9)
        self.assertEqual(branches[first_bp + 1], 1)
        contacts = [k for k, e in enumerate(b.points["event"]) if e == "obstacle_reached"]
        self.assertIn("a contact appears", " ".join(b.contact_changes))
        self.assertEqual(len(contacts), 1)
        self.assertEqual(branches[contacts[0]], 1)
        self.assertAlmostEqual(b.points["y_max"][contacts[0]], 0.2, places=8)

    def test_switch_at_a_disc_contacts_pitchfork_onto_the_asymmetric_contacts(self):
        # wall.toml with a disc of radius 0.5 for its wall (as tests/continue_cli_test.cpp): the
        # symmetric contact at s = 0.5 loses stability at Delta = 0.0271376 to asymmetric ones,
        # mirror images (s, 1 - s) on the two sides, stable. The switch went back along the
        # symmetric contact.
        with open(case_path("wall.toml")) as f:
            text = f.read().replace('type = "plane"', 'type = "cylinder"').replace(
                'point = [0, "a"]', 'centre = ["(L - Delta)/2", "a + 0.5"]\nradius = 0.5').replace(
                'normal = [0, -1, 0]', '')
        with tempfile.TemporaryDirectory() as tmp:
            path = pathlib.Path(tmp) / "arch_disc.toml"
            path.write_text(text)
            case = kirchhoff.load_case(str(path))
            sides = [case.continue_("Delta", to=0.029, switch_at_bp=1, side=side, max_points=80) for side in (1, -1)]
        last_s = []
        for b in sides:
            self.assertTrue(b.switched, b.message)
            on = (b.points["branch"] == 1) & (np.array(b.points["type"]) == "regular")
            self.assertTrue(all(k == 0 for k in b.points["stability_index"][on]))
            last_s.append(b.points["contact_s"][on][-1])
        self.assertGreater(last_s[0], 0.6)
        self.assertLess(last_s[1], 0.4)


class ContinuationTest(unittest.TestCase):
    """The Euler column from P = 1 along the straight branch, switching at the first branch point
    onto the buckled one, which is followed until theta0 = 3 (as tests/continue_cli_test.cpp)."""

    @classmethod
    def setUpClass(cls):
        case = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": 1.0, "theta_guess": 0.0})
        cls.branch = case.continue_("P", to=12.0, switch_at_bp=1, events={"theta0": 3.0})

    def test_stops_at_the_event_after_switching(self):
        b = self.branch
        self.assertEqual(b.reason, "event", b.message)
        self.assertTrue(b.switched)
        self.assertTrue(b.ok)
        self.assertEqual(b.parameter, "P")
        last_type = b.points["type"][-1]
        self.assertEqual(last_type, "event")
        self.assertTrue(re.match(r"theta0=3", b.points["event"][-1]))
        self.assertAlmostEqual(b.points["theta0"][-1], 3.0, places=8)
        self.assertEqual(b.points["branch"][-1], 1)

    def test_stability_index_column(self):
        # Straight and stable below pi^2, buckled and stable until the ends meet (theta0 = 2.28),
        # index 1 past it; NaN never appears on this planar branch (the index is defined).
        pts = self.branch.points
        idx = pts["stability_index"]
        self.assertFalse(np.any(np.isnan(idx)))
        regular = np.array([t == "regular" for t in pts["type"]])
        theta0 = np.abs(pts["theta0"])
        self.assertTrue(np.all(idx[regular & (pts["branch"] == 0)] == 0))
        self.assertTrue(np.all(idx[regular & (pts["branch"] == 1) & (theta0 < 2.27)] == 0))
        self.assertTrue(np.all(idx[regular & (pts["branch"] == 1) & (theta0 > 2.29)] == 1))
        self.assertGreaterEqual(int(pts["zero_modes"][[t == "branch_point" for t in pts["type"]]].min()), 1)

    def test_index_change_rows_of_a_half_rod(self):
        # The half of an anisotropic rod clamped at both ends and turned (plectoneme.toml's
        # symmetry, no self-contact): the whole rod bifurcates off the symmetric branch at turns
        # 0.57322 and 0.86154 (its determinant at fixed turns), which the half's Jacobian cannot
        # see; its index (both halves' perturbations) changes there, and the branch has a row at
        # each, located to ~1e-5 (the index's resolution there; tests/continue_cli_test.cpp).
        text = "\n".join([
            'model = "spatial"', "[parameters]", "turns = 0.0",
            "[rod]", "length = 0.5", "B1 = 1.5", "B2 = 1.0", "B3 = 0.769230769230769",
            "[start]", 'type = "clamped"', "position = [0, 0, -0.25]",
            'orientation = { axis = [0, 0, 1], angle = "-_pi*turns" }', "track_turns = true",
            "[end]", 'type = "half_turn"', "axis = [1, 0, 0]", "director = 1",
            "[guess]", "force = [0, 0, -53.2741126]", "moment = [0, 9.9437843, 0]",
            "[solver]", "tolerance = 1e-8", ""])
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "half.toml")
            with open(path, "w") as f:
                f.write(text)
            b = kirchhoff.load_case(path).continue_("turns", to=1.0, max_step=20.0)
        pts = b.points
        changes = [i for i, t in enumerate(pts["type"]) if t == "index_change"]
        self.assertEqual(len(changes), 2)
        for i, expected in zip(changes, (0.57322, 0.86154)):
            self.assertAlmostEqual(pts["parameter"][i], expected, delta=2e-5)
            self.assertEqual(pts["stability_index"][i], 0)
            self.assertEqual(pts["zero_modes"][i], 1)
        between = [pts["stability_index"][i] for i in range(changes[0] + 1, changes[1])]
        self.assertTrue(between and all(v == 1 for v in between))

    def test_columns(self):
        pts = self.branch.points
        n = len(self.branch)
        self.assertGreater(n, 5)
        for key in ("parameter", "arclength", "theta0", "y_max", "end_to_end", "H_spread", "branch", "multiplicity",
                    "newton_iterations"):
            self.assertIsInstance(pts[key], np.ndarray, key)
            self.assertEqual(len(pts[key]), n, key)
        self.assertEqual(len(pts["type"]), n)
        self.assertTrue(all(isinstance(t, str) for t in pts["type"]))
        self.assertEqual(pts["type"][0], "start")
        self.assertEqual(pts["branch"][0], 0)
        # Branch 0 then branch 1, each contiguous.
        self.assertTrue(np.all(np.diff(pts["branch"]) >= 0))
        self.assertEqual(set(pts["branch"].tolist()), {0, 1})

    def test_branch_point_at_the_euler_load(self):
        pts = self.branch.points
        bp = [i for i, t in enumerate(pts["type"]) if t == "branch_point"]
        self.assertTrue(bp)
        first = bp[0]
        self.assertEqual(pts["branch"][first], 0)
        self.assertEqual(pts["multiplicity"][first], 1)
        self.assertLess(abs(pts["parameter"][first] - math.pi ** 2), 1e-8 * math.pi ** 2)
        # The switched branch starts at the branch point and buckles (theta0 > 0 with side = +1).
        start1 = int(np.argmax(pts["branch"] == 1))
        self.assertEqual(pts["type"][start1], "branch_point")
        self.assertAlmostEqual(pts["parameter"][start1], pts["parameter"][first], places=10)
        self.assertGreater(pts["theta0"][start1 + 1], 0.0)

    def test_hamiltonian_flat_along_the_branch(self):
        pts = self.branch.points
        self.assertTrue(np.all(pts["H_flat"]))
        self.assertLess(np.max(pts["H_relative_spread"]), 1e-9)

    def test_bad_inputs_raise_value_error(self):
        case = kirchhoff.load_case(case_path("euler_column.toml"))
        with self.assertRaises(ValueError) as cm:
            case.continue_("not_a_parameter", to=13.0)
        self.assertIn("not_a_parameter", str(cm.exception))
        with self.assertRaises(ValueError) as cm:
            case.continue_("P", to=13.0, events={"not_derived": 1.0})
        self.assertIn("not_derived", str(cm.exception))
        with self.assertRaises(ValueError):
            case.continue_("P", to=13.0, step=-1.0)
        # A flag is True or False: None or 0 turned the stability columns off silently (a probe).
        for flag in ("stability", "branch_points", "resume", "deflate"):
            for value in (None, 0, 2, "yes"):
                with self.assertRaises(TypeError, msg=f"{flag}={value!r}"):
                    case.continue_("P", to=13.0, **{flag: value})

    def test_branch_points_can_be_skipped(self):
        case = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": 1.0, "theta_guess": 0.0})
        found = case.continue_("P", to=12.0, max_step=1.0)
        skipped = case.continue_("P", to=12.0, max_step=1.0, branch_points=False)
        self.assertIn("branch_point", list(found.points["type"]))
        self.assertNotIn("branch_point", list(skipped.points["type"]))
        self.assertAlmostEqual(skipped.points["parameter"][-1], 12.0, places=12)
        with self.assertRaises(ValueError) as cm:
            case.continue_("P", to=12.0, switch_at_bp=1, branch_points=False)
        self.assertIn("branch_points", str(cm.exception))

    def test_missing_branch_point_is_reported(self):
        # The straight column below the Euler load: no branch point before the target.
        case = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": 1.0, "theta_guess": 0.0})
        b = case.continue_("P", to=2.0, switch_at_bp=1)
        self.assertEqual(b.reason, "reached_target")
        self.assertFalse(b.switched)
        self.assertFalse(b.ok)
        self.assertIn("no branch point 1", b.message)
        self.assertEqual(set(b.points["branch"].tolist()), {0})


class ContinueRunControlTest(unittest.TestCase):
    """continue_'s max_seconds, state/resume and start_from, as the CLI's --max-seconds, --resume
    and --start-from."""

    def test_time_limited_run_resumed_gives_the_uninterrupted_points(self):
        # The straight column to P = 400 (six branch points, ~1100 points in ~3 s) stopped after
        # 0.3 s, then resumed from its state file: the two Branches together are the
        # uninterrupted run's points, bit for bit (the resumed march repeats its steps).
        case = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": 1.0, "theta_guess": 0.0})
        run = dict(to=400.0, max_step=0.5, max_points=5000)
        whole = case.continue_("P", **run)
        self.assertEqual(whole.reason, "reached_target")
        with tempfile.TemporaryDirectory() as tmp:
            state = pathlib.Path(tmp) / "column.state.json"
            first = case.continue_("P", **run, max_seconds=0.3, state=state)
            self.assertEqual(first.reason, "time_limit")
            self.assertFalse(first.ok)
            self.assertTrue(state.exists())
            rest = case.continue_("P", **run, state=state, resume=True)
            self.assertEqual(rest.reason, "reached_target")
            after = rest.points["index"][0]
            self.assertGreater(after, 0)
            kept = first.points["index"] < after
            np.testing.assert_array_equal(np.concatenate([first.points["index"][kept], rest.points["index"]]),
                                          whole.points["index"])
            for column in ("parameter", "theta0"):
                np.testing.assert_array_equal(
                    np.concatenate([first.points[column][kept], rest.points[column]]), whole.points[column])
            types = [t for t, k in zip(first.points["type"], kept) if k] + rest.points["type"]  # (lists of str)
            self.assertEqual(types, whole.points["type"])

    def test_resume_refuses_another_runs_state_and_needs_one(self):
        case = kirchhoff.load_case(case_path("simply_supported.toml"))
        with tempfile.TemporaryDirectory() as tmp:
            state = str(pathlib.Path(tmp) / "a.state.json")
            case.continue_("theta0", to=1.2, state=state)
            with self.assertRaises(kirchhoff.CaseError) as cm:
                case.continue_("theta0", to=1.3, state=state, resume=True)  # another target: another run
            self.assertIn("other arguments", str(cm.exception))
            with self.assertRaises(kirchhoff.CaseError) as cm:
                case.continue_("theta0", to=1.2, resume=True)
            self.assertIn("needs state=PATH", str(cm.exception))
            with self.assertRaises(kirchhoff.CaseError) as cm:
                case.continue_("theta0", to=1.2, state=str(pathlib.Path(tmp) / "none.json"), resume=True)
            self.assertIn("no state file", str(cm.exception))
            with self.assertRaises(ValueError):
                case.continue_("theta0", to=1.2, max_seconds=-1)

    @unittest.skipUnless(os.environ.get("KIRCHHOFF_CLI"), "needs the CLI's path in KIRCHHOFF_CLI (ctest sets it)")
    def test_python_resumes_a_run_the_cli_started(self):
        # One run identity for both front ends (run_identity): a CLI run killed after its third
        # row is resumed from Python with the same arguments, and ends on the points of Python's
        # uninterrupted run. The case is named by another path to the same file.
        path = case_path("simply_supported.toml")
        other_path = str(CASES / ".." / CASES.name / "simply_supported.toml")
        with tempfile.TemporaryDirectory() as tmp:
            csv = pathlib.Path(tmp) / "b.csv"
            killed = subprocess.run([os.environ["KIRCHHOFF_CLI"], "continue", path, "--param", "theta0", "--to", "1.5",
                                     "--set", "theta0=1.0", "--event", "theta_end=-1.4", "--checkpoint", "0",
                                     "--out", str(csv)],
                                    env=dict(os.environ, KIRCHHOFF_TEST_KILL_AFTER_ROW="3"), capture_output=True)
            self.assertNotEqual(killed.returncode, 0)
            case = kirchhoff.load_case(other_path, set={"theta0": 1})
            rest = case.continue_("theta0", to=1.5, events={"theta_end": -1.4}, state=str(csv) + ".state.json",
                                  resume=True)
            whole = case.continue_("theta0", to=1.5, events={"theta_end": -1.4})
            self.assertEqual(rest.reason, whole.reason)
            self.assertGreater(rest.points["index"][0], 0)
            n = len(rest.points["index"])
            np.testing.assert_array_equal(rest.points["index"], whole.points["index"][-n:])
            np.testing.assert_array_equal(rest.points["parameter"], whole.points["parameter"][-n:])

    def test_an_event_value_that_cannot_be_crossed_is_refused(self):
        case = kirchhoff.load_case(case_path("simply_supported.toml"))
        for value in (math.nan, math.inf, 1e300):
            with self.assertRaisesRegex(kirchhoff.CaseError, "theta_end's value must be finite"):
                case.continue_("theta0", to=1.2, events={"theta_end": value})
        with self.assertRaisesRegex(kirchhoff.CaseError, "the state file cannot be read"):
            with tempfile.TemporaryDirectory() as tmp:
                case.continue_("theta0", to=1.2, state=tmp, resume=True)  # a folder

    def test_start_from_another_runs_last_point(self):
        # From the end of a run in theta0 to 1.5, on to 2: the run starts at theta0 = 1.5 (its
        # first point, type 'start') and reaches the elliptic load 4 K(k)^2 EI/L^2 at theta0 = 2
        # (1e-9: Newton to 1e-10 on residuals integrated at 1e-12, as the solve tests).
        case = kirchhoff.load_case(case_path("simply_supported.toml"))
        with tempfile.TemporaryDirectory() as tmp:
            state = pathlib.Path(tmp) / "to_1.5.state.json"
            first = case.continue_("theta0", to=1.5, state=state)
            self.assertEqual(first.reason, "reached_target")
            b = case.continue_("theta0", to=2.0, start_from=state)
            self.assertEqual(b.reason, "reached_target")
            self.assertEqual(b.points["type"][0], "start")
            self.assertAlmostEqual(b.points["parameter"][0], 1.5, delta=1e-12)
            self.assertAlmostEqual(b.points["P"][0], first.points["P"][-1], delta=1e-9 * first.points["P"][-1])
            exact = kirchhoff.analytic_pinned_load(1.0, 1.0, 2.0)
            self.assertLess(abs(b.points["P"][-1] / exact - 1), 1e-9)
            # A state of a run whose parameters this case does not have is refused, naming it.
            with self.assertRaises(ValueError) as cm:
                kirchhoff.load_case(case_path("euler_column.toml")).continue_("P", to=12.0, start_from=state)
            self.assertIn("theta0", str(cm.exception))


class ReproduceTest(unittest.TestCase):
    def test_rows_are_the_reports(self):
        # The quick run (2-3 minutes): every row passes, and the rows returned are report.json's,
        # in order, with the same values (the CLI's `reproduce` test checks its exit status).
        with tempfile.TemporaryDirectory() as tmp:
            rows = kirchhoff.reproduce(tmp)
            with open(pathlib.Path(tmp) / "report.json") as f:
                report = json.load(f)
            self.assertEqual(len(rows), len(report))
            self.assertGreater(len(rows), 80)
            def same(value, saved):  # JSON writes NaN as null; its numbers round-trip exactly
                return value == saved or (saved is None and (value is None or math.isnan(value)))
            for row, saved in zip(rows, report):
                self.assertEqual(row["id"], saved["id"])
                self.assertEqual(row["quantity"], saved["quantity"])
                for key in ("numeric", "analytic", "paper", "rel_error", "tolerance"):
                    self.assertTrue(same(row[key], saved[key]), (row["id"], key, row[key], saved[key]))
                self.assertEqual(row["status"], {True: "pass", False: "FAIL", None: "info"}[saved["pass"]])
            self.assertNotIn("FAIL", [r["status"] for r in rows])
            self.assertTrue((pathlib.Path(tmp) / "profiles" / "fig5_cavity_branch.csv").exists())

    def test_a_case_that_cannot_be_loaded_raises_and_writes_no_report(self):
        # The whole run (a few minutes) is ctest's `reproduce` through the CLI, over the same
        # library function; here its binding, from a cases folder without the cases.
        with tempfile.TemporaryDirectory() as tmp:
            out = pathlib.Path(tmp) / "out"
            with self.assertRaises(ValueError) as cm:
                kirchhoff.reproduce(out, cases=tmp)
            self.assertIn("simply_supported.toml", str(cm.exception))
            self.assertFalse((out / "report.md").exists())


class VibrateTest(unittest.TestCase):
    def test_pinned_column_frequencies_and_flat_h_vib(self):
        # Straight column under the dead load P = pi^2/2: omega_k^2 = (k pi)^4 - P (k pi)^2 (eq. 96).
        P = 0.5 * math.pi ** 2
        case = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": P, "theta_guess": 0.0})
        result = case.vibrate(modes=2, samples=51)
        self.assertIsInstance(result["frequencies"], np.ndarray)
        self.assertTrue(result["straight_equilibrium"])
        for k, mode in enumerate(result["modes"], start=1):
            q = k * math.pi
            self.assertLess(abs(mode["omega"] / math.sqrt(q ** 4 - P * q ** 2) - 1.0), 1e-9)
            self.assertTrue(mode["H_vib"]["applies"])
            self.assertLess(mode["H_vib"]["relative_spread"], 1e-9)
            self.assertEqual(mode["ybar"].shape, (51,))
            # sin(k pi s), normalised to a largest deflection of 1.
            self.assertAlmostEqual(np.max(np.abs(mode["ybar"])), 1.0, places=12)

    def test_buckled_h_vib_is_not_flat(self):
        case = kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": 1.0})
        mode = case.vibrate(modes=1)["modes"][0]
        self.assertFalse(mode["H_vib"]["applies"])
        self.assertGreater(mode["H_vib"]["relative_spread"], 1e-3)

    def test_the_equilibrium_is_the_one_solve_reaches(self):
        # Fig. 3 at theta0 = 3.1, where Newton from the guess lands elsewhere (HomotopyTest): the
        # vibrations are about solve()'s equilibrium, reached by the same homotopy, to the last bit.
        case = kirchhoff.load_case(case_path("simply_supported.toml"), set={"theta0": 3.1})
        v = case.vibrate(modes=1)
        self.assertEqual(v["parameters"], case.solve().parameters)
        self.assertNotEqual(v["parameters"]["P"], case.solve(direct=True).parameters["P"])

    def test_spatial_case_and_bad_options_raise_value_error(self):
        with self.assertRaises(ValueError):
            kirchhoff.load_case(case_path("twisted_clamped.toml")).vibrate()
        with self.assertRaises(ValueError):
            kirchhoff.load_case(case_path("euler_column.toml")).vibrate(rho_s=-1.0)
        # Refused before the equilibrium is solved for, with the CLI's reasons, also where the
        # solve would fail (an end inside the wall).
        with self.assertRaisesRegex(ValueError, "planar rods only"):
            kirchhoff.load_case(case_path("twisted_ribbon_pole.toml"), set={"pole_x": 0, "pole_z": 0}).vibrate()
        with self.assertRaisesRegex(ValueError, "rho_s"):
            kirchhoff.load_case(case_path("wall.toml"), set={"a": -0.01}).vibrate(rho_s=math.nan)


class UnstableVibrationTest(unittest.TestCase):
    def test_straight_column_above_two_euler_loads_has_two_negative_omega2(self):
        case = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": 50.0, "theta_guess": 0.0})
        v = case.vibrate(modes=2)
        self.assertTrue(v["unstable_searched"])
        self.assertEqual(v["negative_omega2_count"], 2)
        self.assertEqual(v["negative_omega2_count"], case.solve().stability["index"])
        self.assertTrue(all(m["omega2"] < 0 and m["growth_rate"] > 0 for m in v["unstable_modes"]))


class AnalyticHelixTest(unittest.TestCase):
    def test_closed_forms_of_the_ply_and_the_column(self):
        theta = 0.3
        s, c2 = math.sin(theta), math.cos(2 * theta)
        self.assertAlmostEqual(kirchhoff.analytic_plectoneme_end_tension(theta, 1.0, 1.0),
                               0.5 * s ** 4 * (1 + 2 / c2), places=14)
        self.assertAlmostEqual(kirchhoff.analytic_helix_twisting_moment(theta, 2.0, 0.5),
                               2.0 / 0.5 * 2 * s ** 3 * math.cos(theta) / c2, places=12)
        self.assertAlmostEqual(kirchhoff.analytic_pinned_column_frequency(1.0, 0.0, 1.0, 1.0, 1), math.pi ** 2, places=12)
        with self.assertRaises(ValueError):
            kirchhoff.analytic_plectoneme_end_tension(1.0, 1.0, 1.0)  # theta beyond pi/4: no ply


class PlectonemesTest(unittest.TestCase):
    """kirchhoff.plectonemes: the CLI's sweep, its CSVs returned as columns."""

    def test_exact_ply_from_the_barrier_branch(self):
        # L/2R = 100 on the barrier to 5 turns, then the ply with exact contact up to 5.2 and down
        # to 4.9 turns (~15 s). The exact rows: rho = R (R = L/(2 L/2R) = 0.005), contact forces and
        # the line's pressure > 0, strands no closer than 2R (1 - 1e-9), H_A = H_B to the issue's
        # 1e-8, and T R^2/EI within the helix approximation of eq. (61) on this short ply
        # (measured 0.85 % below; bar 5 %), the contact set a point, the line and a point.
        with tempfile.TemporaryDirectory() as tmp:
            r = kirchhoff.plectonemes(tmp, [100], [5.2], hard_from=5, turns_min=4.9)
            branch = r["branches"][100.0]
            barrier, exact = branch["barrier"], branch["exact"]
            self.assertEqual(branch["stop"], "reached_target")
            self.assertEqual(branch["exact_stop"], "up: reached_target; down: reached_target")
            self.assertAlmostEqual(barrier["turns"][-1], 5.0, delta=1e-8)
            self.assertEqual(r["points"], len(barrier["turns"]) + len(exact["turns"]))  # a row per point
            ends = [i for i, t in enumerate(exact["type"]) if t == "endpoint"]
            self.assertEqual(len(ends), 2)
            self.assertAlmostEqual(exact["turns"][ends[0]], 5.2, delta=1e-8)
            self.assertAlmostEqual(exact["turns"][ends[1]], 4.9, delta=1e-8)
            np.testing.assert_allclose(exact["helix_radius"], 0.005, rtol=1e-3)
            self.assertTrue(np.all(exact["min_contact_force"] > 0))
            self.assertTrue(np.all(exact["min_wrap_pressure"] > 0))
            self.assertTrue(np.all(exact["self_distance"] >= 1 - 1e-9))
            np.testing.assert_allclose(exact["H_A"] / exact["H_B"], 1.0, rtol=1e-8)
            np.testing.assert_allclose(exact["T_rho2_over_EI"] / exact["eq61"], 1.0, rtol=0.05)
            self.assertTrue(np.all(exact["contact_count"] == 3))
            # The same rows as the CSV the CLI's users read.
            with open(branch["exact_csv"]) as f:
                self.assertEqual(len(f.read().splitlines()) - 1, len(exact["turns"]))
            # Resumed, a finished sweep is left alone: nothing computed, the same columns.
            again = kirchhoff.plectonemes(tmp, [100], [5.2], hard_from=5, turns_min=4.9, resume=True)
            self.assertEqual(again["points"], 0)
            np.testing.assert_array_equal(again["branches"][100.0]["exact"]["T_ext"], exact["T_ext"])

    def test_progress_lines_on_stderr_and_a_finished_branch_left_alone(self):
        # A quarter turn at L/2R = 100: the sweep's progress line for the slenderness reaches
        # stderr through the library's progress callback (as the CLI's); resumed, the branch
        # whose CSV ends with its endpoint row (read by the `type` column) computes nothing.
        with tempfile.TemporaryDirectory() as tmp:
            with captured_stderr() as err:
                r = kirchhoff.plectonemes(tmp, [100], [0.25])
            self.assertIn("L/2R = 100: turns 0 -> 0.25", err.text)
            self.assertEqual(r["branches"][100.0]["stop"], "reached_target")
            self.assertGreater(r["points"], 1)
            again = kirchhoff.plectonemes(tmp, [100], [0.25], resume=True)
            self.assertEqual(again["points"], 0)

    def test_plectonemes_refuses_bad_arguments_before_running(self):
        # The library's checks (plectoneme_sweep.cpp), with the CLI's words and its exit 2.
        with tempfile.TemporaryDirectory() as tmp:
            out = pathlib.Path(tmp) / "out"
            with self.assertRaisesRegex(kirchhoff.CaseError, "--slenderness must be > 0"):
                kirchhoff.plectonemes(str(out), [0], [1])
            with self.assertRaisesRegex(kirchhoff.CaseError, "hard_from must be >= 0"):
                kirchhoff.plectonemes(str(out), [100], [1], hard_from=-1)
            with self.assertRaisesRegex(kirchhoff.CaseError, "sensitivity_tol must be in"):
                kirchhoff.plectonemes(str(out), [100], [1], sensitivity_tol=math.nan)
            self.assertFalse(out.exists())

    def test_interrupted_sweep_resumes_without_losing_rows(self):
        # Ctrl-C (interrupt_main, 2 s into L/2R = 100 to 3 turns, a ~6 s run) raises
        # KeyboardInterrupt after the point being written; the CSV keeps its rows, and resume=True
        # finishes the branch from the last saved point, the rows before it untouched.
        with tempfile.TemporaryDirectory() as tmp:
            timer = threading.Timer(2.0, _thread.interrupt_main)
            timer.start()
            with self.assertRaises(KeyboardInterrupt):
                kirchhoff.plectonemes(tmp, [100], [3])
            timer.join()
            csv = pathlib.Path(tmp) / "plectoneme_100.csv"
            before = csv.read_text().splitlines()
            self.assertGreater(len(before), 5)
            self.assertNotIn(",endpoint,", before[-1])
            done = kirchhoff.plectonemes(tmp, [100], [3], resume=True)
            after = csv.read_text().splitlines()
            self.assertEqual(done["branches"][100.0]["stop"], "reached_target")
            self.assertIn(",endpoint,", after[-1])
            self.assertEqual(after[:len(before) - 3], before[:-3])
            self.assertEqual([int(r.split(",")[0]) for r in after[1:]], list(range(len(after) - 1)))

    def test_arguments_the_sweep_refuses_raise_case_error(self):
        with tempfile.TemporaryDirectory() as tmp:
            with self.assertRaises(kirchhoff.CaseError) as cm:
                kirchhoff.plectonemes(tmp, [100, 200], [10])
            self.assertIn("--slenderness and --turns need the same number of values", str(cm.exception))
            with self.assertRaises(kirchhoff.CaseError) as cm:
                kirchhoff.plectonemes(tmp, [100, 150], [4, 5], hard_from=5, from_ply=[150])
            self.assertIn("L/2R = 150 is reached from the exact ply of L/2R = 100, which has none", str(cm.exception))
            with self.assertRaises(kirchhoff.CaseError):
                kirchhoff.plectonemes(tmp, [100], [3], case=str(pathlib.Path(tmp) / "no_such_case.toml"))
            self.assertEqual(os.listdir(tmp), [])  # refused before anything ran


class KeepFreedMemoryTest(unittest.TestCase):
    # glibc's own count of blocks that have a mapping of their own (mallinfo2().hblks), read
    # with ctypes: a 143 MB array (the exact ply's Jacobian at L/2R = 1000) gets one by default
    # and none once freed memory is kept in the heap. The setting is process-wide, so this runs
    # in a child interpreter.
    def test_large_blocks_come_from_the_heap(self):
        if not sys.platform.startswith("linux"):
            self.skipTest("glibc's malloc")
        child = r"""
import ctypes, numpy as np, kirchhoff
class MallInfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in
                ("arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks", "fordblks", "keepcost")]
libc = ctypes.CDLL(None)
libc.mallinfo2.restype = MallInfo2
def mappings_while_holding():
    block = np.ones(4236 * 4236)
    return libc.mallinfo2().hblks
before = libc.mallinfo2().hblks
print(mappings_while_holding() - before, kirchhoff.keep_freed_memory(), mappings_while_holding() - before)
"""
        out = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, check=True).stdout
        self.assertEqual(out.split(), ["1", "True", "0"])


class SweepTest(unittest.TestCase):
    def test_serial_sweep_returns_the_index_as_columns(self):
        with tempfile.TemporaryDirectory() as d:
            spec = pathlib.Path(d) / "sweep.toml"
            spec.write_text(f'case = "{pathlib.Path(case_path("simply_supported.toml")).resolve()}"\n'
                            '[[jobs]]\nkind = "solve"\ngrid = { theta0 = [0.5, 1.0, 2.0] }\n')
            out = str(pathlib.Path(d) / "out")
            index = kirchhoff.sweep(str(spec), out)
            self.assertEqual(index["job"], ["solve-001", "solve-002", "solve-003"])
            self.assertEqual(index["theta0"], [0.5, 1.0, 2.0])
            self.assertEqual(index["status"], ["ok"] * 3)
            self.assertEqual(index["contact_state"], ["none"] * 3)
            self.assertEqual(index["stability_index"], [0.0] * 3)
            self.assertEqual(index["zero_modes"], [0.0] * 3)
            self.assertAlmostEqual(index["P"][2], 17.4295934848, places=8)  # Fig. 3, README
            self.assertTrue((pathlib.Path(out) / "jobs" / "solve-002" / "profile.csv").exists())
            with self.assertRaises(kirchhoff.CaseError):  # results there already, no resume
                kirchhoff.sweep(str(spec), out)
            self.assertEqual(kirchhoff.sweep(str(spec), out, resume=True), index)

    def test_serial_sweep_refuses_to_be_one_of_several_mpi_copies(self):
        # Under mpirun each copy of the serial sweep would run every job into the same folder:
        # the library refuses (as the CLI built without MPI does), before anything is written.
        with tempfile.TemporaryDirectory() as d:
            spec = pathlib.Path(d) / "sweep.toml"
            spec.write_text(f'case = "{pathlib.Path(case_path("simply_supported.toml")).resolve()}"\n'
                            '[[jobs]]\nkind = "solve"\ngrid = { theta0 = [0.5] }\n')
            out = pathlib.Path(d) / "out"
            os.environ["OMPI_COMM_WORLD_SIZE"] = "2"
            try:
                with self.assertRaisesRegex(kirchhoff.CaseError, "one of 2 MPI processes"):
                    kirchhoff.sweep(str(spec), str(out))
            finally:
                del os.environ["OMPI_COMM_WORLD_SIZE"]
            self.assertFalse((out / "jobs").exists())

    def test_bad_sweep_file_raises_case_error_with_line_and_key(self):
        with tempfile.TemporaryDirectory() as d:
            spec = pathlib.Path(d) / "bad.toml"
            spec.write_text(f'case = "{pathlib.Path(case_path("simply_supported.toml")).resolve()}"\n[[jobs]]\nkind = "solve"\n'
                            'grid = { nope = [1, 2] }\n')
            with self.assertRaisesRegex(kirchhoff.CaseError, r"bad.toml:4: key 'jobs\[1\].grid.nope': no parameter"):
                kirchhoff.sweep(str(spec), str(pathlib.Path(d) / "out"))


class EquilibriaTest(unittest.TestCase):
    def test_clamped_clamped_modes_by_energy(self):
        c = kirchhoff.load_case(case_path("clamped_clamped.toml"))
        eqs = c.equilibria(max=4)
        self.assertEqual(len(eqs), 4)
        # The symmetric mode and its mirror image (stable), then the S-shaped pair (index 1).
        self.assertEqual([e.stability["index"] for e in eqs], [0, 0, 1, 1])
        energies = [e.energy for e in eqs]
        self.assertEqual(energies, sorted(energies))
        for e in eqs:
            self.assertTrue(e.converged)
            self.assertLessEqual(e.residual, 1e-10)
            self.assertTrue(e.found_by)
            self.assertIn("y_max", e.derived)
        # Mirror images: the same energy to the solver's accuracy (residuals 1e-10).
        self.assertAlmostEqual(energies[0], energies[1], delta=1e-8 * energies[0])
        self.assertNotAlmostEqual(eqs[0].profile["y"][100], eqs[1].profile["y"][100], places=3)

    def test_a_rod_lying_flat_on_the_wall_is_listed(self):
        # A pinned-pinned rod held at 0.7 under a wall at y = 0.2 (tests/discrete_seed_test.cpp):
        # the mirror-symmetric Ipopt seed brings it lying flat on the wall, energy 11.620963 (the
        # discretised energy's at 100, 200 and 400 segments, extrapolated: 1e-5 leaves ten times
        # its error), index 1 by the discretised energy, its profile at the wall's height between
        # the flat contacts' outer ends (to the solve's 1e-10).
        with tempfile.TemporaryDirectory() as d:
            path = pathlib.Path(d) / "pinned_wall.toml"
            path.write_text('model = "planar"\n[parameters]\nD = 0.7\n[rod]\nlength = 1.0\nB = 1.0\n'
                            '[start]\ntype = "pinned"\nposition = [0, 0]\n[end]\ntype = "pinned"\n'
                            'position = ["D", 0]\n[guess]\norientation = { axis = [0, 0, 1], angle = 1.2 }\n'
                            'force = [-15, 0]\n[[obstacles]]\ntype = "plane"\nname = "wall"\npoint = [0, 0.2]\n'
                            'normal = [0, -1, 0]\n')
            eqs = kirchhoff.load_case(str(path)).equilibria(max=4)
        flat = [e for e in eqs if any(c["extended"] for c in e.contacts)]
        self.assertEqual(len(flat), 1)
        self.assertAlmostEqual(flat[0].energy, 11.620963, delta=1e-5)
        self.assertEqual(flat[0].stability["index"], 1)
        first = min(c["s"] for c in flat[0].contacts)
        last = max(c["s_end"] for c in flat[0].contacts)
        on_wall = [y for s, y in zip(flat[0].profile["s"], flat[0].profile["y"]) if first <= s <= last]
        self.assertGreater(len(on_wall), 10)
        for y in on_wall:
            self.assertAlmostEqual(y, 0.2, delta=1e-10)

    def test_points_of_a_continuous_family_share_its_number(self):
        # A rod pinned at both ends at one point: every closed Elastica is a circle of equilibria
        # (turned about the pin), of which the search finds several points (the CLI's JSON
        # "family"; tests/equilibria_test.cpp checks the grouping).
        with tempfile.TemporaryDirectory() as d:
            path = pathlib.Path(d) / "pinned_twice.toml"
            path.write_text('model = "planar"\n[parameters]\nF = 86.0\n[rod]\nlength = 1.0\nB = 1.0\n'
                            '[start]\ntype = "pinned"\nposition = [0, 0]\n[end]\ntype = "pinned"\nposition = [0, 0]\n'
                            '[guess]\norientation = { axis = [0, 0, 1], angle = 2.2 }\nforce = ["-F", 0]\n')
            eqs = kirchhoff.load_case(str(path)).equilibria(max=4)
        # Families numbered from 1, at least two (a closed rod and its mirror image are not turned
        # into each other), one of them holding two of the four points (which depends on the
        # order the seeds reach them).
        families = [e.family for e in eqs]
        self.assertGreaterEqual(len(set(families)), 2)
        self.assertEqual(sorted(set(families)), list(range(1, len(set(families)) + 1)))
        self.assertGreaterEqual(max(families.count(f) for f in set(families)), 2)
        self.assertEqual([e.stability["zero_modes"] for e in eqs], [1, 1, 1, 1])
        self.assertIsNone(kirchhoff.load_case(case_path("clamped_clamped.toml")).equilibria(max=1)[0].family)

    def test_bad_options_raise(self):
        # The library's checks (EquilibriaOptions::validate, StartSeed::validate), as the CLI's,
        # raised as CaseError like every other bad input of a case.
        c = kirchhoff.load_case(case_path("clamped_clamped.toml"))
        for bad in (lambda: c.equilibria(max=0), lambda: c.solve(max_seconds=-1), lambda: c.solve(samples=1),
                    lambda: c.vibrate(rho_s=-1.0)):
            with self.assertRaises(kirchhoff.CaseError):
                bad()
        with self.assertRaisesRegex(ValueError, r"max \(equilibria\) must be in \[1, 1000\]"):
            c.equilibria(max=0)
        with self.assertRaisesRegex(ValueError, r"must be in \[1, 1000\]"):
            c.equilibria(max=1001)
        with self.assertRaisesRegex(ValueError, "max_seconds must be in"):
            c.equilibria(max_seconds=-1)
        with self.assertRaisesRegex(ValueError, r"seed segments must be in \[4, 100000\]"):
            c.solve(seed="ipopt", seed_segments=200000)

    def test_an_equilibrium_converged_at_round_off_says_so(self):
        # The straight rod in tension at P = 150: its residual's sensitivity to theta0 grows like
        # exp(sqrt(P) L) = 2e5, so Newton stops with its step at round-off above the tolerance
        # 1e-10 (within 1e3 times it, as solve accepts); the message says how it converged.
        # (The values in the file itself: with --set ones the list would start from solve's
        # equilibrium, reached by homotopy and converged within the tolerance.)
        text = pathlib.Path(case_path("euler_column.toml")).read_text()
        text = re.sub(r"(?m)^P = [0-9.]+", "P = 150.0", text)
        text = re.sub(r"(?m)^theta_guess = [0-9.]+", "theta_guess = 3.14159", text)
        with tempfile.TemporaryDirectory() as d:
            path = pathlib.Path(d) / "column_at_150.toml"
            path.write_text(text)
            e = kirchhoff.load_case(str(path)).equilibria(max=1)
        self.assertEqual(len(e), 1)
        self.assertAlmostEqual(e[0].energy, -150.0, delta=1e-9 * 150)
        self.assertGreater(e[0].residual, 1e-10)
        self.assertLessEqual(e[0].residual, 1e-7)
        self.assertIn("converged with step at round-off", e[0].message)

    def test_no_equilibrium_found_warns_with_the_search_s_reason(self):
        # An end inside the wall: the CLI exits 1 with "no equilibrium found (...)"; Python returns
        # an empty list and says the same in a RuntimeWarning.
        case = kirchhoff.load_case(case_path("wall.toml"), set={"a": -0.01})
        with self.assertWarnsRegex(RuntimeWarning, "no equilibrium found"):
            self.assertEqual(case.equilibria(max=2, max_seconds=60), [])

    def test_continue_starts_from_solve_s_equilibrium_where_the_guess_fails(self):
        # The wall at Delta = 0.04: the active-set loop from the arch's guess does not settle, so
        # the branch starts from the equilibrium solve reaches by homotopy (the CLI's note, in
        # Branch.notes), P = 251.69 on the flat contact, as solve() gives it.
        case = kirchhoff.load_case(case_path("wall.toml"), set={"Delta": 0.04})
        b = case.continue_("Delta", to=0.045, stability=False)
        self.assertTrue(b.ok, b.message)
        self.assertTrue(any("by homotopy from the file's values (Delta = 0.026 -> 0.04)" in n for n in b.notes),
                        b.notes)
        self.assertAlmostEqual(b.points["P"][0], case.solve().derived["P"], delta=1e-12 * 251.69)

    def test_continue_deflate_follows_every_branch_from_the_start(self):
        # The Euler column's five equilibria at P = 50, each followed to P = 60 (as the CLI's
        # --deflate; tests/continue_cli_test.cpp checks the ends against the closed form).
        b = kirchhoff.load_case(case_path("euler_column.toml"), set={"P": 50}).continue_(
            "P", to=60, deflate=True, deflate_max=5, stability=False)
        self.assertEqual(b.reason, "reached_target")
        branch = np.asarray(b.points["branch"])
        self.assertEqual(sorted(set(branch.tolist())), [0, 1, 2, 3, 4])
        P = np.asarray(b.points["parameter"])
        for k in range(5):
            self.assertEqual(P[branch == k][0], 50.0)
            self.assertAlmostEqual(P[branch == k][-1], 60.0, delta=1e-9)
        with self.assertRaises(ValueError):
            kirchhoff.load_case(case_path("euler_column.toml")).continue_("P", to=60, deflate=True, switch_at_bp=1)


class SystemContinuationTest(unittest.TestCase):
    """kirchhoff.continue_system: the engine on systems given as Python functions."""

    def test_circle_folds(self):
        # F = (x1 - x2, x1^2 + lam^2 - 1): a circle in (x1, lam), folds at lam = +1 and -1. The
        # corrector holds |F| <= 1e-10 at every point; the folds are located where the tangent's
        # lambda component vanishes, x1 = 0 to the location's tolerance t, so |lam| = 1 to t^2 / 2.
        F = lambda x, lam: [x[0] - x[1], x[0] ** 2 + lam ** 2 - 1]
        J = lambda x, lam: [[1.0, -1.0, 0.0], [2 * x[0], 0.0, 2 * lam]]
        b = kirchhoff.continue_system(F, J, [0.9, 0.9], 0.0, max_points=100, max_step=0.1)
        p = b["points"]
        self.assertEqual(b["reason"], "max_points")
        np.testing.assert_allclose(p["x"][:, 0] ** 2 + p["parameter"] ** 2, 1.0, atol=1e-10)
        folds = [lam for lam, t in zip(p["parameter"], p["type"]) if t == "fold"]
        self.assertGreaterEqual(len(folds), 2)
        self.assertAlmostEqual(folds[0], 1.0, delta=1e-9)
        self.assertAlmostEqual(folds[1], -1.0, delta=1e-9)

    def test_pitchfork_switch_and_event(self):
        # x (lam - x^2) = 0: the trivial branch from lam = -1, its branch point at the origin, then
        # the parabola x = +sqrt(lam) to the event x0 = 0.5 (lam = 0.25).
        F = lambda x, lam: [x[0] * (lam - x[0] ** 2)]
        J = lambda x, lam: [[lam - 3 * x[0] ** 2, x[0]]]
        b = kirchhoff.continue_system(F, J, [0.1], -1.0, to=1.0, switch_at_bp=1, events={"x0": 0.5})
        p = b["points"]
        self.assertTrue(b["switched"])
        self.assertEqual(b["reason"], "event")
        bp = list(p["type"]).index("branch_point")
        self.assertAlmostEqual(p["parameter"][bp], 0.0, delta=1e-9)
        after = p["branch"] == 1
        np.testing.assert_allclose(p["parameter"][after], p["x"][after, 0] ** 2, atol=1e-8)
        self.assertAlmostEqual(p["x"][-1, 0], 0.5, delta=1e-9)
        self.assertAlmostEqual(p["parameter"][-1], 0.25, delta=1e-8)

    def test_bratu_fold_converges_to_the_critical_value(self):
        # u'' + lam exp(u) = 0, u(0) = u(1) = 0, by central differences on N interior points: the
        # fold of the discrete problem converges at second order in h to the continuous one,
        # lam_c = 3.513830719 (the root of the closed form lam = 8 t^2 / cosh(t/4)^2's maximum).
        # Richardson's extrapolation of N = 20 and 40 (h = 1/21, 1/41) removes the h^2 term; what
        # is left is O(h1^2 h2^2) = 1.3e-6 times a coefficient of order one (measured: 7.6e-7).
        def fold(N):
            h = 1.0 / (N + 1)
            def F(u, lam):
                v = np.concatenate(([0.0], u, [0.0]))
                return (v[:-2] - 2 * v[1:-1] + v[2:]) / h ** 2 + lam * np.exp(u)
            def J(u, lam):
                A = np.zeros((N, N + 1))
                A[np.arange(N), np.arange(N)] = -2 / h ** 2 + lam * np.exp(u)
                A[np.arange(N - 1), np.arange(1, N)] = 1 / h ** 2
                A[np.arange(1, N), np.arange(N - 1)] = 1 / h ** 2
                A[:, N] = np.exp(u)
                return A
            b = kirchhoff.continue_system(F, J, np.zeros(N), 0.0, to=5.0, max_step=0.5, max_points=200)
            folds = [lam for lam, t in zip(b["points"]["parameter"], b["points"]["type"]) if t == "fold"]
            self.assertEqual(len(folds), 1, b["message"])
            return folds[0]
        l20, l40 = fold(20), fold(40)
        self.assertLess(l20, l40)  # the error is -c h^2: both below lam_c, the finer closer
        h20, h40 = 1 / 21, 1 / 41
        extrapolated = (h20 ** 2 * l40 - h40 ** 2 * l20) / (h20 ** 2 - h40 ** 2)
        self.assertAlmostEqual(extrapolated, 3.513830719, delta=1e-5)

    def test_bad_systems_say_why(self):
        F = lambda x, lam: [x[0] - lam]
        wrong_shape = lambda x, lam: [[1.0]]
        b = kirchhoff.continue_system(F, wrong_shape, [0.0], 0.0, to=1.0)
        self.assertEqual(b["reason"], "start_failed")
        self.assertIn("J returned a 1 x 1 matrix", b["message"])

        def raises(x, lam):
            raise RuntimeError("no F here")
        with self.assertRaisesRegex(RuntimeError, "no F here"):
            kirchhoff.continue_system(raises, wrong_shape, [0.0], 0.0)
        with self.assertRaisesRegex(ValueError, "components of x"):
            kirchhoff.continue_system(F, wrong_shape, [0.0], 0.0, events={"y": 1.0})
        with self.assertRaisesRegex(ValueError, "to must be a finite number"):
            kirchhoff.continue_system(F, wrong_shape, [0.0], 0.0, to=float("nan"))


if __name__ == "__main__":
    unittest.main()

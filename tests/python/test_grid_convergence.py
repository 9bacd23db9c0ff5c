"""bvmesh.grid_convergence against closed-form grid sequences (phi = phi0 + C h^p, whose order and
limit the extrapolation must give back), and the grid-convergence command on run summaries."""

import contextlib
import io
import json
import math
import os
import tempfile
import unittest

from bvmesh import grid_convergence
from bvmesh.__main__ import main


def exact_sequence(limit, coefficient, order, cells, dimension=3):
    return [limit + coefficient * count ** (-order / dimension) for count in cells]


class Richardson(unittest.TestCase):
    def test_order_and_limit_of_an_exact_sequence_with_unequal_ratios(self):
        # h = 1/40, 1/30, 1/20: r21 = 4/3, r32 = 3/2, so the order needs the fixed-point iteration.
        cells = [40 ** 3, 30 ** 3, 20 ** 3]
        for order in (1.0, 1.5, 2.0, 3.0):
            values = exact_sequence(0.25, 0.8, order, cells)
            study = grid_convergence.richardson(values, cells)
            self.assertEqual(study["convergence"], "monotone")
            self.assertAlmostEqual(study["r21"], 4.0 / 3.0, places=12)
            self.assertAlmostEqual(study["r32"], 1.5, places=12)
            self.assertAlmostEqual(study["order"], order, places=9)
            self.assertAlmostEqual(study["extrapolated"], 0.25, places=12)
            fine_error = abs(values[0] - values[1]) / values[0]
            self.assertAlmostEqual(study["gci_fine"], 1.25 * fine_error / ((4.0 / 3.0) ** order - 1.0), places=12)
            self.assertAlmostEqual(study["extrapolated_error"], abs(values[0] - 0.25) / 0.25, places=10)

    def test_grids_in_any_order_and_in_two_dimensions(self):
        cells = [4096, 1024, 256]  # h halves in two dimensions
        values = exact_sequence(-0.01, 2.0, 2.0, cells, dimension=2)
        study = grid_convergence.richardson(list(reversed(values)), list(reversed(cells)), dimension=2)
        self.assertEqual(study["cells"], cells)
        self.assertAlmostEqual(study["r21"], 2.0, places=12)
        self.assertAlmostEqual(study["order"], 2.0, places=10)
        self.assertAlmostEqual(study["extrapolated"], -0.01, places=12)

    def test_oscillating_and_converged_values(self):
        cells = [64000, 27000, 8000]  # finest first
        oscillating = grid_convergence.richardson([0.27, 0.26, 0.275], cells)
        self.assertEqual(oscillating["convergence"], "oscillatory")
        converged = grid_convergence.richardson([0.27, 0.27, 0.26], cells)
        self.assertEqual(converged["convergence"], "none")
        self.assertIsNone(converged["order"])
        self.assertIsNone(converged["gci_fine"])
        diverging = grid_convergence.richardson([0.26, 0.27, 0.27], cells)
        self.assertEqual(diverging["convergence"], "divergent")
        self.assertIsNone(diverging["extrapolated"])
        # Differences that grow with refinement (an exact sequence with a negative order): no order
        # (Celik et al.'s absolute value would give these a positive one).
        growing = grid_convergence.richardson(exact_sequence(0.25, 0.8, -1.0, cells), cells)
        self.assertEqual(growing["convergence"], "divergent")
        self.assertIsNone(growing["order"])
        self.assertIsNone(growing["gci_fine"])

    def test_bad_input_names_the_problem(self):
        with self.assertRaisesRegex(ValueError, "three grids"):
            grid_convergence.richardson([1.0, 2.0], [10, 20])
        with self.assertRaisesRegex(ValueError, "different cell counts"):
            grid_convergence.richardson([1.0, 2.0, 3.0], [10, 10, 20])
        with self.assertRaisesRegex(ValueError, "finite"):
            grid_convergence.richardson([1.0, math.nan, 3.0], [10, 20, 40])
        with self.assertRaisesRegex(ValueError, "positive integers"):
            grid_convergence.richardson([1.0, 2.0, 3.0], [10, 20, 0])
        with self.assertRaisesRegex(ValueError, "dimension"):
            grid_convergence.richardson([1.0, 2.0, 3.0], [10, 20, 40], dimension=4)


class Command(unittest.TestCase):
    def run_command(self, *reports):
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(["grid-convergence"] + list(reports))
        return code, out.getvalue(), err.getvalue()

    def test_studies_cl_cd_and_cm_from_the_reports(self):
        cells = [8000, 27000, 64000]
        values = {name: exact_sequence(limit, 0.5, 2.0, cells)
                  for name, limit in (("CL", 0.28), ("CD", 0.016), ("CM", -0.003))}
        with tempfile.TemporaryDirectory() as folder:
            reports = []
            for g, count in enumerate(cells):
                report = os.path.join(folder, "grid{}".format(g))
                os.makedirs(report)
                with open(os.path.join(report, "summary.json"), "w") as file:
                    json.dump(dict(cells=count, CL=values["CL"][g], CD=values["CD"][g], CM=values["CM"][g]), file)
                reports.append(report)
            code, out, err = self.run_command(*reports)
            self.assertEqual(code, 0, err)
            self.assertIn("64000 / 27000 / 8000 cells", out)
            rows = {line.split("|")[1].strip(): line for line in out.splitlines() if line.startswith("| C")}
            self.assertEqual(sorted(rows), ["CD", "CL", "CM"])
            self.assertIn("| monotone | 2 | 0.28 |", rows["CL"])
            self.assertIn("| 0.016 |", rows["CD"])
            self.assertIn("| -0.003 |", rows["CM"])

            os.remove(os.path.join(reports[1], "summary.json"))
            code, out, err = self.run_command(*reports)
            self.assertEqual(code, 1)
            self.assertIn(os.path.join(reports[1], "summary.json"), err)
            with open(os.path.join(reports[1], "summary.json"), "w") as file:
                json.dump(dict(cells=27000, CL=0.3), file)
            code, out, err = self.run_command(*reports)
            self.assertEqual(code, 1)
            self.assertIn("has no CD", err)


if __name__ == "__main__":
    unittest.main()

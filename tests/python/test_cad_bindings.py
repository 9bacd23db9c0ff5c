"""The compiled module from plain /usr/bin/python3: shape summaries, B-spline faces, errors."""

import math
import os
import unittest

import numpy as np

import bvmesh
from bvmesh import _core

DATA = os.environ.get("BVMESH_TEST_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "data"))
WING = os.path.join(DATA, "AileM6_with_sharp_TE.stp")


def bicubic_poles():
    u, v = np.meshgrid(np.arange(4.0), np.arange(5.0), indexing="ij")
    return np.stack([u, v, 0.05 * (u * u - v * v)], axis=-1)


class ErrorClasses(unittest.TestCase):
    def test_hierarchy_maps_to_python_builtins(self):
        self.assertTrue(issubclass(bvmesh.InvalidInputError, ValueError))
        self.assertTrue(issubclass(bvmesh.TopologyError, bvmesh.InvalidInputError))
        self.assertTrue(issubclass(bvmesh.SolverError, RuntimeError))
        self.assertTrue(issubclass(bvmesh.CancelledError, RuntimeError))


class ShapeSummary(unittest.TestCase):
    def test_m6_wing_file(self):
        report = _core.summarize_file(WING)
        self.assertEqual(report["faces"], 11)
        self.assertEqual(report["surface_types"].count("BSplineSurface"), 8)
        self.assertEqual(report["surface_types"].count("Plane"), 3)
        self.assertEqual(report["edge_counts"]["free"], 0)
        self.assertGreater(report["edge_counts"]["sharp"], 0)
        low, high = report["bounds"]
        self.assertAlmostEqual(low[1], 0.0, places=3)

    def test_threshold_changes_sharp_count(self):
        loose = _core.summarize_file(WING, sharp_angle_degrees=5.0)["edge_counts"]["sharp"]
        strict = _core.summarize_file(WING, sharp_angle_degrees=100.0)["edge_counts"]["sharp"]
        self.assertGreater(loose, strict)

    def test_bad_input_names_the_problem(self):
        with self.assertRaisesRegex(bvmesh.InvalidInputError, "does not exist"):
            _core.summarize_file(os.path.join(DATA, "missing.stp"))
        with self.assertRaisesRegex(ValueError, "empty"):
            _core.summarize_brep("")
        with self.assertRaisesRegex(ValueError, "corrupt"):
            _core.summarize_brep("CASCADE Topology V1, (c) Matra-Datavision\nnonsense")


class BSplineFace(unittest.TestCase):
    def test_face_brep_is_returned(self):
        brep = _core.bspline_face_brep(bicubic_poles(), 3, 3, [0.0, 1.0], [0.0, 0.5, 1.0], [4, 4], [4, 1, 4])
        self.assertIn("CASCADE Topology", brep)
        report = _core.summarize_brep(brep)
        self.assertEqual(report["surface_types"], ["BSplineSurface"])
        self.assertEqual(report["edge_counts"]["free"], 4)

    def test_wrong_shapes_and_values(self):
        with self.assertRaisesRegex(ValueError, r"shape \(n_u, n_v, 3\)"):
            _core.bspline_face_brep(np.zeros((4, 5)), 3, 3, [0, 1], [0, 1], [4, 4], [4, 4])
        poles = bicubic_poles()
        poles[1, 2, 0] = math.nan
        with self.assertRaisesRegex(ValueError, "pole 7 has a non-finite"):
            _core.bspline_face_brep(poles, 3, 3, [0.0, 1.0], [0.0, 0.5, 1.0], [4, 4], [4, 1, 4])
        with self.assertRaisesRegex(ValueError, "weights must have shape"):
            _core.bspline_face_brep(bicubic_poles(), 3, 3, [0.0, 1.0], [0.0, 0.5, 1.0], [4, 4], [4, 1, 4],
                                    weights=np.ones(3))


if __name__ == "__main__":
    unittest.main()

"""bvmesh.SurfaceFitter from Python: steps, run with progress and cancel, options, errors."""

import threading
import unittest

import numpy as np

import bvmesh

from fixtures import CUBE_FACES, CUBE_VERTICES, sphere_target


class FitterSteps(unittest.TestCase):
    def setUp(self):
        self.fitter = bvmesh.SurfaceFitter(sphere_target(), bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES),
                                           max_level=3, check_samples_per_face=2)

    def test_steps_one_by_one(self):
        self.fitter.subdivide()
        self.assertEqual(self.fitter.level, 1)
        samples = self.fitter.compute_limit_samples()
        mesh = self.fitter.mesh
        self.assertEqual(samples.shape, (mesh.num_vertices + mesh.num_edges + mesh.num_faces, 3))
        projected = self.fitter.project()
        np.testing.assert_allclose(np.linalg.norm(projected["points"], axis=1), 1.0, atol=1e-9)
        before = self.fitter.record()["max_distance"]
        self.fitter.approximate()
        self.fitter.correct_parameters(2)
        after = self.fitter.record(check=True)
        self.assertLess(after["max_distance"], 0.5 * before)
        self.assertIsNotNone(after["limit_to_target"])
        self.assertEqual([r["correction"] for r in self.fitter.history], [0, 3])

    def test_run_reports_progress_and_converges(self):
        records = []
        summary = self.fitter.run(progress=records.append, tolerance=1e-3, max_level=4)
        self.assertEqual(summary["reason"], "converged")
        # Each pass is reported, and once more when its two-sided check is measured (the stop rule
        # measures it at every pass whose samples are within the tolerance, and at the end).
        checked = [r for r in summary["history"] if r["limit_to_target"] is not None]
        self.assertEqual(len(records), len(summary["history"]) + len(checked))
        last = summary["history"][-1]
        self.assertLessEqual(max(last["limit_to_target"], last["target_to_limit_beyond_cad"]), 1e-3)
        self.assertEqual(summary["detail"], "")
        self.assertLessEqual(summary["history"][-1]["max_distance"], 1e-3)
        self.assertEqual(self.fitter.options["tolerance"], 1e-3)

    def test_check_target_subdivisions(self):
        # The check's target side: the tessellation's nodes, or k^2 times as many points on the CAD.
        self.fitter.run(tolerance=1e-3, max_level=2)
        nodes = self.fitter.two_sided_distance(2)
        self.assertEqual(nodes["target_points"], len(sphere_target().mesh_nodes))
        dense = self.fitter.two_sided_distance(2, 4)
        self.assertGreater(dense["target_points"], 9 * nodes["target_points"])
        self.fitter.set_options(check_target_subdivisions=4)
        self.assertEqual(self.fitter.options["check_target_subdivisions"], 4)
        self.assertEqual(self.fitter.two_sided_distance(2)["target_points"], dense["target_points"])

    def test_cancel_with_an_event(self):
        stop = threading.Event()
        summary = self.fitter.run(progress=lambda record: stop.set(), cancel=stop)
        self.assertEqual(summary["reason"], "cancelled")
        self.assertEqual(len(summary["history"]), 1)
        self.assertEqual(self.fitter.level, 0)
        # The fitter can go on after a cancel.
        self.assertEqual(self.fitter.run(tolerance=1e-2)["reason"], "converged")

    def test_a_level_beyond_the_control_point_budget_is_not_made(self):
        # The cube's levels have 26, 98 and 386 control points: with 100 allowed the fit stops at
        # level 2 with the reason and the count, and a subdivision by hand is refused the same way.
        summary = self.fitter.run(tolerance=1e-9, max_control_points=100)
        self.assertEqual(summary["reason"], "memory_limit")
        self.assertEqual(self.fitter.level, 2)
        self.assertIn("at level 2: samples up to", summary["detail"])
        self.assertIn("; level 3 would have 386 control points, more than max_control_points (100, the memory budget)",
                      summary["detail"])
        with self.assertRaisesRegex(bvmesh.InvalidInputError, "level 3 would have 386 control points"):
            self.fitter.subdivide()
        self.assertEqual(self.fitter.level, 2)
        self.fitter.set_options(max_control_points=0)  # no limit
        self.fitter.subdivide()
        self.assertEqual(self.fitter.mesh.num_vertices, 386)
        with self.assertRaisesRegex(ValueError, "max_control_points must be 0 .no limit. or more, got -1"):
            self.fitter.set_options(max_control_points=-1)

    def test_options_round_trip(self):
        self.assertTrue(self.fitter.options["reject_opposing_feet"])
        self.fitter.set_options(reject_opposing_feet=False, solver="cholesky", symmetry_plane=((0, 0, 0), (0, 0, 2)))
        options = self.fitter.options
        self.assertFalse(options["reject_opposing_feet"])
        self.assertEqual(options["solver"], "cholesky")
        np.testing.assert_allclose(options["symmetry_plane"][1], [0, 0, 2])

    def test_bad_arguments_name_the_problem(self):
        with self.assertRaisesRegex(ValueError, "unknown fitting option 'tolerence'"):
            self.fitter.set_options(tolerence=1e-3)
        with self.assertRaisesRegex(ValueError, "solver must be"):
            self.fitter.set_options(solver="lu")
        with self.assertRaisesRegex(ValueError, r"vertices must have shape \(n, 3\)"):
            self.fitter.set_vertices(np.zeros((8, 2)))
        with self.assertRaisesRegex(ValueError, "unknown feature-map key"):
            bvmesh.SurfaceFitter(sphere_target(), bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), {"curve": []})
        with self.assertRaisesRegex(ValueError, "tolerance must be a finite number >= 0, got -1"):
            bvmesh.SurfaceFitter(sphere_target(), bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), tolerance=-1.0)
        far = bvmesh.ControlMesh(CUBE_VERTICES + 100.0, CUBE_FACES)
        with self.assertRaisesRegex(bvmesh.InvalidInputError, "far from the target"):
            bvmesh.SurfaceFitter(sphere_target(), far).run()


class GapLeftOpen(unittest.TestCase):
    """A sphere as two hemispherical faces, the upper one moved up by 1e-3 (a gap left open at
    the equator): the fit bridges the gap, with closest points and along the limit normals.
    Along the normals, samples next to the gap were cast through it onto the far side of the
    sphere, and the fit ended in "face 0 is degenerate"; a cast hit more than 4 times farther
    than the closest point now gives way to the closest point."""

    def test_the_fit_bridges_the_gap(self):
        import FreeCAD
        import Part

        gap = 1e-3
        lower = Part.makeSphere(1, FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(0, 0, 1), -90, 0)
        upper = Part.makeSphere(1, FreeCAD.Vector(0, 0, gap), FreeCAD.Vector(0, 0, 1), 0, 90)
        target = bvmesh.Target.from_brep(Part.makeCompound(lower.Faces + upper.Faces).exportBrepToString())
        start = np.array(CUBE_VERTICES, dtype=float) * [1, 1, 1 + gap / 2] + [0, 0, gap / 2]
        for along in (False, True):
            fitter = bvmesh.SurfaceFitter(target, bvmesh.ControlMesh(start, CUBE_FACES), max_level=2, tolerance=1e-5,
                                          project_along_normals=along)
            last = fitter.run()["history"][-1]
            self.assertEqual(last["level"], 2)
            self.assertEqual(last["failed_projections"], 0)
            self.assertLess(last["max_distance"], gap)  # 4.8e-4 and 6.1e-4 measured


if __name__ == "__main__":
    unittest.main()

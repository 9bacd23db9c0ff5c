"""bvmesh.Target from plain /usr/bin/python3: construction from BREP text and files, the report,
projections against FreeCAD's Part.distToShape (BRepExtrema) and closed forms, bad input."""

import math
import os
import sys
import unittest

import numpy as np

import bvmesh

DATA = os.environ.get("BVMESH_TEST_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "data"))
WING = os.path.join(DATA, "AileM6_with_sharp_TE.stp")

try:
    sys.path.append("/usr/lib/freecad-python3/lib")
    import FreeCAD  # noqa: F401
    import Part
except ImportError:  # FreeCAD is optional for the bindings themselves
    Part = None


def near_surface_points(target, count, spread, seed):
    """count points: tessellation nodes moved by up to spread (absolute) in each coordinate."""
    rng = np.random.default_rng(seed)
    nodes = np.asarray(target.mesh_nodes)
    return nodes[rng.integers(0, len(nodes), count)] + rng.uniform(-spread, spread, (count, 3))


class Construction(unittest.TestCase):
    def test_from_file_reports_the_wing(self):
        target = bvmesh.Target.from_file(WING)
        report = target.report()
        self.assertEqual(report["faces"], 11)
        self.assertEqual(report["surface_types"].count("BSplineSurface"), 8)
        self.assertEqual(report["free_edges"], [])
        self.assertEqual(report["gaps"], [])
        self.assertGreater(report["diagonal"], 800.0)
        self.assertGreater(report["triangles"], 100)
        self.assertEqual(sorted(report["sharp_edges"]), sorted(target.sharp_edges(30.0)))
        # The sharp trailing edge is nearly a knife edge; only it passes 150 degrees.
        self.assertEqual(len(target.sharp_edges(150.0)), 1)
        for angle in (float("nan"), -1.0, 181.0):  # NaN gave an empty list, as if nothing were sharp
            with self.assertRaisesRegex(ValueError, "angle_deg must be 0 .. 180, got"):
                target.sharp_edges(angle)

    @unittest.skipIf(Part is None, "FreeCAD is not importable")
    def test_from_freecad_brep_text_equals_from_file(self):
        shape = Part.read(WING)
        from_text = bvmesh.Target.from_brep(shape.exportBrepToString())
        from_file = bvmesh.Target.from_file(WING)
        points = near_surface_points(from_file, 200, 20.0, 1)
        a = from_text.project(points)
        b = from_file.project(points)
        np.testing.assert_allclose(a["distances"], b["distances"], rtol=0, atol=1e-9)

    def test_bad_input_raises_value_errors(self):
        with self.assertRaises(bvmesh.InvalidInputError):
            bvmesh.Target.from_file(os.path.join(DATA, "does-not-exist.stp"))
        with self.assertRaises(ValueError):
            bvmesh.Target.from_brep("")
        if Part is not None:
            with self.assertRaises(bvmesh.TopologyError):  # a shape without faces
                bvmesh.Target.from_brep(Part.makeLine((0, 0, 0), (1, 0, 0)).exportBrepToString())
        target = bvmesh.Target.from_file(WING)
        with self.assertRaises(ValueError):
            target.project(np.zeros((4, 2)))
        with self.assertRaises(ValueError):
            target.project(np.array([[0.0, 0.0, math.nan]]))
        with self.assertRaises(ValueError):
            target.project(np.zeros((2, 3)), hint_faces=np.zeros(3, dtype=np.int32), hint_uv=np.zeros((3, 2)))
        with self.assertRaises(ValueError):
            target.project_to_edges(np.zeros((2, 3)), [10_000])
        with self.assertRaises(ValueError):
            target.project_along(np.zeros((2, 3)), np.zeros((2, 3)))


@unittest.skipIf(Part is None, "FreeCAD is not importable")
class AgainstFreeCAD(unittest.TestCase):
    def test_distances_match_dist_to_shape(self):
        shape = Part.read(WING)
        target = bvmesh.Target.from_brep(shape.exportBrepToString())
        size = target.report()["diagonal"]
        surface = Part.Compound(shape.Faces)  # distToShape measures 0 inside a solid
        points = np.vstack([near_surface_points(target, 100, 0.02 * size, 2),
                            np.random.default_rng(3).uniform(-500, 1500, (50, 3))])
        result = target.project(points)
        self.assertTrue(np.all(result["status"] <= int(bvmesh.ProjectionStatus.ON_TRIM_BOUNDARY)))
        for i, p in enumerate(points):
            reference, _, info = surface.distToShape(Part.Vertex(FreeCAD.Vector(*p)))
            # Nearest point at a vertex or on an edge: the model is defined to that tolerance only
            # (the edge curves and surfaces meet the vertex point within it; BRepExtrema measures
            # to the vertex point, the projection to the curves and surfaces).
            kind, index = info[0][3], info[0][4]
            tolerance = 2 * {"Vertex": lambda: surface.Vertexes[index].Tolerance,
                             "Edge": lambda: surface.Edges[index].Tolerance}.get(kind, lambda: 0.0)()
            self.assertAlmostEqual(result["distances"][i], reference, delta=1e-9 * size + tolerance,
                                   msg="point {} ({})".format(i, kind))
        # Foot points lie on their face's surface.
        for i in range(0, len(points), 10):
            face = shape.Faces[result["faces"][i]]
            u, v = result["params"][i]
            on_surface = face.Surface.value(u, v)
            self.assertLess((on_surface - FreeCAD.Vector(*result["points"][i])).Length, 1e-6 * size)


class Projections(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.target = bvmesh.Target.from_file(WING)
        cls.size = cls.target.report()["diagonal"]

    def test_warm_start_equals_cold_start(self):
        points = near_surface_points(self.target, 2000, 0.01 * self.size, 4)
        previous = self.target.project(points)
        moved = points + np.random.default_rng(5).uniform(-1, 1, points.shape)
        warm = self.target.project(moved, hint_faces=previous["faces"], hint_uv=previous["params"])
        cold = self.target.project(moved)
        np.testing.assert_allclose(warm["distances"], cold["distances"], rtol=0, atol=1e-9 * self.size)
        np.testing.assert_allclose(warm["points"], cold["points"], rtol=0, atol=1e-9 * self.size)
        self.assertTrue(np.all(np.isfinite(warm["points"])))
        self.assertTrue(np.allclose(np.linalg.norm(cold["normals"], axis=1), 1.0))

    def test_result_shapes_and_dtypes(self):
        result = self.target.project(np.zeros((7, 3)))
        self.assertEqual(result["points"].shape, (7, 3))
        self.assertEqual(result["params"].shape, (7, 2))
        self.assertEqual(result["normals"].shape, (7, 3))
        for key in ("distances", "ids", "faces", "status"):
            self.assertEqual(result[key].shape, (7,))
        self.assertEqual(result["status"].dtype, np.uint8)

    def test_no_points_give_empty_results(self):
        none = np.zeros((0, 3))
        results = [self.target.project(none), self.target.project([]),
                   self.target.project(none, hint_faces=np.zeros(0, dtype=np.int32), hint_uv=np.zeros((0, 2))),
                   self.target.project_to_edges(none, self.target.sharp_edges(150.0)),
                   self.target.project_to_free_boundary(none), self.target.project_to_vertex(none, 0),
                   self.target.project_along(none, none)]
        for result in results:
            self.assertEqual(result["points"].shape, (0, 3))
            self.assertEqual(result["params"].shape, (0, 2))
            self.assertEqual(result["normals"].shape, (0, 3))
            for key in ("distances", "ids", "faces", "status"):
                self.assertEqual(result[key].shape, (0,))

    def test_edges_vertices_and_directions(self):
        trailing_edge = self.target.sharp_edges(150.0)
        points = near_surface_points(self.target, 300, 0.02 * self.size, 6)
        on_edge = self.target.project_to_edges(points, trailing_edge)
        on_surface = self.target.project(points)
        # The edge lies on the surface: no point is nearer to the edge than to the surface.
        self.assertTrue(np.all(on_edge["distances"] >= on_surface["distances"] - 1e-9 * self.size))
        self.assertTrue(np.all(on_edge["ids"] == trailing_edge[0]))
        vertex = self.target.project_to_vertex(points, 0)
        expected = np.linalg.norm(points - self.target.vertex_position(0), axis=1)
        np.testing.assert_allclose(vertex["distances"], expected, rtol=1e-15, atol=0)
        # Lines along the surface normal through points off the surface hit it at the foot point.
        feet = on_surface["points"][on_surface["status"] == 0]
        normals = on_surface["normals"][on_surface["status"] == 0]
        offsets = feet + 0.001 * self.size * normals
        along = self.target.project_along(offsets, normals)
        np.testing.assert_allclose(along["distances"], 0.001 * self.size, rtol=0, atol=1e-9 * self.size)


@unittest.skipIf(Part is None, "FreeCAD not available")
class SpherePoles(unittest.TestCase):
    def test_lines_through_a_pole_hit_the_near_pole(self):
        # At the pole the sphere's parametrization degenerates (Su = 0).
        target = bvmesh.Target.from_brep(Part.makeSphere(2, FreeCAD.Vector(1, 2, 3)).exportBrepToString())
        heights = np.array([-1.5, -0.2, 0.5, 1.0, 3.0, 10.0])
        origins = np.column_stack([np.full(len(heights), 1.0), np.full(len(heights), 2.0), 5.0 + heights])
        for direction in ([0, 0, 1.0], [0, 0, -1.0]):
            result = target.project_along(origins, np.tile(direction, (len(heights), 1)))
            np.testing.assert_array_equal(result["status"], 0)
            np.testing.assert_allclose(result["points"], np.tile([1.0, 2.0, 5.0], (len(heights), 1)), rtol=0, atol=1e-12)
            np.testing.assert_allclose(result["distances"], np.abs(heights), rtol=0, atol=1e-12)


if __name__ == "__main__":
    unittest.main()

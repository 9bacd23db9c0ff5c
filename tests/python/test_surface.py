"""limit_surface_to_bsplines from plain /usr/bin/python3: charts, exactness on regular grids,
a sewn solid that FreeCAD's Part module accepts, and clear errors for bad arrays."""

import sys
import unittest

import numpy as np
from scipy.interpolate import BSpline

import bvmesh


def grid(nx, ny, height):
    """(nx x ny)-quad grid over [0, nx] x [0, ny], vertex (i, j) at row i * (ny + 1) + j."""
    i, j = np.meshgrid(np.arange(nx + 1.0), np.arange(ny + 1.0), indexing="ij")
    vertices = np.stack([i, j, height(i, j)], axis=-1).reshape(-1, 3)
    vid = lambda a, b: a * (ny + 1) + b
    faces = [[vid(a, b), vid(a + 1, b), vid(a + 1, b + 1), vid(a, b + 1)] for a in range(nx) for b in range(ny)]
    return vertices, np.array(faces, dtype=np.int64)


def cube_grid(n):
    """The cube [-1, 1]^3 with n x n quads per side, outward oriented: 8 valence-3 corners."""
    index, vertices, faces = {}, [], []

    def vid(p):
        key = tuple(p)
        if key not in index:
            index[key] = len(vertices)
            vertices.append([c / n for c in p])
        return index[key]

    for axis in range(3):
        a, b = (axis + 1) % 3, (axis + 2) % 3
        for sign in (-1, 1):
            for i in range(n):
                for j in range(n):
                    quad = []
                    for ci, cj in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)):
                        p = [0, 0, 0]
                        p[axis], p[a], p[b] = sign * n, -n + 2 * ci, -n + 2 * cj
                        quad.append(vid(p))
                    faces.append(quad if sign > 0 else quad[::-1])
    return np.array(vertices), np.array(faces)


def uniform_bspline_patch(points, u, v):
    """Uniform bicubic B-spline patch of a 4 x 4 x 3 control net at (u, v)."""
    def basis(t):
        return np.array([(1 - t) ** 3, 3 * t ** 3 - 6 * t ** 2 + 4, -3 * t ** 3 + 3 * t ** 2 + 3 * t + 1, t ** 3]) / 6
    return np.einsum("i,j,ijk->k", basis(u), basis(v), points)


def chart_surface(chart):
    """The chart's surface as a scipy BSpline callable (s, t) -> point."""
    knots_u = np.repeat(chart["u_knots"], chart["u_multiplicities"])
    knots_v = np.repeat(chart["v_knots"], chart["v_multiplicities"])
    poles = chart["poles"]

    def evaluate(s, t):
        along_v = BSpline(knots_v, np.moveaxis(poles, 1, 0), 3)(t)  # (n_u, 3)
        return BSpline(knots_u, along_v, 3)(s)
    return evaluate


class LimitSurfaceToBSplines(unittest.TestCase):
    def test_regular_grid_is_one_exact_chart(self):
        nx, ny = 6, 5
        vertices, faces = grid(nx, ny, lambda x, y: 0.3 * np.sin(1.3 * x + 0.4) * np.cos(0.9 * y) + 0.05 * x * y)
        result = bvmesh.limit_surface_to_bsplines(vertices, faces)
        self.assertEqual(len(result["charts"]), 1)
        chart = result["charts"][0]
        self.assertEqual(chart["poles"].shape, (chart["u_cells"] + 3, chart["v_cells"] + 3, 3))
        self.assertEqual(sorted([chart["u_cells"], chart["v_cells"]]), [5, 6])
        self.assertLess(result["max_deviation"], 1e-11)
        # Independent check with scipy: interior faces are uniform bicubic patches of the grid.
        surface = chart_surface(chart)
        net = vertices.reshape(nx + 1, ny + 1, 3)
        corner_uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
        worst = 0.0
        for ci in range(chart["u_cells"]):
            for cj in range(chart["v_cells"]):
                f = chart["faces"][ci, cj]
                i, j = divmod(int(f), ny)
                if not (1 <= i <= nx - 2 and 1 <= j <= ny - 2):
                    continue
                rotation = chart["rotations"][ci, cj]
                for a, b in ((0.2, 0.7), (0.5, 0.5), (0.9, 0.1)):
                    weights = [(1 - a) * (1 - b), a * (1 - b), a * b, (1 - a) * b]
                    u, v = sum(w * corner_uv[(k + rotation) % 4] for k, w in enumerate(weights))
                    expected = uniform_bspline_patch(net[i - 1:i + 3, j - 1:j + 3], u, v)
                    worst = max(worst, np.linalg.norm(surface(ci + a, cj + b) - expected))
        self.assertLess(worst, 1e-11)

    def test_cube_is_a_valid_solid_in_freecad(self):
        vertices, faces = cube_grid(2)
        result = bvmesh.limit_surface_to_bsplines(vertices, faces)
        self.assertEqual(len(result["charts"]), 6)
        self.assertEqual(len(result["segments"]), 12)
        self.assertEqual(len(result["junctions"]), 8)
        # Every face sits in exactly one chart, and face_chart says which.
        for index, chart in enumerate(result["charts"]):
            self.assertTrue(np.all(result["face_chart"][chart["faces"]] == index))
        self.assertEqual(sorted(np.concatenate([c["faces"].ravel() for c in result["charts"]])), list(range(len(faces))))
        self.assertTrue(result["solid"])
        self.assertTrue(result["valid"])
        self.assertEqual(result["free_edges"], 0)
        self.assertLess(result["max_border_gap"], 1e-12)
        # C0 across the cube edges, G1 not enforced: near the valence-3 corners of this coarse,
        # sharply rounded cube the neighbouring normals differ by about 17 degrees.
        self.assertTrue(0.0 < result["max_kink_degrees"] < 25.0)
        for segment in result["segments"]:
            self.assertEqual(len(segment["uses"]), 2)
            self.assertEqual(segment["kind"], "separatrix")
        sys.path.append("/usr/lib/freecad-python3/lib")
        try:
            import FreeCAD  # noqa: F401  (Part crashes when imported before FreeCAD)
            import Part
        except ImportError:
            self.skipTest("FreeCAD's Part module is not available")
        shape = Part.Shape()
        shape.importBrepFromString(result["brep"])
        self.assertEqual(shape.ShapeType, "Solid")
        self.assertTrue(shape.isValid())
        self.assertEqual(len(shape.Faces), 6)
        self.assertTrue(0.5 < shape.Volume < 8.0)

    def test_control_mesh_input(self):
        vertices, faces = cube_grid(2)
        mesh = bvmesh.ControlMesh(vertices, faces.tolist())
        from_mesh = bvmesh.limit_surface_to_bsplines(mesh, sew=False)
        from_arrays = bvmesh.limit_surface_to_bsplines(vertices, faces, sew=False)
        self.assertEqual(len(from_mesh["charts"]), 6)
        for a, b in zip(from_mesh["charts"], from_arrays["charts"]):
            np.testing.assert_array_equal(a["poles"], b["poles"])
        triangles = bvmesh.ControlMesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]])
        with self.assertRaisesRegex(ValueError, "needs quads"):
            bvmesh.limit_surface_to_bsplines(triangles)

    def test_subdivided_icosahedron_is_a_solid_of_one_chart_per_quad(self):
        # One subdivision of the icosahedron: its 12 vertices have valence 5, the 20 triangle
        # centres valence 3. Every quad has one of each at opposite corners and its four edges
        # lie on separatrices between them, so each of the 60 quads is a 1 x 1 chart.
        t = (1 + 5 ** 0.5) / 2
        vertices = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
                             [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]])
        triangles = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                     [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                     [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
        mesh = bvmesh.ControlMesh(vertices, triangles).subdivide()
        result = bvmesh.limit_surface_to_bsplines(mesh)
        self.assertEqual(len(result["charts"]), 60)
        self.assertTrue(all(c["u_cells"] == 1 and c["v_cells"] == 1 for c in result["charts"]))
        self.assertEqual(len(result["junctions"]), 32)
        self.assertTrue(result["solid"])
        self.assertTrue(result["valid"])
        self.assertEqual(result["free_edges"], 0)
        self.assertLess(result["max_border_gap"], 1e-12)
        self.assertLess(result["max_deviation"], 0.01 * 2 * np.linalg.norm(vertices[0]))

    def test_creases_split_charts(self):
        vertices, faces = grid(4, 3, lambda x, y: 0.1 * x * y)
        creases = np.array([[8, 9], [9, 10], [10, 11]])  # the line x = 2
        result = bvmesh.limit_surface_to_bsplines(vertices, faces, creases=creases, sew=False)
        self.assertEqual(len(result["charts"]), 2)
        self.assertNotIn("brep", result)
        kinds = sorted(segment["kind"] for segment in result["segments"])
        self.assertEqual(kinds.count("crease"), 1)
        self.assertLess(result["max_deviation"], 1e-11)

    def test_bad_arrays_raise_value_errors(self):
        vertices, faces = grid(2, 2, lambda x, y: 0 * x)
        with self.assertRaisesRegex(ValueError, "quads"):
            bvmesh.limit_surface_to_bsplines(vertices, faces[:, :3])
        with self.assertRaisesRegex(ValueError, "quads"):
            bvmesh.limit_surface_to_bsplines(vertices, np.array([[0, 1, 4, 3], [1, 2, 5, 4, 7]], dtype=object))
        with self.assertRaisesRegex(ValueError, "quads"):
            bvmesh.limit_surface_to_bsplines(vertices, [[0, 1, 4, 3], [1, 2, 5]])
        with self.assertRaisesRegex(ValueError, r"vertices must have shape \(#V, 3\)"):
            bvmesh.limit_surface_to_bsplines(vertices[:, :2], faces)
        bad = vertices.copy()
        bad[4, 2] = np.nan
        with self.assertRaisesRegex(bvmesh.InvalidInputError, r"vertex 4 has a non-finite coordinate \(1, 1, nan\)"):
            bvmesh.limit_surface_to_bsplines(bad, faces)
        with self.assertRaisesRegex(ValueError, "integers"):
            bvmesh.limit_surface_to_bsplines(vertices, faces.astype(float))
        out_of_range = faces.copy()
        out_of_range[2, 1] = 42
        with self.assertRaisesRegex(bvmesh.InvalidInputError, "face 2 refers to vertex 42"):
            bvmesh.limit_surface_to_bsplines(vertices, out_of_range)
        with self.assertRaisesRegex(ValueError, r"creases must have shape \(#C, 2\)"):
            bvmesh.limit_surface_to_bsplines(vertices, faces, creases=np.array([0, 1, 2]))
        with self.assertRaisesRegex(bvmesh.TopologyError, "not an edge"):
            bvmesh.limit_surface_to_bsplines(vertices, faces, creases=np.array([[0, 4]]))
        with self.assertRaises(bvmesh.InvalidInputError):
            bvmesh.limit_surface_to_bsplines(vertices, faces, corners=np.array([99]))


if __name__ == "__main__":
    unittest.main()

"""Control meshes, subdivision and limit samples through the Python API."""

import os
import tempfile
import unittest

import numpy as np
import scipy.sparse

import bvmesh

CUBE_VERTICES = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
CUBE_FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
TOP_LOOP = [[4, 5], [5, 6], [6, 7], [7, 4]]


def output_dir():
    path = os.environ.get("BVMESH_TEST_OUTPUT_DIR") or tempfile.mkdtemp()
    os.makedirs(path, exist_ok=True)
    return path


class ControlMeshTest(unittest.TestCase):
    def test_faces_as_lists_or_flat_arrays(self):
        mesh = bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES, creases=TOP_LOOP, corners=[0])
        sizes = np.full(6, 4)
        flat = bvmesh.ControlMesh(CUBE_VERTICES, (sizes, np.concatenate(CUBE_FACES)))
        self.assertEqual(mesh.faces, CUBE_FACES)
        np.testing.assert_array_equal(mesh.edges, flat.edges)
        self.assertEqual((mesh.num_vertices, mesh.num_faces, mesh.num_edges), (8, 6, 12))
        self.assertEqual(mesh.creases.shape, (4, 2))
        self.assertTrue(np.all(np.isinf(mesh.crease_sharpness)))
        np.testing.assert_array_equal(mesh.corners, [0])
        self.assertEqual(mesh.boundary_edges.shape, (0, 2))

    def test_semi_sharp_creases_and_boundaries(self):
        grid = np.array([[i, j, 0.0] for j in range(3) for i in range(3)])
        faces = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]]
        mesh = bvmesh.ControlMesh(grid, faces, creases=np.array([[1, 4], [4, 7]]), crease_sharpness=[2.0, 0.5])
        np.testing.assert_array_equal(mesh.crease_sharpness, [2.0, 0.5])
        rows = bvmesh.ControlMesh(grid, faces, creases=[[1, 4, 2.0], [4, 7, np.inf]])
        np.testing.assert_array_equal(rows.creases, [[1, 4], [4, 7]])
        np.testing.assert_array_equal(rows.crease_sharpness, [2.0, np.inf])
        self.assertEqual(len(mesh.boundary_edges), 8)
        self.assertEqual(len(mesh.boundary_edge_ids), 8)

    def test_assigning_vertices_keeps_topology(self):
        mesh = bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES)
        mesh.vertices = CUBE_VERTICES * 2
        np.testing.assert_array_equal(mesh.vertices, CUBE_VERTICES * 2)
        with self.assertRaises(ValueError):
            mesh.vertices = CUBE_VERTICES[:3]

    def test_invalid_meshes_raise_the_right_error(self):
        cases = [
            (bvmesh.InvalidInputError, "vertex 2 has a non-finite", dict(vertices=np.where(np.arange(24).reshape(8, 3) == 7, np.nan, CUBE_VERTICES))),
            (bvmesh.InvalidInputError, "face 0 refers to vertex 9", dict(faces=[[0, 3, 2, 9]] + CUBE_FACES[1:])),
            (bvmesh.TopologyError, "face 0 repeats vertex 0", dict(faces=[[0, 3, 0, 1]] + CUBE_FACES[1:])),
            (bvmesh.TopologyError, "inconsistently oriented", dict(faces=[[0, 1, 2, 3]] + CUBE_FACES[1:])),
            (bvmesh.TopologyError, "is not an edge", dict(creases=[[0, 6]])),
            (bvmesh.InvalidInputError, "is listed twice", dict(corners=[1, 1])),
            (bvmesh.InvalidInputError, "face 0 is degenerate", dict(vertices=np.vstack([CUBE_VERTICES[:3], CUBE_VERTICES[2:3], CUBE_VERTICES[4:]]))),
        ]
        for error, text, change in cases:
            arguments = dict(vertices=CUBE_VERTICES, faces=CUBE_FACES)
            arguments.update(change)
            with self.subTest(text=text):
                with self.assertRaises(error) as caught:
                    bvmesh.ControlMesh(**arguments)
                self.assertIn(text, str(caught.exception))
                self.assertIsInstance(caught.exception, ValueError)
                if error is bvmesh.InvalidInputError:
                    self.assertNotIsInstance(caught.exception, bvmesh.TopologyError)
        fin = [[0, 1, 3, 2], [1, 0, 4, 5], [0, 1, 5, 4]]
        with self.assertRaisesRegex(bvmesh.TopologyError, "more than two faces"):
            bvmesh.ControlMesh(np.random.default_rng(1).random((6, 3)), fin)
        with self.assertRaisesRegex(ValueError, r"shape \(n, 3\)"):
            bvmesh.ControlMesh(CUBE_VERTICES[:, :2], CUBE_FACES)
        with self.assertRaisesRegex(ValueError, r"creases must have shape \(k, 2\) or \(k, 3\)"):
            bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES, creases=[0, 1, 2])


class SubdivisionTest(unittest.TestCase):
    def test_counts_operator_and_creases(self):
        mesh = bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES, creases=TOP_LOOP)
        child, operator = mesh.subdivide(return_operator=True)
        self.assertIsInstance(operator, scipy.sparse.csr_matrix)
        self.assertEqual(operator.shape, (26, 8))
        np.testing.assert_allclose(operator @ mesh.vertices, child.vertices, atol=1e-14)
        self.assertEqual((child.num_vertices, child.num_faces, child.num_edges), (8 + 12 + 6, 24, 2 * 12 + 24))
        self.assertTrue(child.is_all_quads)
        self.assertEqual(len(child.creases), 8)
        # Face point = centroid of the face (rule 3.1): face 0 is the bottom.
        np.testing.assert_allclose(child.vertices[8 + 12 + 0], CUBE_VERTICES[[0, 3, 2, 1]].mean(axis=0))
        # A crease vertex moves by (p_left + 6 p + p_right) / 8 (rule 3.5).
        np.testing.assert_allclose(child.vertices[4], (CUBE_VERTICES[5] + 6 * CUBE_VERTICES[4] + CUBE_VERTICES[7]) / 8)

    def test_options(self):
        grid = np.array([[i, j, 0.0] for j in range(2) for i in range(2)])
        mesh = bvmesh.ControlMesh(grid, [[0, 1, 3, 2]])
        np.testing.assert_array_equal(mesh.subdivide().vertices[0], grid[0])
        options = bvmesh.SubdivisionOptions(boundary=bvmesh.SubdivisionOptions.Boundary.EDGE_ONLY)
        self.assertFalse(np.allclose(mesh.subdivide(options).vertices[0], grid[0]))


class LimitSamplesTest(unittest.TestCase):
    def setUp(self):
        rng = np.random.default_rng(5)
        self.mesh = bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES).subdivide()
        self.mesh.vertices = self.mesh.vertices + 0.05 * rng.standard_normal((26, 3))
        self.samples = self.mesh.limit_samples()

    def test_layout_and_operator(self):
        s, m = self.samples, self.mesh
        count = m.num_vertices + m.num_edges + m.num_faces
        self.assertEqual(len(s), count)
        self.assertEqual(s.positions.shape, (count, 3))
        self.assertEqual(s.normals.shape, (count, 3))
        self.assertEqual(s.operator.shape, (count, m.num_vertices))
        np.testing.assert_allclose(s.operator @ m.vertices, s.positions, atol=1e-14)
        np.testing.assert_array_equal(s.elements[: m.num_vertices], int(bvmesh.SampleElement.VERTEX))
        np.testing.assert_array_equal(s.elements[-m.num_faces:], int(bvmesh.SampleElement.FACE))
        np.testing.assert_array_equal(s.source_vertices[m.num_vertices: m.num_vertices + m.num_edges], m.edges)
        np.testing.assert_allclose(np.linalg.norm(s.normals, axis=1), 1.0)
        moved = m.vertices * 1.5
        np.testing.assert_allclose(s.positions_for(moved), 1.5 * s.positions, atol=1e-14)
        t1, t2 = s.tangent_operators
        n = np.cross(t1 @ moved, t2 @ moved)
        np.testing.assert_allclose(n / np.linalg.norm(n, axis=1)[:, None], s.normals_for(moved), atol=1e-12)

    def test_closed_form_at_extraordinary_vertex(self):
        # Vertex 0 of the subdivided cube has valence 3.
        m, p = self.mesh, self.mesh.vertices
        neighbours = [b if a == 0 else a for a, b in m.edges if 0 in (a, b)]
        diagonals = [f[(f.index(0) + 2) % 4] for f in m.faces if 0 in f]
        n = len(neighbours)
        expected = (n * n * p[0] + 4 * p[neighbours].sum(axis=0) + p[diagonals].sum(axis=0)) / (n * (n + 5))
        np.testing.assert_allclose(self.samples.positions[0], expected, atol=1e-12)

    def test_evaluate_matches_samples_and_broadcasts(self):
        s = self.samples
        positions, du, dv, normals = self.mesh.evaluate(s.location_faces, s.location_uv[:, 0], s.location_uv[:, 1])
        np.testing.assert_allclose(positions, s.positions, atol=1e-12)
        np.testing.assert_allclose(self.mesh.evaluate(*s.locations)[0], s.positions, atol=1e-12)
        positions, du, dv, normals = self.mesh.evaluate(3, [0.1, 0.5, 0.9], 0.25)
        self.assertEqual(positions.shape, (3, 3))
        evaluator = bvmesh.LimitEvaluator(self.mesh, isolation_level=8)
        again = evaluator.evaluate(self.mesh.vertices, 3, [0.1, 0.5, 0.9], 0.25)
        np.testing.assert_allclose(again[0], positions, atol=1e-12)
        with self.assertRaises(bvmesh.InvalidInputError):
            self.mesh.evaluate(0, 1.5, 0.5)
        with self.assertRaises(ValueError):
            self.mesh.evaluate([0, 1], [0.1, 0.2, 0.3], 0.5)

    def test_sharp_crease_and_features(self):
        mesh = bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES, creases=TOP_LOOP)
        samples = mesh.limit_samples()
        features = samples.features
        self.assertTrue(np.all(features[4:8] == int(bvmesh.SampleFeature.CREASE)))
        self.assertTrue(np.all(features[0:4] == int(bvmesh.SampleFeature.SMOOTH)))
        # Edge (4, 5) from the top face (1: v = 0) and from the side face (2: v = 1).
        _, _, _, normals = mesh.evaluate([1, 2], [0.5, 0.5], [0.0, 1.0])
        self.assertLess(np.dot(normals[0], normals[1]), 0.5)


class MeshFilesTest(unittest.TestCase):
    def test_round_trip_and_errors(self):
        mesh = bvmesh.ControlMesh(CUBE_VERTICES + 0.1234567890123, CUBE_FACES, creases=TOP_LOOP,
                                  crease_sharpness=[np.inf, 2.5, np.inf, 0.5], corners=[0])
        for name in ("py_cube.cmesh", "py_cube.obj"):
            path = os.path.join(output_dir(), name)
            mesh.write(path)
            back = bvmesh.read_control_mesh(path)
            np.testing.assert_array_equal(back.vertices, mesh.vertices)
            self.assertEqual(back.faces, mesh.faces)
            np.testing.assert_array_equal(back.creases, mesh.creases)
            np.testing.assert_array_equal(back.crease_sharpness, mesh.crease_sharpness)
            np.testing.assert_array_equal(back.corners, mesh.corners)
        bad = os.path.join(output_dir(), "py_bad.obj")
        with open(bad, "w") as stream:
            stream.write("v 0 0 0\nv 1 0 zero\n")
        with self.assertRaisesRegex(bvmesh.InvalidInputError, "py_bad.obj line 2: 'zero' is not a number"):
            bvmesh.read_control_mesh(bad)


if __name__ == "__main__":
    unittest.main()

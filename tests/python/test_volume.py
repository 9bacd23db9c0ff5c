"""bvmesh.volume from Python: the volume mesh around a fitted sphere against the sphere's closed
forms, the blocks as arrays, the block file, and errors that name the problem."""

import os
import tempfile
import unittest

import numpy as np

import FreeCAD  # noqa: F401  -- Part needs it loaded first
import Part

import bvmesh
import bvmesh.volume

A = 1.0 / np.sqrt(3.0)
CUBE_VERTICES = A * np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                              [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
CUBE_FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]


def greville(knots):
    knots = np.asarray(knots)
    return np.array([knots[i + 1:i + 4].mean() for i in range(len(knots) - 4)])


class SphereVolume(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        target = bvmesh.Target.from_brep(Part.makeSphere(1.0).exportBrepToString())
        cls.fitter = bvmesh.SurfaceFitter(target, bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), max_level=4,
                                          tolerance=1e-9)
        cls.fitter.run()
        cls.result = bvmesh.volume.offset_and_farfield(cls.fitter, boundary_layer_thickness=0.05,
                                                       boundary_layer_layers=4, farfield_distance=20.0)

    def test_layers_are_concentric_spheres(self):
        result, blocks = self.result, self.result.blocks
        distances = np.asarray(result.layer_distance)
        self.assertAlmostEqual(distances[4], 0.05, places=12)
        w_layers = distances / distances[-1]
        for b in range(blocks.block_count):
            u, v, w = blocks.knots(b)
            # At the Greville points the blocks interpolate the marched layers: in the boundary layer
            # (straight lines along the wall normals) each layer's radius is the wall's plus d_k, to
            # 1e-6 relative; the wall itself is the fitted sphere (its charts within 2e-5 of it at
            # level 4, most of that next to the extraordinary vertices); the far field at w = 1.
            grid = blocks.evaluate_grid(b, greville(u), greville(v), w_layers[:5])
            radii = np.linalg.norm(grid, axis=3)
            np.testing.assert_allclose(radii[:, :, 0], 1.0, rtol=2e-5)
            for k in range(1, 5):
                np.testing.assert_allclose(radii[:, :, k] - radii[:, :, 0], distances[k], rtol=1e-6)
            outer = np.linalg.norm(blocks.evaluate_grid(b, greville(u), greville(v), [1.0]), axis=3)
            np.testing.assert_allclose(outer, 20.0, rtol=1e-12)

    def test_wall_orthogonality_and_positive_jacobians(self):
        blocks = self.result.blocks
        worst = 1.0
        angles = []
        for b in range(blocks.block_count):
            u, v, w = (np.unique(k) for k in blocks.knots(b))
            at = [np.concatenate([np.linspace(k[i], k[i + 1], 4, endpoint=False) for i in range(len(k) - 1)] + [k[-1:]])
                  for k in (u, v, w)]
            x, du, dv, dw = blocks.evaluate_grid(b, *at, derivatives=True)
            normal = np.cross(du, dv)
            det = np.einsum("...i,...i", normal, dw)
            scaled = det / (np.linalg.norm(du, axis=3) * np.linalg.norm(dv, axis=3) * np.linalg.norm(dw, axis=3))
            worst = min(worst, scaled.min())
            cosine = np.einsum("...i,...i", normal[:, :, 0], dw[:, :, 0]) / (
                np.linalg.norm(normal[:, :, 0], axis=2) * np.linalg.norm(dw[:, :, 0], axis=2))
            angles.extend(np.degrees(np.arccos(np.clip(cosine, -1, 1))).ravel())
        self.assertGreater(worst, 0.3)
        self.assertLess(np.percentile(angles, 99), 2.0)

    def test_arrays_and_block_file(self):
        blocks = self.result.blocks
        poles = blocks.poles(0)
        u, v, w = blocks.knots(0)
        self.assertEqual(poles.shape, (len(u) - 4, len(v) - 4, len(w) - 4, 3))
        self.assertEqual(blocks.degrees(0), (3, 3, 3))
        faces = blocks.faces(0)
        self.assertEqual(faces["w_min"]["condition"], "wall")
        self.assertEqual(faces["w_max"]["condition"], "farfield")
        self.assertEqual(faces["u_min"]["condition"], "connected")
        control = blocks.control_mesh()
        self.assertEqual(control["cells"].shape[1], 8)
        self.assertEqual(sorted(set(control["boundary_conditions"])), ["farfield", "wall"])
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "sphere.blocks")
            blocks.write(path)
            back = bvmesh.read_block_mesh(path)
            self.assertEqual(back.block_count, blocks.block_count)
            np.testing.assert_array_equal(back.poles(3), blocks.poles(3))
            with open(path) as handle:
                text = handle.read()
            with open(path, "w") as handle:
                handle.write(text[: len(text) // 3])
            with self.assertRaisesRegex(ValueError, "sphere.blocks"):
                bvmesh.read_block_mesh(path)
            with self.assertRaisesRegex(ValueError, "cannot write"):
                blocks.write(os.path.join(folder, "missing", "x.blocks"))

    def test_bad_input_names_the_problem(self):
        with self.assertRaisesRegex(ValueError, "far-field distance"):
            bvmesh.volume.offset_and_farfield(self.fitter, boundary_layer_thickness=0.05, farfield_distance=0.01)
        with self.assertRaisesRegex(ValueError, "boundary-layer growth"):
            bvmesh.volume.offset_and_farfield(self.fitter, boundary_layer_growth=0.5)
        with self.assertRaisesRegex(ValueError, "symmetry_plane"):
            bvmesh.volume.offset_and_farfield(self.fitter, symmetry_plane=(0, 1, 2))
        with self.assertRaises(TypeError):
            bvmesh.volume.offset_and_farfield("sphere")
        with self.assertRaises(IndexError):
            self.result.blocks.poles(99)
        with self.assertRaisesRegex(ValueError, "outside the knot range"):
            self.result.blocks.evaluate(0, [[0.0, 0.0, 2.0]])
        inward = bvmesh.ControlMesh(CUBE_VERTICES, [list(reversed(f)) for f in CUBE_FACES])
        with self.assertRaisesRegex(ValueError, "oriented inwards"):
            bvmesh.volume.offset_and_farfield(inward, boundary_layer_thickness=0.05)


if __name__ == "__main__":
    unittest.main()

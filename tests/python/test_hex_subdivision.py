"""Volumetric Catmull-Clark from Python: the volume mesh around a fitted sphere refined by
subdivision into a grid that quality, checkMesh and VTK accept, the operator against the points it
maps, the wall fitted again after a volume step, the M6 volume refined without an inverted cell,
the raw hex mesh interface on a hand-made mesh, and errors that name the problem."""

import os
import tempfile
import unittest

import numpy as np

import bvmesh
import bvmesh.grid
import bvmesh.volume
from fixtures import CUBE_FACES, CUBE_VERTICES, check_mesh, failed_checks, sphere_target, sphere_volume



def two_cubes():
    """Two unit cubes along x: wall at z = 0, far field elsewhere."""
    points = np.array([[i, j, k] for k in range(2) for j in range(2) for i in range(3)], dtype=float)

    def at(i, j, k):
        return i + 3 * j + 6 * k

    cells = [[at(i, 0, 0), at(i + 1, 0, 0), at(i + 1, 1, 0), at(i, 1, 0),
              at(i, 0, 1), at(i + 1, 0, 1), at(i + 1, 1, 1), at(i, 1, 1)] for i in range(2)]
    faces, conditions = [], []
    for i in range(2):
        for quad, condition in (([at(i, 0, 0), at(i + 1, 0, 0), at(i + 1, 1, 0), at(i, 1, 0)], "wall"),
                                ([at(i, 0, 1), at(i + 1, 0, 1), at(i + 1, 1, 1), at(i, 1, 1)], "farfield"),
                                ([at(i, 0, 0), at(i + 1, 0, 0), at(i + 1, 0, 1), at(i, 0, 1)], "farfield"),
                                ([at(i, 1, 0), at(i + 1, 1, 0), at(i + 1, 1, 1), at(i, 1, 1)], "farfield")):
            faces.append(quad)
            conditions.append(condition)
    for i in (0, 2):
        faces.append([at(i, 0, 0), at(i, 1, 0), at(i, 1, 1), at(i, 0, 1)])
        conditions.append("farfield")
    return dict(points=points, cells=np.array(cells), boundary_faces=np.array(faces), boundary_conditions=conditions)


def wall_deviation(grid):
    """Largest distance of the grid's wall points (w = 0 for these blocks) from the unit sphere."""
    return max(np.abs(np.linalg.norm(grid.points(b)[:, :, 0, :], axis=-1) - 1.0).max()
               for b in range(grid.block_count))


class SphereSubdivision(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.target, cls.fitter, cls.volume = sphere_volume(2)
        cls.grids = {k: bvmesh.grid.refine(cls.volume, method="subdivision", steps=k) for k in (1, 2)}
        cls.folder = tempfile.TemporaryDirectory()

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    def test_blocks_keep_their_structure_and_every_cell_is_positive(self):
        blocks = self.volume.blocks
        for steps, grid in self.grids.items():
            self.assertEqual(grid.block_count, blocks.block_count)
            for b in range(blocks.block_count):
                poles = blocks.poles(b).shape[:3]
                self.assertEqual(grid.size(b), tuple(2 ** steps * (n - 1) + 1 for n in poles))
                self.assertEqual(grid.faces(b), blocks.faces(b))
            report = bvmesh.grid.quality(grid)
            self.assertGreater(report["summary"]["scaled_jacobian"]["min"], 0.3, steps)

    def test_grid_points_are_the_subdivided_control_mesh(self):
        refined = bvmesh.volume.subdivide(self.volume, steps=2)
        merged = self.grids[2].merged_points()
        self.assertEqual(len(merged), len(refined["points"]))
        # Same points, in another order: compare sorted rows.
        order = np.lexsort(merged.T)
        theirs = np.lexsort(refined["points"].T)
        np.testing.assert_array_equal(merged[order], refined["points"][theirs])
        control = bvmesh._core.hex_mesh_of_blocks(self.volume.blocks)
        np.testing.assert_allclose(refined["operator"] @ control["points"], refined["points"], rtol=0, atol=1e-12)

    def test_wall_approaches_the_limit_but_is_not_the_fitted_surface(self):
        # The control points converge to the Catmull-Clark limit of the wall's B-spline nets, which
        # treats their clamped ends as uniform: closer at every step, but not the chart surfaces
        # that the B-spline evaluation reproduces (docs/volume.md).
        deviations = [wall_deviation(self.grids[k]) for k in (1, 2)]
        self.assertLess(deviations[1], deviations[0])
        bspline = bvmesh.grid.refine(self.volume, "euler", edge_points=9, normal_points=17)
        self.assertLess(wall_deviation(bspline.grid), deviations[1] / 10)

    def test_fitting_goes_on_after_the_volume_exists(self):
        # One volume step with 3 passes on the wall: closer to the sphere than the level-2 surface
        # fit the volume was made from, the interior still valid.
        fitted = bvmesh.volume.fit_on_volume(self.volume, self.target, passes=3, tolerance=1e-9,
                                             check_samples_per_face=0)
        surface = self.fitter.record(False)["max_distance"]
        self.assertLess(fitted["wall"]["max_distance"], surface / 2)
        self.assertEqual(fitted["wall"]["failed_projections"], 0)
        self.assertGreater(fitted["min_scaled_jacobian"], 0.3)
        refined = bvmesh.volume.subdivide(self.volume)
        self.assertEqual(len(fitted["points"]), len(refined["points"]))
        np.testing.assert_array_equal(fitted["cells"], refined["cells"])
        # The wall moved, the far field did not.
        wall = np.unique(fitted["boundary_faces"][[c == "wall" for c in fitted["boundary_conditions"]]])
        far = np.unique(fitted["boundary_faces"][[c == "farfield" for c in fitted["boundary_conditions"]]])
        self.assertGreater(np.abs(fitted["points"][wall] - refined["points"][wall]).max(), 1e-4)
        np.testing.assert_array_equal(fitted["points"][far], refined["points"][far])

    def test_checkmesh_fails_only_on_the_thin_wall_cells(self):
        case = os.path.join(self.folder.name, "subdivided")
        bvmesh.grid.write_openfoam(self.grids[1], case)
        output = check_mesh(case)
        failed = failed_checks(output)
        # The boundary-layer control cells are 20 to 1 flat; checkMesh calls their determinant small.
        self.assertTrue(all("small determinant" in line for line in failed), failed)
        self.assertIn("cells:", output)

    def test_vtk_multiblock_and_hex_vtk_load(self):
        import vtk

        path = os.path.join(self.folder.name, "subdivided.vtm")
        bvmesh.grid.write_vtk(self.grids[1], path)
        reader = vtk.vtkXMLMultiBlockDataReader()
        reader.SetFileName(path)
        reader.Update()
        self.assertEqual(sum(reader.GetOutput().GetBlock(b).GetNumberOfCells()
                             for b in range(self.grids[1].block_count)), self.grids[1].cell_count)

        mesh = bvmesh.volume.subdivide(two_cubes(), steps=2)
        hex_path = bvmesh.volume.write_hex_vtk(mesh, os.path.join(self.folder.name, "cubes.vtk"))
        hex_reader = vtk.vtkUnstructuredGridReader()
        hex_reader.SetFileName(hex_path)
        hex_reader.Update()
        data = hex_reader.GetOutput()
        self.assertEqual(data.GetNumberOfCells(), 2 * 64)
        self.assertEqual(data.GetNumberOfPoints(), len(mesh["points"]))
        self.assertEqual(data.GetCellType(0), vtk.VTK_HEXAHEDRON)
        quality = vtk.vtkMeshQuality()
        quality.SetInputData(data)
        quality.SetHexQualityMeasureToScaledJacobian()
        quality.Update()
        from vtk.util.numpy_support import vtk_to_numpy
        jacobians = vtk_to_numpy(quality.GetOutput().GetCellData().GetArray("Quality"))
        self.assertGreater(jacobians.min(), 0.0)


class M6Subdivision(unittest.TestCase):
    """The M6 volume at level 2 refined by one subdivision step. Its B-spline evaluation has
    inverted samples at the tip's trailing-edge corner (docs/volume.md); the control mesh refined
    by subdivision has none."""

    def test_every_cell_is_positive(self):
        from test_volume import fit_m6

        fitter, _ = fit_m6(level=2)
        volume = bvmesh.volume.offset_and_farfield(fitter, reference_length=805.0)
        grid = bvmesh.grid.refine(volume, method="subdivision", steps=1)
        self.assertEqual(grid.block_count, 24)
        self.assertEqual(grid.cell_count, 8 * len(bvmesh._core.hex_mesh_of_blocks(volume.blocks)["cells"]))
        self.assertGreater(bvmesh.grid.quality(grid)["summary"]["scaled_jacobian"]["min"], 0.0)

    def test_fitting_goes_on_from_the_control_volume(self):
        # The control volume keeps the trailing edge's and the tip's creases and corners, so one
        # volume step fits the wall as the surface fit's level 3 does, and no cell turns over.
        from test_volume import fit_m6, m6_wing

        fitter, _ = fit_m6(level=2)
        volume = bvmesh.volume.control_volume(fitter, reference_length=805.0)
        self.assertEqual(len(volume.hex_mesh()["creases"]), len(fitter.mesh.creases))
        fitted = bvmesh.volume.fit_on_volume(volume, m6_wing()[0], passes=3,
                                             symmetry_plane=fitter.options["symmetry_plane"],
                                             tolerance=1e-5 * 805.0, check_samples_per_face=0)
        level3, _ = fit_m6(level=3)
        self.assertLess(fitted["wall"]["max_distance"], 1.01 * level3.record(False)["max_distance"])
        self.assertGreater(fitted["min_scaled_jacobian"], 0.0)


class ControlVolumeOfTheSphereFit(unittest.TestCase):
    """The volume control mesh marched from the level-2 sphere fit's own control mesh: its wall
    refines exactly as the surface fit does, so fitting goes on from it as the surface fit would,
    and its grid's wall points lie on the fitted limit surface."""

    @classmethod
    def setUpClass(cls):
        cls.target = sphere_target()
        cls.fitter = bvmesh.SurfaceFitter(cls.target, bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), max_level=2,
                                          tolerance=1e-9, check_samples_per_face=0)
        cls.fitter.run()
        cls.volume = bvmesh.volume.control_volume(cls.fitter, boundary_layer_thickness=0.05, farfield_distance=20.0,
                                                  reference_length=1.0)

    def test_wall_refines_as_the_surface_fit(self):
        refined = bvmesh.volume.subdivide(self.volume, steps=2)
        wall = np.unique(refined["boundary_faces"][[c == "wall" for c in refined["boundary_conditions"]]])
        surface = np.asarray(self.fitter.mesh.subdivide().subdivide().vertices)
        self.assertEqual(len(wall), len(surface))
        tree_distance = np.array([np.linalg.norm(surface - p, axis=1).min() for p in refined["points"][wall]])
        self.assertLess(tree_distance.max(), 1e-13)
        # The B-spline blocks' control mesh does not: its wall nets are the charts' clamped nets.
        blocks = bvmesh.volume.subdivide(bvmesh.volume.offset_and_farfield(
            self.fitter, boundary_layer_thickness=0.05, farfield_distance=20.0, reference_length=1.0), steps=2)
        block_wall = np.unique(blocks["boundary_faces"][[c == "wall" for c in blocks["boundary_conditions"]]])
        self.assertGreater(np.abs(np.linalg.norm(blocks["points"][block_wall], axis=1) - 1.0).max(), 1e-3)

    def test_fitting_goes_on_as_the_surface_fit_would(self):
        fitted = bvmesh.volume.fit_on_volume(self.volume, self.target, passes=3, tolerance=1e-9,
                                             check_samples_per_face=0)
        level3 = bvmesh.SurfaceFitter(self.target, bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), max_level=3,
                                      tolerance=1e-9, check_samples_per_face=0)
        level3.run()
        surface = level3.record(False)["max_distance"]
        self.assertLess(fitted["wall"]["max_distance"], 1.02 * surface)
        self.assertGreater(fitted["min_scaled_jacobian"], 0.5)

    def test_grid_wall_lies_on_the_fitted_surface(self):
        grid = bvmesh.grid.refine(self.volume, method="subdivision", steps=1)
        self.assertEqual(grid.block_count, self.volume.block_count)
        self.assertEqual(grid.cell_count, 8 * self.volume.cell_count)
        wall = np.concatenate([grid.points(b)[:, :, 0, :].reshape(-1, 3) for b in range(grid.block_count)])
        # The grid's wall points are the limit points at the fit's vertices, edge midpoints and face
        # centres: its samples, whose largest distance from the sphere the fit reports.
        self.assertAlmostEqual(np.abs(np.linalg.norm(wall, axis=1) - 1.0).max(),
                               self.fitter.record(False)["max_distance"], delta=1e-12)
        report = bvmesh.grid.quality(grid)
        self.assertGreater(report["summary"]["scaled_jacobian"]["min"], 0.5)
        # The first grid lines leave the wall along the marching directions (here the normals):
        # left to the interior rules they lean by up to 10 degrees.
        self.assertLess(report["summary"]["wall_angle"]["max"], 1.0)

    def test_errors_name_the_problem(self):
        with self.assertRaisesRegex(TypeError, "control_volume takes a bvmesh.SurfaceFitter or a bvmesh.ControlMesh"):
            bvmesh.volume.control_volume(self.volume)
        with self.assertRaisesRegex(bvmesh.InvalidInputError, "far-field distance 0.01 is not beyond"):
            bvmesh.volume.control_volume(self.fitter, boundary_layer_thickness=0.05, farfield_distance=0.01)
        with self.assertRaisesRegex(bvmesh.InvalidInputError, "knife_edge_fans is an option of generate_volume_mesh"):
            bvmesh.volume.control_volume(self.fitter, knife_edge_fans=True)


class HexMeshInterface(unittest.TestCase):
    def test_one_step_counts_and_operator(self):
        mesh = two_cubes()
        refined = bvmesh.volume.subdivide(mesh)
        # 12 points, 20 edges, 11 faces, 2 cells.
        self.assertEqual(len(refined["points"]), 12 + 20 + 11 + 2)
        self.assertEqual(refined["cells"].shape, (16, 8))
        self.assertEqual(refined["boundary_faces"].shape, (40, 4))
        self.assertEqual(refined["boundary_conditions"].count("wall"), 8)
        self.assertEqual(refined["operator"].shape, (45, 12))
        np.testing.assert_array_equal(refined["operator"] @ mesh["points"], refined["points"])
        np.testing.assert_allclose(refined["operator"].sum(axis=1), 1.0, rtol=0, atol=1e-15)
        # The wall stays in its plane. Its edge is a crease (wall meets far field), so the wall's
        # corner moves along that crease by the cubic B-spline rule: (p_prev + 6 p + p_next) / 8.
        # The far-field faces meeting at the box's vertical edge carry one condition: no crease.
        wall = np.unique(refined["boundary_faces"][[c == "wall" for c in refined["boundary_conditions"]]])
        np.testing.assert_array_equal(refined["points"][wall, 2], 0.0)
        np.testing.assert_array_equal(refined["points"][0], [0.125, 0.125, 0.0])

    def test_errors_name_the_problem(self):
        mesh = two_cubes()
        with self.assertRaisesRegex(ValueError, r"cells must be an integer array of shape \(n, 8\), got \(2, 7\)"):
            bvmesh.volume.subdivide(dict(mesh, cells=mesh["cells"][:, :7]))
        with self.assertRaisesRegex(ValueError, "unknown boundary condition 'walls'"):
            bvmesh.volume.subdivide(dict(mesh, boundary_conditions=["walls"] + mesh["boundary_conditions"][1:]))
        inverted = mesh["cells"].copy()
        inverted[1] = inverted[1][[4, 5, 6, 7, 0, 1, 2, 3]]
        with self.assertRaisesRegex(bvmesh.InvalidInputError, "cell 1 is inverted"):
            bvmesh.volume.subdivide(dict(mesh, cells=inverted))
        with self.assertRaisesRegex(ValueError, "crease 0 \\(0, 7\\) is not an edge of a boundary face"):
            bvmesh.volume.subdivide(dict(mesh, creases=np.array([[0, 7]])))
        with self.assertRaisesRegex(ValueError, "the hex mesh has no boundary_conditions"):
            bvmesh.volume.subdivide({k: v for k, v in mesh.items() if k != "boundary_conditions"})
        with self.assertRaisesRegex(ValueError, "steps must be an int >= 1"):
            bvmesh.volume.subdivide(mesh, steps=0)
        # 12 points times 8^14 are beyond the free memory: refused before the first step.
        with self.assertRaisesRegex(ValueError, r"14 subdivision steps would make about 5.28e\+13 points, more than "
                                                r"the free memory holds"):
            bvmesh.volume.subdivide(mesh, steps=14)

    def test_refine_options_belong_to_their_method(self):
        # The options are checked before the blocks are looked at.
        with self.assertRaisesRegex(ValueError, "needs steps"):
            bvmesh.grid.refine(None, method="subdivision")
        with self.assertRaisesRegex(ValueError, "takes steps only, not edge_points"):
            bvmesh.grid.refine(None, method="subdivision", steps=1, edge_points=9)
        with self.assertRaisesRegex(ValueError, "steps applies to method='subdivision' only"):
            bvmesh.grid.refine(None, steps=1)
        with self.assertRaisesRegex(ValueError, "method must be 'bspline' or 'subdivision'"):
            bvmesh.grid.refine(None, method="catmull")


if __name__ == "__main__":
    unittest.main()

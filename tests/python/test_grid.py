"""bvmesh.grid from Python: the volume mesh around a fitted sphere refined into euler and rans
grids, judged as a CFD engineer judges them: OpenFOAM's checkMesh on the written polyMesh, the
first cell height against the flat-plate formula, growth ratios along the wall-normal lines,
cgnscheck and libcgns's file read back with h5py, Plot3D read back and through plot3dToFoam, VTK
loaded by VTK itself, the G+Smo file re-evaluated with scipy, and errors that name the problem."""

import math
import os
import re
import subprocess
import tempfile
import time
import unittest

import numpy as np

import bvmesh
import bvmesh.grid
import bvmesh.volume
from fixtures import OPENFOAM, check_mesh, failed_checks, sphere_volume

# checkMesh -allGeometry flags every cell of a large aspect ratio three ways: the aspect ratio
# itself, the cell determinant (which scales as (h / a)^4) and flat decomposition tets (whose
# quality scales likewise). A y+ ~ 1 grid has them by design; no other check may fail.
ASPECT_RATIO_CHECKS = ("aspect ratio", "small determinant", "face tets")


def read_text(*parts):
    with open(os.path.join(*parts)) as file:
        return file.read()


def flat_plate_height(y_plus, reynolds, length):
    # White's turbulent flat plate: Cf = 0.026 Re^(-1/7); y = y+ nu / u_tau, u_tau = U sqrt(Cf / 2).
    return y_plus * length / (reynolds * math.sqrt(0.013 * reynolds ** (-1.0 / 7.0)))


class SphereGrids(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        _, _, cls.volume = sphere_volume(3)
        cls.euler = bvmesh.grid.refine(cls.volume, "euler", edge_points=9, normal_points=33)
        cls.rans = bvmesh.grid.refine(cls.volume, "rans", edge_points=9, reynolds_number=1e6)
        cls.folder = tempfile.TemporaryDirectory()

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    def wall_lines(self, refined):
        """Per block the wall-normal lines (w = 0 is the wall for these blocks): (ni, nj, nk, 3)."""
        return [refined.grid.points(b) for b in range(refined.grid.block_count)]

    def test_euler_grid_passes_checkmesh(self):
        case = os.path.join(self.folder.name, "euler")
        bvmesh.grid.write_openfoam(self.euler, case)
        output = check_mesh(case)
        self.assertIn("Mesh OK.", output, failed_checks(output))
        cells = int(re.search(r"^\s*cells:\s+(\d+)", output, re.M).group(1))
        self.assertEqual(cells, self.euler.grid.cell_count)
        self.assertEqual(cells, 6 * 8 * 8 * 32)
        points = int(re.search(r"^\s*points:\s+(\d+)", output, re.M).group(1))
        self.assertEqual(points, len(self.euler.grid.merged_points()))
        patches = read_text(case, "constant", "polyMesh", "boundary")
        self.assertNotIn("defaultFaces", patches)
        self.assertRegex(patches, r"wall\s*\{\s*type\s+wall;")
        self.assertRegex(patches, r"farfield\s*\{\s*type\s+patch;")
        non_orthogonality = float(re.search(r"non-orthogonality Max:\s*([0-9.eE+-]+)", output).group(1))
        self.assertLess(non_orthogonality, 70.0)

    def test_euler_lines_grow_by_the_asked_ratio(self):
        # No first height: every wall-normal line grows by exactly 1.2 in point spacings, bent
        # lines included (the marched lines bend next to the cube's corner vertices; a law in arc
        # length put their spacings up to 0.5 % off).
        ratios = []
        for points in self.wall_lines(self.euler):
            spacing = np.linalg.norm(np.diff(points, axis=2), axis=3)
            ratios.append((spacing[:, :, 1:] / spacing[:, :, :-1]).ravel())
        ratios = np.concatenate(ratios)
        np.testing.assert_allclose(ratios, 1.2, rtol=1e-9)
        self.assertLessEqual(self.euler.growth_max, 1.2 * (1 + 1e-9))
        self.assertFalse(self.euler.grid.viscous_wall)

    def test_rans_first_cell_height_is_the_flat_plate_value_everywhere(self):
        asked = flat_plate_height(1.0, 1e6, 1.0)
        self.assertAlmostEqual(self.rans.first_cell_height_asked / asked, 1.0, places=12)
        report = bvmesh.grid.quality(self.rans)
        heights = np.asarray(report["first_cell_height"])
        self.assertEqual(len(heights), 6 * 9 * 9)
        np.testing.assert_allclose(heights, asked, rtol=1e-3)
        for points in self.wall_lines(self.rans):
            first = np.linalg.norm(points[:, :, 1] - points[:, :, 0], axis=2)
            np.testing.assert_allclose(first, asked, rtol=1e-9)
        self.assertTrue(self.rans.grid.viscous_wall)

    def test_rans_growth_stays_within_the_maximum(self):
        # The fewest points that keep growth <= 1.2 on the longest line: the ratio along every line
        # (measured on point spacings) is at most 1.2, and one point fewer would need more.
        self.assertLessEqual(self.rans.growth_max, 1.2 * (1 + 1e-9))
        for points in self.wall_lines(self.rans):
            spacing = np.linalg.norm(np.diff(points, axis=2), axis=3)
            self.assertLessEqual((spacing[:, :, 1:] / spacing[:, :, :-1]).max(), 1.2 * (1 + 1e-9))
        fewer = bvmesh.refine_blocks(self.volume.blocks, normal_points=self.rans.normal_points - 1, y_plus=1.0,
                                     reynolds_number=1e6, reference_length=1.0, edge_points=9, growth=1.25)
        self.assertGreater(fewer.growth_max, 1.2)
        with self.assertRaisesRegex(ValueError, r"growth ratio of .* above the maximum 1\.2.* at least \d+ points"):
            bvmesh.refine_blocks(self.volume.blocks, normal_points=self.rans.normal_points - 1, y_plus=1.0,
                                 reynolds_number=1e6, reference_length=1.0, edge_points=9)

    def test_rans_grid_fails_only_the_aspect_ratio_checks(self):
        case = os.path.join(self.folder.name, "rans")
        bvmesh.grid.write_openfoam(self.rans, case)
        output = check_mesh(case)
        failed = failed_checks(output)
        unexpected = [line for line in failed if not any(name in line for name in ASPECT_RATIO_CHECKS)]
        self.assertEqual(unexpected, [], output)
        self.assertIn("Cell volumes OK.", output)
        self.assertIn("Face pyramids OK.", output)
        self.assertIn("Non-orthogonality check OK.", output)

    def test_cell_determinant_is_checkmeshs(self):
        # The rans grid's thin wall cells are what checkMesh -allGeometry fails as small
        # determinants: its minimum, mean and count below 1e-3 are ours.
        case = os.path.join(self.folder.name, "rans_determinant")
        bvmesh.grid.write_openfoam(self.rans, case)
        output = check_mesh(case)
        found = re.search(r"Cell determinant \(wellposedness\) : minimum: ([0-9.eE+-]+) average: ([0-9.eE+-]+)", output)
        self.assertIsNotNone(found, output)
        determinant = bvmesh.grid.quality(self.rans)["determinant"]
        # (The minimum, 3e-13, is a determinant of near-singular tensors of entries about 1: both
        # sides carry rounding of about 1e-16 there.)
        self.assertAlmostEqual(determinant.min(), float(found.group(1)), delta=1e-15)
        self.assertAlmostEqual(determinant.mean() / float(found.group(2)), 1.0, delta=1e-9)
        small = re.search(r"Cells with small determinant \(< 0.001\) found, number of cells: (\d+)", output)
        self.assertIsNotNone(small, output)
        self.assertEqual(int((determinant < 1e-3).sum()), int(small.group(1)))

    def test_quality_report_and_histograms(self):
        report = bvmesh.grid.quality(self.euler)
        summary = report["summary"]
        self.assertGreater(summary["scaled_jacobian"]["min"], 0.8)
        self.assertLess(summary["non_orthogonality"]["max"], 20.0)
        self.assertLess(summary["wall_angle"]["p99"], 2.0)
        self.assertEqual(len(report["scaled_jacobian"]), self.euler.grid.cell_count)
        self.assertEqual(len(report["block_summary"]), self.euler.grid.block_count)
        table = bvmesh.grid.quality_table(report)
        self.assertIn("| scaled_jacobian |", table)
        self.assertIn("| determinant |", table)
        path = os.path.join(self.folder.name, "quality.png")
        bvmesh.grid.write_histograms(report, path)
        with open(path, "rb") as image:
            self.assertEqual(image.read(8), b"\x89PNG\r\n\x1a\n")

    def test_shared_faces_are_point_matched(self):
        # Six blocks around the sphere: merged points = all points minus the duplicates on the 12
        # shared faces (block edges shared by three faces counted once).
        grid = self.euler.grid
        ni, nj, nk = grid.size(0)
        total = grid.block_count * ni * nj * nk
        merged = len(grid.merged_points())
        # 12 shared faces of ni x nk points, minus the 8 corner lines counted three times over.
        self.assertEqual(total - merged, 12 * ni * nk - 8 * nk)

    def test_cgns_passes_cgnscheck_and_reads_back(self):
        import h5py

        for refined, wall_type in ((self.euler, b"BCWall"), (self.rans, b"BCWallViscous")):
            path = os.path.join(self.folder.name, "sphere_{}.cgns".format(wall_type.decode()))
            bvmesh.grid.write_cgns(refined, path)
            report = subprocess.run(["cgnscheck", path], capture_output=True, text=True, timeout=300).stdout
            self.assertIn("checking complete", report)
            self.assertNotRegex(report, r"(?i)error|warning", report)
            grid = refined.grid
            with h5py.File(path, "r") as cgns:
                base = cgns["Base"]
                for b in range(grid.block_count):
                    zone = base["block_{:04d}".format(b + 1)]
                    points = grid.points(b)  # (ni, nj, nk, 3); CGNS stores (nk, nj, ni)
                    for axis, name in enumerate("XYZ"):
                        stored = zone["GridCoordinates"]["Coordinate" + name][" data"][()]
                        np.testing.assert_array_equal(stored, points[..., axis].transpose(2, 1, 0))
                    self.assertEqual(len(zone["ZoneGridConnectivity"]), 4)
                self.assertEqual(bytes(base["wall"]["FamBC"][" data"][()]).rstrip(b"\0"), wall_type)
                self.assertEqual(bytes(base["farfield"]["FamBC"][" data"][()]).rstrip(b"\0"), b"BCFarfield")

    def test_plot3d_round_trip_and_plot3dtofoam_merges_every_shared_point(self):
        grid = self.euler.grid
        for form in ("binary", "ascii"):
            path = os.path.join(self.folder.name, "sphere_{}.p3d".format(form))
            bvmesh.grid.write_plot3d(self.euler, path, form)
            blocks = bvmesh.grid.read_plot3d(path)
            self.assertEqual(len(blocks), grid.block_count)
            for b, points in enumerate(blocks):
                np.testing.assert_array_equal(points, grid.points(b))
        # OpenFOAM's plot3dToFoam joins block faces only where points are bit-identical: it must
        # find exactly the grid's distinct points.
        case = os.path.join(self.folder.name, "plot3d_case")
        bvmesh.grid.write_openfoam(self.euler, case)
        result = subprocess.run(["plot3dToFoam", "-noBlank", "-case", case,
                                 os.path.join(self.folder.name, "sphere_ascii.p3d")],
                                env=OPENFOAM, capture_output=True, text=True, timeout=300)
        owner = read_text(case, "constant", "polyMesh", "owner")
        points = int(re.search(r"nPoints:\s*(\d+)", owner).group(1))
        self.assertEqual(points, len(grid.merged_points()), result.stdout[-2000:])

    def test_vtk_multiblock_loads_with_its_quality_fields(self):
        from vtk.util.numpy_support import vtk_to_numpy

        path = os.path.join(self.folder.name, "sphere.vtm")
        report = bvmesh.grid.quality(self.euler)
        bvmesh.grid.write_vtk(self.euler, path, report)
        data = read_vtk_multiblock(path)
        grid = self.euler.grid
        self.assertEqual(data.GetNumberOfBlocks(), grid.block_count)
        start = 0
        for b in range(grid.block_count):
            block = data.GetBlock(b)
            points = vtk_to_numpy(block.GetPoints().GetData())
            np.testing.assert_array_equal(points, grid.points(b).transpose(2, 1, 0, 3).reshape(-1, 3))
            cells = block.GetNumberOfCells()
            jacobian = vtk_to_numpy(block.GetCellData().GetArray("scaled_jacobian"))
            np.testing.assert_array_equal(jacobian, report["scaled_jacobian"][start:start + cells])
            determinant = vtk_to_numpy(block.GetCellData().GetArray("determinant"))
            np.testing.assert_array_equal(determinant, report["determinant"][start:start + cells])
            self.assertTrue(np.all(vtk_to_numpy(block.GetCellData().GetArray("block")) == b))
            start += cells
        self.assertEqual(start, grid.cell_count)

    def test_gismo_file_evaluates_as_the_blocks(self):
        import xml.etree.ElementTree as ElementTree
        from scipy.interpolate import BSpline

        path = os.path.join(self.folder.name, "sphere.xml")
        bvmesh.grid.write_gismo(self.volume, path)
        root = ElementTree.parse(path).getroot()
        geometries = [g for g in root.iter("Geometry") if g.get("type") == "TensorBSpline3"]
        blocks = self.volume.blocks
        self.assertEqual(len(geometries), blocks.block_count)
        random = np.random.default_rng(3)
        for geometry in geometries:
            b = int(geometry.get("id"))
            knots = [np.array(k.text.split(), float) for k in geometry.iter("KnotVector")]
            degrees = [int(k.get("degree")) for k in geometry.iter("KnotVector")]
            self.assertEqual(tuple(degrees), blocks.degrees(b))
            coefs = np.array(geometry.find("coefs").text.split(), float).reshape(-1, 3)
            counts = [len(k) - d - 1 for k, d in zip(knots, degrees)]
            poles = coefs.reshape(counts[2], counts[1], counts[0], 3)  # first index fastest
            parameters = random.uniform(0.0, 1.0, (20, 3)) * [k[-1] - k[0] for k in knots] + [k[0] for k in knots]
            matrices = [BSpline.design_matrix(parameters[:, d], knots[d], degrees[d]).toarray() for d in range(3)]
            points = np.einsum("pi,pj,pk,kjix->px", matrices[0], matrices[1], matrices[2], poles)
            np.testing.assert_allclose(points, blocks.evaluate(b, parameters), atol=1e-12)
        interfaces = root.find(".//MultiPatch/interfaces")
        self.assertEqual(len(interfaces.text.strip().splitlines()), 12)

    def test_turning_limit_sets_the_counts_on_a_curved_wall(self):
        # The sphere's cube layout: every wall edge turns through about 70 degrees, a face's middle
        # line through 90. A spacing of a diameter alone gives 2 points per edge; a 10-degree limit
        # gives every wall cell along the block edges at most 10 degrees of turning (consecutive
        # chords of the wall points turn by the mean of two cells'). Lines inside a face take
        # their parameters blended from the edges', so they only come close (12.4 degrees).
        diameter = np.ptp(bvmesh.grid.wall_points(self.euler), axis=0).max()
        coarse = bvmesh.grid.refine(self.volume, "euler", tangential_spacing=diameter, normal_points=5)
        turned = bvmesh.grid.refine(self.volume, "euler", tangential_spacing=diameter, normal_points=5,
                                    max_turning_angle=10.0)
        self.assertEqual({coarse.grid.size(b)[:2] for b in range(coarse.grid.block_count)}, {(2, 2)})

        def turning(lines):  # (n_lines, n_points, 3) -> degrees between consecutive chords
            chords = np.diff(lines, axis=1)
            a, c = chords[:, :-1], chords[:, 1:]
            cosine = (a * c).sum(-1) / np.linalg.norm(a, axis=-1) / np.linalg.norm(c, axis=-1)
            return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))

        edges, inside = 0.0, 0.0
        for b in range(turned.grid.block_count):
            self.assertGreaterEqual(min(turned.grid.size(b)[:2]), 8)
            sheet = bvmesh.grid.face_array(turned.grid.points(b), "w_min")
            for lines in (np.moveaxis(sheet, 1, 0), sheet):  # lines along the sheet's first, second axis
                angles = turning(lines)
                edges = max(edges, angles[[0, -1]].max())
                inside = max(inside, angles[1:-1].max())
        self.assertLess(edges, 10.0 * 1.05)
        self.assertGreater(edges, 5.0)  # the limit is what set the counts, not a finer spacing
        self.assertLess(inside, 13.0)

    def test_spacing_jump_limit_leaves_an_even_layout_alone(self):
        # The sphere's six blocks meet at corners with equal spacings on both sides: the presets'
        # limit (4) finds no jump and the grid is the one without it, bit for bit.
        limited = bvmesh.grid.refine(self.volume, "euler", edge_points=9, normal_points=9)
        plain = bvmesh.grid.refine(self.volume, "euler", edge_points=9, normal_points=9, max_spacing_jump=0.0)
        for b in range(limited.grid.block_count):
            np.testing.assert_array_equal(limited.grid.points(b), plain.grid.points(b))

    def test_feature_spacing_clusters_the_wall_edges_leaving_a_corner(self):
        # A short line through one corner of the cube layout, along the sphere's normal: the three
        # wall edges leaving that corner start with the asked spacing (the wall points nearest the
        # corner are that far along the edges' arcs; their chords are shorter by ~1e-5), the
        # counts stay as edge_points asks, and the opposite corner keeps its uniform spacing.
        plain = bvmesh.grid.refine(self.volume, "euler", edge_points=9, normal_points=9)
        wall = bvmesh.grid.wall_points(plain)
        corner = wall[np.argmax(wall.sum(axis=1))]
        spacing = 0.02 * np.linalg.norm(corner)
        refined = bvmesh.grid.refine(self.volume, "euler", edge_points=9, normal_points=9,
                                     feature_spacings=[{"points": [0.9 * corner, 1.1 * corner], "spacing": spacing}])
        self.assertEqual([refined.grid.size(b) for b in range(6)], [plain.grid.size(b) for b in range(6)])

        def nearest(points, at):
            distance = np.linalg.norm(points - at, axis=1)
            return distance[distance > 1e-9 * np.linalg.norm(at)].min()

        clustered = bvmesh.grid.wall_points(refined)
        self.assertAlmostEqual(nearest(clustered, corner) / spacing, 1.0, delta=1e-3)
        self.assertGreater(nearest(wall, corner), 5 * spacing)
        self.assertAlmostEqual(nearest(clustered, -corner), nearest(wall, -corner), delta=1e-9)

    def test_grid_beyond_the_memory_is_refused_before_it_is_computed(self):
        # The free memory's budget, measured per point (grid.BYTES_PER_POINT), is a positive count
        # on this machine; a grid beyond it or beyond max_points is refused by its planned size
        # (2e9 cells would take some 500 GB: refused at once, not computed until the memory runs out).
        budget = bvmesh.grid.point_budget()
        self.assertGreater(budget, 1_000_000)
        with open("/proc/meminfo") as info:
            available = next(int(line.split()[1]) * 1024 for line in info if line.startswith("MemAvailable:"))
        self.assertAlmostEqual(budget * bvmesh.grid.BYTES_PER_POINT, available, delta=0.1 * available)
        started = time.perf_counter()
        # 6 x 100 000^2 x 49 points are beyond any machine; 2e9 cells beyond this one's budget.
        asked = [dict(edge_points=100_000)] + ([dict(target_cells=2_000_000_000)] if budget < 2e9 else [])
        for options in asked:
            with self.subTest(**options), self.assertRaisesRegex(ValueError, r"the grid would have [0-9.e+]+ points, "
                                                                             r"more than max_points \(\d+, the memory budget\)"):
                bvmesh.grid.refine(self.volume, "euler", **options)
        self.assertLess(time.perf_counter() - started, 30.0)
        # The euler grid (6 x 9 x 9 x 33 points) against a budget just above and just below it.
        points = 6 * 9 * 9 * 33
        bvmesh.grid.refine(self.volume, "euler", edge_points=9, normal_points=33, max_points=points)
        with self.assertRaisesRegex(ValueError, "the grid would have {} points, more than max_points \\({}".format(
                points, points - 1)):
            bvmesh.grid.refine(self.volume, "euler", edge_points=9, normal_points=33, max_points=points - 1)
        with self.assertRaisesRegex(ValueError, "max_points must be 0"):
            bvmesh.grid.refine(self.volume, "euler", max_points=-1)
        # Subdivision steps are held to the budget too: 12 steps would be 8^12 times the control net.
        with self.assertRaisesRegex(ValueError, "the grid would have .* points, more than max_points"):
            bvmesh.grid.refine(self.volume, method="subdivision", steps=12)

    def test_errors_name_the_problem(self):
        line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
        for bad, message in ((dict(points=line[:1], spacing=0.1), "feature spacing 0: the line needs at least two"),
                             (dict(points=line, spacing=-1.0), "feature spacing 0: the spacing"),
                             (dict(points=[[0.0, 1.0]] * 2, spacing=0.1), r"feature_spacings\[0\]\['points'\] must have shape"),
                             (dict(points=line, spacing=0.1, width=2), "unknown key 'width'"),
                             (dict(points=line), "needs 'points' and 'spacing'"),
                             (dict(points=line, spacing="fine"), r"\['spacing'\] must be a number")):
            with self.assertRaisesRegex(ValueError, message):
                bvmesh.grid.refine(self.volume, "euler", feature_spacings=[bad])
        with self.assertRaisesRegex(ValueError, "sequence of dicts"):
            bvmesh.grid.refine(self.volume, "euler", feature_spacings="leading edge")
        with self.assertRaisesRegex(ValueError, "max_turning_angle"):
            bvmesh.grid.refine(self.volume, "euler", max_turning_angle=-5.0)
        for bad in (0.5, float("nan")):
            with self.assertRaisesRegex(ValueError, "max_spacing_jump"):
                bvmesh.grid.refine(self.volume, "euler", max_spacing_jump=bad)
        with self.assertRaisesRegex(ValueError, "no block face 'top'"):
            self.euler.grid.quad_conditions(0, "top")
        with self.assertRaisesRegex(ValueError, "preset"):
            bvmesh.grid.refine(self.volume, "navier")
        with self.assertRaisesRegex(ValueError, "reynolds_number"):
            bvmesh.grid.refine(self.volume, "rans")
        with self.assertRaisesRegex(ValueError, "growth"):
            bvmesh.grid.refine(self.volume, "euler", growth=0.9)
        with self.assertRaisesRegex(ValueError, "distribution"):
            bvmesh.grid.refine(self.volume, "euler", distribution="cubic")
        with self.assertRaisesRegex(TypeError, "VolumeMesh or a BlockMesh"):
            bvmesh.grid.refine("mesh.cgns")
        missing = os.path.join(self.folder.name, "file", "in", "the", "way")
        open(os.path.join(self.folder.name, "file"), "w").close()
        with self.assertRaisesRegex(ValueError, "cannot create the OpenFOAM case folder"):
            bvmesh.grid.write_openfoam(self.euler, missing)


def read_vtk_multiblock(path):
    """The VTK multiblock data set of a .vtm file, read by VTK itself."""
    import vtk

    reader = vtk.vtkXMLMultiBlockDataReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def fan_wedge_block_file(path, half_wedge_degrees=10.0):
    """The block file of a sharp edge as a fan (tests/cpp/block_fixtures.h, fanWedgeBlocks): the
    y axis is the edge of a wedge whose faces run along -x, block 0 on the upper face, block 1 on
    the lower, block 2 fanning round the edge from the lower face's normal to the upper's, its
    w_min face the edge itself (collapsed). y = 0 is a symmetry plane."""
    alpha = math.radians(half_wedge_degrees)
    upper = np.array([math.sin(alpha), 0.0, math.cos(alpha)])
    lower = np.array([math.sin(alpha), 0.0, -math.cos(alpha)])
    greville = [0.0, 1.0 / 6.0, 0.5, 5.0 / 6.0, 1.0]
    knots = "knots {} 3 9 0 0 0 0 1 2 2 2 2\n"
    lines = ["bvmesh-blocks 1", "blocks 3"]
    for b in range(3):
        lines += ["block {}".format(b)] + [knots.format(d).rstrip() for d in "uvw"] + ["poles 5 5 5"]
        for t in greville:
            for along in greville:
                for y in greville:
                    edge = np.array([0.0, y, 0.0])
                    if b == 0:
                        x = edge + t * upper if along == 0.0 else np.array(
                            [-2 * along * math.cos(alpha), y, 2 * along * math.sin(alpha)]) + t * upper
                    elif b == 1:
                        s = 1.0 - along
                        x = edge + t * lower if s == 0.0 else np.array(
                            [-2 * s * math.cos(alpha), y, -2 * s * math.sin(alpha)]) + t * lower
                    else:
                        angle = (2 * along - 1) * (math.pi / 2 - alpha)
                        direction = lower if along == 0.0 else upper if along == 1.0 else np.array(
                            [math.cos(angle), 0.0, math.sin(angle)])
                        x = edge + t * direction
                    lines.append("{!r} {!r} {!r}".format(*x))
        faces = {"u_min": "symmetry", "u_max": "farfield", "v_min": "farfield", "v_max": "farfield",
                 "w_min": "collapsed" if b == 2 else "wall", "w_max": "farfield"}
        if b == 0:
            faces["v_min"] = "connected 2 v_max 0 0 0"
        if b == 1:
            faces["v_max"] = "connected 2 v_min 0 0 0"
        if b == 2:
            faces["v_min"] = "connected 1 v_max 0 0 0"
            faces["v_max"] = "connected 0 v_min 0 0 0"
        lines += ["face {} {}".format(name, faces[name]) for name in ("u_min", "u_max", "v_min", "v_max", "w_min", "w_max")]
    lines.append("end")
    with open(path, "w") as file:
        file.write("\n".join(lines) + "\n")


class FanGrid(unittest.TestCase):
    """A fan of prisms round a sharp edge (a block with a collapsed face) through every writer and
    the real checkers."""

    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.TemporaryDirectory()
        path = os.path.join(cls.folder.name, "fan.blocks")
        fan_wedge_block_file(path)
        cls.blocks = bvmesh.read_block_mesh(path)
        cls.refined = bvmesh.grid.refine(cls.blocks, None, normal_points=9, tangential_spacing=0.25)

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    def test_the_block_file_keeps_the_collapsed_face(self):
        self.assertEqual(self.blocks.faces(2)["w_min"]["condition"], "collapsed")
        self.assertEqual(self.refined.grid.faces(2)["w_min"]["condition"], "collapsed")
        fan = self.refined.grid.points(2)  # (ni, nj, nk, 3)
        self.assertEqual(fan.shape[1], 7)  # 160 degrees in cells of at most 30
        np.testing.assert_array_equal(fan[:, :, 0], np.repeat(fan[:, :1, 0], fan.shape[1], axis=1))

    def test_cgns_passes_cgnscheck_with_a_degenerate_line(self):
        import h5py

        path = os.path.join(self.folder.name, "fan.cgns")
        bvmesh.grid.write_cgns(self.refined, path)
        report = subprocess.run(["cgnscheck", path], capture_output=True, text=True, timeout=300).stdout
        self.assertIn("checking complete", report)
        self.assertNotRegex(report, r"(?i)error|warning", report)
        with h5py.File(path, "r") as cgns:
            base = cgns["Base"]
            self.assertEqual(bytes(base["collapsed"]["FamBC"][" data"][()]).rstrip(b"\0"), b"BCDegenerateLine")
            boundary = base["block_0003"]["ZoneBC"]["collapsed_w_min"]
            self.assertEqual(bytes(boundary[" data"][()]).rstrip(b"\0"), b"BCDegenerateLine")

    def test_checkmesh_and_plot3dtofoam_see_the_same_prisms(self):
        grid = self.refined.grid
        prisms = (grid.points(2).shape[0] - 1) * (grid.points(2).shape[1] - 1)
        case = os.path.join(self.folder.name, "fan_case")
        bvmesh.grid.write_openfoam(self.refined, case)
        output = check_mesh(case)
        self.assertIn("Mesh OK.", output)
        self.assertRegex(output, r"prisms: +{}\n".format(prisms))
        # plot3dToFoam merges the Plot3D file's bit-identical points, the edge's included.
        plot3d = os.path.join(self.folder.name, "fan.p3d")
        bvmesh.grid.write_plot3d(self.refined, plot3d, "ascii")
        for points, read in zip((grid.points(b) for b in range(3)), bvmesh.grid.read_plot3d(plot3d)):
            np.testing.assert_array_equal(read, points)
        second = os.path.join(self.folder.name, "plot3d_case")
        bvmesh.grid.write_openfoam(self.refined, second)
        subprocess.run(["plot3dToFoam", "-noBlank", "-case", second, plot3d], env=OPENFOAM,
                       capture_output=True, text=True, timeout=300)
        output = check_mesh(second)
        self.assertRegex(output, r"cells: +{}\n".format(grid.cell_count), output)
        self.assertRegex(output, r"prisms: +{}\n".format(prisms), output)

    def test_vtk_loads_it_and_the_quality_is_the_prisms(self):
        path = os.path.join(self.folder.name, "fan.vtm")
        report = bvmesh.grid.quality(self.refined)
        bvmesh.grid.write_vtk(self.refined, path, report)
        self.assertEqual(read_vtk_multiblock(path).GetNumberOfBlocks(), 3)
        self.assertGreater(report["scaled_jacobian"].min(), 0.3)  # sin(160 / 6 degrees) = 0.45 at the edge
        self.assertLess(report["non_orthogonality"].max(), 20.0)


if __name__ == "__main__":
    unittest.main()

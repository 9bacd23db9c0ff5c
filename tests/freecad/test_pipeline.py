"""`python3 -m bvmesh mesh`: the whole job on any CAD file, as a batch run would call it. The
body of a flow domain's file in every solver format, a closed body as a whole, a half model's
surface with a template parameter, a lofted wing whose sharp trailing edge gets fans of prisms,
and bad input refused with a message and exit status 1; a run whose fit stops above its tolerance
writes every file and ends with a warning and exit status 2."""

import os
import re
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ElementTree

import FreeCAD
import Part

import bvmesh
from bvmesh import grid

sys.path.insert(0, os.path.join(os.environ["BVMESH_SOURCE_DIR"], "tests", "python"))
from fixtures import naca0012_section  # noqa: E402  -- the wing section the Python tests draw too

DATA = os.environ.get("BVMESH_TEST_DATA_DIR", os.path.join(os.environ["BVMESH_SOURCE_DIR"], "tests", "data"))
ENV = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(os.environ["BVMESH_SOURCE_DIR"], "Mod"),
                                                   "/usr/lib/freecad-python3/lib"]))


def mesh(*arguments, timeout=600):
    return subprocess.run(["/usr/bin/python3", "-m", "bvmesh", "mesh"] + [str(a) for a in arguments], env=ENV,
                          capture_output=True, text=True, timeout=timeout)


def read(path):
    with open(path) as text:
        return text.read()


class FlowDomainInEveryFormat(unittest.TestCase):
    """The hemisphere-cylinder's flow-domain file: the body is found, fitted from the capsule
    template and meshed inside the file's own half sphere, in all six formats."""

    @classmethod
    def setUpClass(cls):
        cls.output = tempfile.mkdtemp(prefix="bvmesh-mesh-")
        cls.done = mesh(os.path.join(DATA, "hemisph-cyl.stp"), "--template", "capsule", "--output", cls.output,
                        "--max-level", "2", "--target-cells", "20000",
                        "--formats", "cgns,openfoam,plot3d,vtk,gismo,blocks")

    def path(self, name):
        return os.path.join(self.output, name)

    def test_runs_and_writes_every_file(self):
        # Level 2 is above the 1e-5 tolerance: every file is written, and the exit status and a
        # warning tell a batch run so.
        self.assertEqual(self.done.returncode, 2, self.done.stderr)
        self.assertRegex(self.done.stderr, r"^bvmesh: warning: the fit stopped as max_level: at level 2: samples up to "
                                           r"[0-9.e-]+ from the target, above the tolerance 0.0001;")
        for name in ("hemisph-cyl.FCStd", "hemisph-cyl_surface.step", "hemisph-cyl_convergence.png",
                     "hemisph-cyl_report.md", "hemisph-cyl_volume_report.md", "hemisph-cyl_cut.png",
                     "hemisph-cyl_quality.png", "hemisph-cyl.cgns", "hemisph-cyl.xyz", "hemisph-cyl.vtm",
                     "hemisph-cyl.xml", "hemisph-cyl.blocks"):
            self.assertTrue(os.path.isfile(self.path(name)), name)
        self.assertTrue(os.path.isfile(self.path("hemisph-cyl_openfoam/constant/polyMesh/owner")))
        self.assertIn("the body inside the CAD's flow domain (sphere, 2 faces)", read(self.path("hemisph-cyl_report.md")))

    def test_volume_report_matches_the_document_and_the_files(self):
        report = read(self.path("hemisph-cyl_volume_report.md"))
        self.assertIn("checkMesh on hemisph-cyl_openfoam: Mesh OK.", report)
        # The body's length on the symmetry plane is the reference length; the far field is the
        # file's own domain, a half sphere of radius 100 around (10, 0, 0).
        self.assertIn("(reference length 10, ", report)
        self.assertIn("far field: sphere of radius 100 ", report)
        cells = int(re.search(r"Grid: preset euler, (\d+) cells", report).group(1))
        self.assertTrue(10000 < cells < 30000, cells)
        doc = FreeCAD.openDocument(self.path("hemisph-cyl.FCStd"))
        try:
            kinds = [o.Proxy.Type for o in doc.Objects if hasattr(o, "Proxy") and hasattr(o.Proxy, "Type")]
            self.assertEqual(kinds.count("BVMesh::Export"), 6)
            self.assertEqual(kinds.count("BVMesh::GridCut"), 1)
            grid_object = doc.getObject("VolumeGrid")
            self.assertEqual(grid_object.CellCount, cells)
            blocks = grid_object.VolumeMesh.BlockCount
        finally:
            FreeCAD.closeDocument(doc.Name)
        # The block file and the G+Smo file hold the volume mesh's blocks, Plot3D the grid's cells.
        self.assertEqual(bvmesh.read_block_mesh(self.path("hemisph-cyl.blocks")).block_count, blocks)
        patches = ElementTree.parse(self.path("hemisph-cyl.xml")).getroot().findall(".//Geometry[@type='TensorBSpline3']")
        self.assertEqual(len(patches), blocks)
        sizes = grid.read_plot3d(self.path("hemisph-cyl.xyz"))
        self.assertEqual(sum((a.shape[0] - 1) * (a.shape[1] - 1) * (a.shape[2] - 1) for a in sizes), cells)

    def test_cgns_passes_cgnscheck(self):
        checked = subprocess.run(["cgnscheck", self.path("hemisph-cyl.cgns")], capture_output=True, text=True,
                                 timeout=300).stdout
        self.assertIn("checking complete", checked)
        self.assertNotRegex(checked, r"(?i)error|warning", checked)


class ClosedBodyAsAWhole(unittest.TestCase):
    @staticmethod
    def ball():
        """A STEP file of the unit sphere and a folder for the results."""
        folder = tempfile.mkdtemp(prefix="bvmesh-mesh-ball-")
        cad = os.path.join(folder, "ball.step")
        Part.makeSphere(1.0).exportStep(cad)
        return cad, os.path.join(folder, "out")

    def test_sphere_meshed_out_to_twenty_diameters(self):
        cad, output = self.ball()
        done = mesh(cad, "--template", "sphere", "--output", output, "--max-level", "3", "--tolerance", "1e-3",
                    "--target-cells", "20000", "--formats", "openfoam")
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertEqual(done.stderr, "")
        report = read(os.path.join(output, "ball_report.md"))
        self.assertIn("Target: all 1 faces of the CAD; reference length 2;", report)
        self.assertIn("closed shells: 1, free edges: 0", report)
        volume_report = read(os.path.join(output, "ball_volume_report.md"))
        # The reference length is the body's largest extent; the far field 20 of them.
        self.assertIn("far field: sphere of radius 40 (20.0 reference lengths)", volume_report)
        self.assertIn("checkMesh on ball_openfoam: Mesh OK.", volume_report)
        self.assertIn("Cells with a non-positive scaled Jacobian: 0;", volume_report)
        self.assertFalse(os.path.exists(os.path.join(output, "ball.cgns")))

    def test_reference_length_of_a_b_spline_body_is_its_extent(self):
        # A sphere stretched to 4 x 1.4 x 1 is one B-spline surface whose poles reach 6 along x:
        # FreeCAD's Shape.BoundBox made that the reference length (and the tolerance and the far
        # field 1.5 times as large).
        folder = tempfile.mkdtemp(prefix="bvmesh-mesh-ellipsoid-")
        cad = os.path.join(folder, "ellipsoid.step")
        ellipsoid = Part.makeSphere(1.0).transformGeometry(FreeCAD.Matrix(2, 0, 0, 0, 0, 0.7, 0, 0, 0, 0, 0.5, 0))
        self.assertAlmostEqual(ellipsoid.BoundBox.XLength, 6.0, delta=1e-6)
        ellipsoid.exportStep(cad)
        done = mesh(cad, "--template", "sphere", "--output", os.path.join(folder, "out"), "--max-level", "1",
                    "--surface-only")
        self.assertIn(done.returncode, (0, 2), done.stderr)
        report = read(os.path.join(folder, "out", "ellipsoid_report.md"))
        self.assertIn("reference length 4; tolerance 4e-05", report)

    def test_a_grid_that_checkmesh_fails_is_written_with_a_warning(self):
        # y+ 1 at Re 1e7 on 20 000 cells: wall cells some 35 000 times wider than high, which
        # checkMesh's default checks fail. The files are there; the exit status says it.
        cad, output = self.ball()
        done = mesh(cad, "--template", "sphere", "--output", output, "--max-level", "3", "--tolerance", "1e-3",
                    "--target-cells", "20000", "--formats", "openfoam", "--preset", "rans", "--reynolds", "1e7")
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertRegex(done.stderr, r"^bvmesh: warning: checkMesh on the OpenFOAM case: \*\*\*High aspect ratio "
                                      r"cells found, Max aspect ratio: [0-9.]+, number of cells \d+\n$")
        self.assertTrue(os.path.isfile(os.path.join(output, "ball_openfoam", "constant", "polyMesh", "owner")))
        self.assertIn("checkMesh on ball_openfoam: ***High aspect ratio cells found",
                      read(os.path.join(output, "ball_volume_report.md")))

    def test_volume_and_grid_options_reach_their_objects(self):
        # A box domain facing a flow 0.1 rad off x, 9 points on every tangential edge and 33 on
        # the wall-normal lines: 6 blocks of 8 x 8 x 32 cells, the box's faces as inlet, outlet
        # and side patches.
        cad, output = self.ball()
        done = mesh(cad, "--template", "sphere", "--output", output, "--max-level", "2", "--tolerance", "1e-2",
                    "--volume-option", "domain=box", "--volume-option", "flow_direction=1,0,0.1",
                    "--grid-option", "edge_points=9", "--grid-option", "normal_points=33", "--formats", "openfoam")
        self.assertEqual(done.returncode, 0, done.stderr)
        report = read(os.path.join(output, "ball_volume_report.md"))
        self.assertIn("far field: box at a distance of 40 (20.0 reference lengths)", report)
        self.assertIn("Grid: preset euler, 12288 cells", report)
        self.assertIn("checkMesh on ball_openfoam: Mesh OK.", report)
        patches = read(os.path.join(output, "ball_openfoam", "constant", "polyMesh", "boundary"))
        for patch in ("inlet", "outlet", "side", "wall"):
            self.assertRegex(patches, r"\n\s*{}\s*\n\s*{{".format(patch))


class HalfModelSurface(unittest.TestCase):
    def test_half_wing_without_its_root_face_and_with_a_template_parameter(self):
        output = tempfile.mkdtemp(prefix="bvmesh-mesh-m6-")
        done = mesh(os.path.join(DATA, "AileM6_with_sharp_TE.stp"), "--template", "half_wing", "--half-model",
                    "--template-parameter", "tip_kinks=follow", "--output", output, "--name", "wing",
                    "--max-level", "1", "--surface-only")
        self.assertEqual(done.returncode, 2, done.stderr)  # level 1 is above the tolerance
        report = read(os.path.join(output, "wing_report.md"))
        # The root face is left out and its largest extent, the root chord, is the reference length.
        match = re.search(r"Target: the CAD's faces without Face(\d+), its symmetry-plane face; reference length "
                          r"([0-9.]+);", report)
        self.assertIsNotNone(match, report)
        self.assertAlmostEqual(float(match.group(2)), 810.5, delta=0.5)
        self.assertEqual(sorted(os.listdir(output)),
                         ["wing.FCStd", "wing_convergence.png", "wing_report.md", "wing_surface.step"])
        doc = FreeCAD.openDocument(os.path.join(output, "wing.FCStd"))
        try:
            self.assertIn(doc.getObject("ControlPolyhedron").Summary, done.stdout)
            fit = doc.getObject("SurfaceFit")
            self.assertTrue(fit.UseSymmetryPlane)
            self.assertAlmostEqual(abs(fit.SymmetryNormal.y), 1.0, places=9)
        finally:
            FreeCAD.closeDocument(doc.Name)


class OpenHalfModel(unittest.TestCase):
    def test_half_wing_without_a_root_face_is_meshed_on_its_symmetry_plane(self):
        # A half wing written without its root face (an open shell): the fit had no symmetry
        # plane, and the volume stage stopped ("the wall is open at wall patch 0 side v_min ...
        # give the symmetry plane it lies on"); the reference length was the span, 1219.
        folder = tempfile.mkdtemp(prefix="bvmesh-mesh-open-")
        wing = Part.read(os.path.join(DATA, "AileM6_with_sharp_TE.stp"))
        root = [i for i, face in enumerate(wing.Faces) if face.Surface.TypeId == "Part::GeomPlane"
                and face.BoundBox.YLength < 1e-6][0]
        cad = os.path.join(folder, "open_wing.step")
        Part.Shell([face for i, face in enumerate(wing.Faces) if i != root]).exportStep(cad)
        output = os.path.join(folder, "out")
        done = mesh(cad, "--template", "half_wing", "--template-parameter", "tip_kinks=follow", "--output", output,
                    "--max-level", "2", "--target-cells", "20000", "--formats", "openfoam")
        self.assertEqual(done.returncode, 2, done.stderr)  # level 2 is above the tolerance
        self.assertNotIn("VolumeMesh failed", done.stderr)
        report = read(os.path.join(output, "open_wing_report.md"))
        match = re.search(r"Target: all 10 faces of the CAD, a half model open on its symmetry plane; reference "
                          r"length ([0-9.]+);", report)
        self.assertIsNotNone(match, report)
        self.assertAlmostEqual(float(match.group(1)), 810.5, delta=0.5)
        volume_report = read(os.path.join(output, "open_wing_volume_report.md"))
        self.assertIn("checkMesh on open_wing_openfoam: Mesh OK.", volume_report)
        self.assertRegex(read(os.path.join(output, "open_wing_openfoam", "constant", "polyMesh", "boundary")),
                         r"\n\s*symmetry\s*\n\s*{\s*\n\s*type\s+symmetryPlane;")


class FullWing(unittest.TestCase):
    def test_the_mirrored_m6_is_fitted_and_meshed_on_its_root_chord(self):
        # The M6 fused with its mirror image: the trailing edge turns by 31 degrees at the root, where
        # the wedge's faces used to bulge 1 mm behind it (the fit stopped at 0.69 mm at level 3 and the
        # boundary layer folded); the reference length was the span (2437), and the automatic
        # marching level (level 1, the highest within 4000 points) folded at the trailing edge.
        folder = tempfile.mkdtemp(prefix="bvmesh-mesh-full-wing-")
        half = Part.read(os.path.join(DATA, "AileM6_with_sharp_TE.stp"))
        cad = os.path.join(folder, "full_wing.step")
        half.fuse(half.mirror(FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(0, 1, 0))).removeSplitter().exportStep(cad)
        output = os.path.join(folder, "out")
        done = mesh(cad, "--template", "wing", "--template-parameter", "tip_kinks=follow", "--output", output,
                    "--target-cells", "20000", "--formats", "openfoam")
        self.assertEqual(done.returncode, 0, done.stderr)  # converged, and checkMesh passes
        self.assertRegex(done.stdout, r"fit: converged at level 3,")
        match = re.search(r"Target: all 20 faces of the CAD; reference length ([0-9.]+);",
                          read(os.path.join(output, "full_wing_report.md")))
        self.assertIsNotNone(match)
        self.assertAlmostEqual(float(match.group(1)), 810.5, delta=0.5)
        volume_report = read(os.path.join(output, "full_wing_volume_report.md"))
        self.assertIn("layers marched from the fit refitted to level 2", volume_report)
        self.assertIn("checkMesh on full_wing_openfoam: Mesh OK.", volume_report)
        self.assertRegex(volume_report, r"Cells with a non-positive scaled Jacobian: 0;")


class WingInItsFlowDomain(unittest.TestCase):
    def test_reference_length_is_the_root_chord(self):
        # The M6 inside its half sphere, scaled to a unit root chord: the reference length is the
        # body's extent on the symmetry plane (the root section), as a half model's root face
        # gives it, not the wing's largest extent (its span, 1.5).
        output = tempfile.mkdtemp(prefix="bvmesh-mesh-m6-domain-")
        done = mesh(os.path.join(DATA, "onera-m6-sharp-te.stp"), "--template", "half_wing", "--output", output,
                    "--name", "wing", "--max-level", "1", "--surface-only")
        self.assertEqual(done.returncode, 2, done.stderr)  # level 1 is above the tolerance
        report = read(os.path.join(output, "wing_report.md"))
        match = re.search(r"Target: the body inside the CAD's flow domain \(sphere, 10 faces\); reference length "
                          r"([0-9.]+);", report)
        self.assertIsNotNone(match, report)
        self.assertAlmostEqual(float(match.group(1)), 1.0, delta=1e-3)


class LoftedWing(unittest.TestCase):
    """A half wing as Part lofts it (two NACA 0012 sections, swept, tapered, a flat tip): its sharp
    trailing edge's O-grid cells are skew beyond checkMesh's limit (11 here), so the mesh command
    cuts the edge open with fans of prisms, unless told which to take."""

    @staticmethod
    def wing():
        folder = tempfile.mkdtemp(prefix="bvmesh-mesh-loft-")
        cad = os.path.join(folder, "loft.step")
        sections = [naca0012_section(0.0, 0.0, 1.0), naca0012_section(0.5, 1.2, 0.4)]
        Part.makeLoft(sections, True, True).exportStep(cad)
        return cad, os.path.join(folder, "out")

    def run_mesh(self, *options):
        cad, output = self.wing()
        done = mesh(cad, "--template", "half_wing", "--half-model", "--output", output, "--max-level", "2",
                    "--tolerance", "1e-4", "--target-cells", "30000", "--formats", "openfoam", *options)
        return done, read(os.path.join(output, "loft_volume_report.md"))

    def test_skew_trailing_edge_cells_are_replaced_by_fans(self):
        done, report = self.run_mesh()
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertRegex(report, r"Knife edges cut open with fans of prisms \(knife_edge_fans, chosen because the "
                                 r"O-grid's largest skewness, [0-9.]+, is above checkMesh's 4; with the fans [0-3]\.")
        self.assertIn("checkMesh on loft_openfoam: Mesh OK.", report)

    def test_the_o_grid_asked_for_is_kept_with_its_warning(self):
        done, report = self.run_mesh("--volume-option", "knife_edge_fans=false")
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertIn("highly skew faces", done.stderr)
        self.assertIn("--volume-option knife_edge_fans=true replaces", done.stderr)
        self.assertNotIn("Knife edges cut open", report)


class BluntLoftedWing(unittest.TestCase):
    def test_a_corner_block_that_folds_sampled_coarsely_is_refined(self):
        # The lofted half wing with a base 0.25 % of the chord thick (tests/python/test_blunt_wing.py)
        # at the mesh command's fit: one or two cells across the blocks where the base meets the
        # flat tip, whose layers wrap round that corner, left 2 folded cells there (scaled Jacobian
        # -0.048; the blocks themselves are positive), and the writers refused the grid.
        from test_blunt_wing import BASE, half_wing

        folder = tempfile.mkdtemp(prefix="bvmesh-mesh-blunt-")
        cad = os.path.join(folder, "blunt.step")
        half_wing(BASE).exportStep(cad)
        done = mesh(cad, "--template", "half_wing", "--half-model", "--output", os.path.join(folder, "out"),
                    "--target-cells", "300000", "--formats", "openfoam")
        self.assertEqual(done.returncode, 0, done.stderr)
        report = read(os.path.join(folder, "out", "blunt_volume_report.md"))
        self.assertIn("The blocks with a folded cell took 2 times their tangential cells", report)
        self.assertIn("checkMesh on blunt_openfoam: Mesh OK.", report)


class UnmetGoals(unittest.TestCase):
    def test_skew_faces_point_to_the_knife_edge_fans(self):
        # Lofted wings' O-grids fail checkMesh's skewness at the sharp trailing edge's first cells
        # (docs/hostile_input.md), which the fans replace: the warning says so when they were off.
        from bvmesh import pipeline

        skew = "***Max skewness = 15.03, 76 highly skew faces detected which may impair the quality of the results"
        outcome = {"stop_reason": "converged", "check_mesh": skew, "knife_edge_fans": False}
        self.assertEqual(pipeline.unmet_goals(outcome), [
            "checkMesh on the OpenFOAM case: " + skew + "; skew faces at a sharp trailing edge are the O-grid's first "
            "cells there, which --volume-option knife_edge_fans=true replaces by a fan of prisms"])
        self.assertEqual(pipeline.unmet_goals(dict(outcome, knife_edge_fans=True)),
                         ["checkMesh on the OpenFOAM case: " + skew])
        # The mesh command tried the fans itself and kept the O-grid: no advice to try them.
        self.assertEqual(pipeline.unmet_goals(dict(outcome, knife_edge_fans_tried=True)),
                         ["checkMesh on the OpenFOAM case: " + skew])
        aspect = "***High aspect ratio cells found, Max aspect ratio: 35000, number of cells 12"
        self.assertEqual(pipeline.unmet_goals(dict(outcome, check_mesh=aspect)),
                         ["checkMesh on the OpenFOAM case: " + aspect])
        self.assertEqual(pipeline.unmet_goals(dict(outcome, check_mesh="Mesh OK.")), [])


class BadInput(unittest.TestCase):
    def test_refused_with_a_message(self):
        domain = os.path.join(DATA, "hemisph-cyl.stp")
        output = tempfile.mkdtemp(prefix="bvmesh-mesh-bad-")
        cases = [
            ((domain, "--template", "nosuch"), "no template named 'nosuch'"),
            ((domain, "--template", "capsule", "--half-model"), "leave out the half model"),
            # The M6 with its root face, under the half wing template without --half-model.
            ((os.path.join(DATA, "AileM6_with_sharp_TE.stp"), "--template", "half_wing"),
             "(leave out the root face); to leave out a half model's symmetry-plane face, run with --half-model"),
            ((domain, "--template", "capsule", "--template-parameter", "axial"), "KEY=VALUE"),
            ((domain, "--template", "capsule", "--template-parameter", "nosuch=3"), "has no parameter 'nosuch'"),
            ((domain, "--template", "capsule", "--preset", "rans"), "needs --reynolds"),
            ((domain, "--template", "capsule", "--formats", "cgns,stl"), "unknown format 'stl'"),
            ((domain, "--template", "capsule", "--volume-option", "domain=cube"),
             "volume mesh option 'domain' takes one of sphere, box, cylinder, cad, got 'cube'"),
            ((domain, "--template", "capsule", "--volume-option", "farfield=3"), "unknown volume mesh option 'farfield'"),
            ((domain, "--template", "capsule", "--grid-option", "normal_points=many"),
             "volume grid option 'normal_points' takes a whole number, got 'many'"),
            ((os.path.join(output, "missing.step"), "--template", "capsule"), "does not exist"),
            ((domain, "--template", "capsule", "--name", "a/b"), "name 'a/b' is not a file name"),
            ((domain, "--template", "capsule", "--reference-length", "nan"),
             "the reference length must be a positive number, got nan"),
            ((domain, "--template", "capsule", "--reference-length", "-2"),
             "the reference length must be a positive number, got -2.0"),
            # Refused when the volume mesh and the grid are computed.
            ((domain, "--template", "capsule", "--volume-option", "farfield_distance=5"),
             "Domain 'cad' takes the far field from the CAD's flow domain"),
            ((domain, "--template", "capsule", "--grid-option", "normal_points=-4"),
             "NormalPoints is -1 (the preset's) or not negative, got -4"),
        ]
        for arguments, message in cases:
            with self.subTest(arguments=arguments):
                done = mesh(*arguments, "--output", output, "--max-level", "1", timeout=300)
                self.assertEqual(done.returncode, 1, done.stdout + done.stderr)
                self.assertIn(message, done.stderr)
                self.assertNotIn("Traceback", done.stderr)
        # Option names are checked before the surface fit, which a batch run spent first.
        for option, message in ((("--volume-option", "farfield=3"), "unknown volume mesh option 'farfield'"),
                                (("--grid-option", "edges=3"), "unknown volume grid option 'edges'")):
            with self.subTest(option=option):
                done = mesh(domain, "--template", "capsule", *option, "--output", output, "--max-level", "1",
                            timeout=300)
                self.assertEqual(done.returncode, 1, done.stdout + done.stderr)
                self.assertIn(message, done.stderr)
                self.assertNotIn("fit:", done.stdout)

    def test_solids_that_run_into_each_other_are_named(self):
        # A wing through a fuselage written as two solids: the template was fitted over both, the
        # wing's root face inside the fuselage among the target's faces, and stopped 8e-3 of the
        # length from them at level 2 with only max_level said.
        folder = tempfile.mkdtemp(prefix="bvmesh-mesh-solids-")
        cad = os.path.join(folder, "parts.step")
        fuselage = Part.makeCylinder(0.6, 10, FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(1, 0, 0))
        wing = Part.makeBox(2, 4, 0.2, FreeCAD.Vector(4, -2, -0.1))
        Part.makeCompound([fuselage, wing]).exportStep(cad)
        done = mesh(cad, "--template", "capsule", "--output", os.path.join(folder, "out"), "--max-level", "1")
        self.assertEqual(done.returncode, 1, done.stdout + done.stderr)
        message = ("solids that run into each other: 1 and 2 (at (")
        self.assertIn("bvmesh: Target failed: ValueError: the Source parts holds " + message, done.stderr)
        self.assertIn("fuse them into one solid first (FreeCAD: Part, Boolean, Union)", done.stderr)
        self.assertIn("  " + message, done.stdout)  # the CAD's report says it first
        self.assertNotIn("Traceback", done.stderr)

    def test_output_folder_that_cannot_be_made(self):
        done = mesh(os.path.join(DATA, "hemisph-cyl.stp"), "--template", "capsule", "--output", "/proc/bvmesh-out",
                    "--max-level", "1")
        self.assertEqual(done.returncode, 1, done.stdout + done.stderr)
        self.assertIn("cannot create the output folder /proc/bvmesh-out: No such file or directory", done.stderr)
        self.assertNotIn("Traceback", done.stderr)


if __name__ == "__main__":
    unittest.main()

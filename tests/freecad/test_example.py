"""The README's main job (python -m bvmesh example), stopped at level 2: it writes a document
that reopens with every object, a STEP surface that reads back, a plot and a report, and the volume
stage's files: CGNS that cgnscheck passes, an OpenFOAM case that checkMesh accepts, pictures, and a
volume report whose figures a recomputation from the reopened document gives again."""

import os
import re
import subprocess
import tempfile
import unittest

import FreeCAD
import Part

from bvmesh import api, example, grid, pipeline


class MainJob(unittest.TestCase):
    def test_example_writes_document_step_plot_and_report(self):
        output = tempfile.mkdtemp(prefix="bvmesh-example-")
        result = example.run(output, max_level=2, log=lambda line: None)
        files = result["files"]
        self.assertEqual(result["level"], 2)
        self.assertAlmostEqual(result["chord"], 810.5, delta=0.5)
        self.assertLess(result["max_distance"], 0.05 * result["chord"])

        surface = Part.read(files["step"])
        self.assertGreater(len(surface.Faces), 1)
        self.assertTrue(surface.isValid())

        doc = FreeCAD.openDocument(files["document"])
        try:
            kinds = sorted(o.Proxy.Type for o in doc.Objects if hasattr(o, "Proxy") and hasattr(o.Proxy, "Type"))
            self.assertEqual(kinds, ["BVMesh::BsplineShell", "BVMesh::ControlPolyhedron", "BVMesh::Export",
                                     "BVMesh::Export", "BVMesh::GridCut", "BVMesh::MeshQuality",
                                     "BVMesh::SurfaceFit", "BVMesh::Target", "BVMesh::VolumeGrid",
                                     "BVMesh::VolumeMesh"])
            # The STEP shell's charts are tangent-continuous: 0.57 degrees at worst at level 2 (next
            # to the trailing edge's tip corner), 3.2 fitted on their own.
            shell = doc.getObject("BsplineShell")
            self.assertTrue(shell.TangentContinuity)
            self.assertLess(shell.MaxKinkDegrees, 1.0)
            visible = sorted(o.Name for o in doc.Objects if o.Visibility)
            self.assertEqual(visible, ["GridCut", "VolumeGrid"])
            # The report's figures again from the reopened document (blocks marched and points
            # evaluated again, checked against the saved digests).
            grid_object = doc.getObject("VolumeGrid")
            refined = api.grid_of(grid_object)
            recomputed = grid.quality(refined)
            # Every wall-normal line grows by at most the euler preset's 1.2 in point spacings
            # (1.2063 where the lines bend when the law was held in arc length).
            self.assertLessEqual(refined.growth_max, 1.2 * (1 + 1e-9))
            self.assertLessEqual(grid_object.GrowthMax, 1.2 * (1 + 1e-9))
            with open(files["volume_report"]) as report:
                volume_report = report.read()
            self.assertIn(grid.quality_table(recomputed).strip(), volume_report)
            self.assertIn("{} cells".format(grid_object.CellCount), volume_report)
            self.assertGreater(grid_object.CellCount, 900000)
            # The tip corner's 1 mm blocks get the points their wall edges need: when their
            # far-field edges set the counts, 616 cells had a face above 70 degrees, up to 83; the
            # spacing-jump limit at block corners took the 26 left (up to 78.4) to 14 (75.6).
            non_orthogonality = recomputed["non_orthogonality"]
            self.assertLess(int((non_orthogonality > 70.0).sum()), 20)
            self.assertLess(float(non_orthogonality.max()), 77.0)
            # The wall's distance from the CAD, measured on the grid (here the level-2 wall: 1.2e-2).
            reported = re.search(r"wall points lie within ([-+.e0-9]+) of the CAD faces", volume_report)
            self.assertAlmostEqual(float(reported.group(1)), pipeline.wall_distance(grid_object), delta=1e-5)
            self.assertLess(float(reported.group(1)), 0.02)
        finally:
            FreeCAD.closeDocument(doc.Name)

        cgns = subprocess.run(["cgnscheck", files["cgns"]], capture_output=True, text=True, timeout=600).stdout
        self.assertIn("checking complete", cgns)
        self.assertNotRegex(cgns, r"(?i)error", cgns)
        verdict = pipeline.check_mesh(files["openfoam"])
        self.assertEqual(verdict, "Mesh OK.")
        self.assertIn("checkMesh on M6_openfoam: Mesh OK.", volume_report)
        self.assertEqual(result["check_mesh"], verdict)
        for picture in ("cut", "quality"):
            self.assertGreater(os.path.getsize(files[picture]), 50000)
        match = re.search(r"far field: sphere of radius ([0-9.]+)", volume_report)
        self.assertAlmostEqual(float(match.group(1)) / result["chord"], 20.0, delta=0.1)
        self.assertIn("reference lengths), marched hyperbolic.", volume_report)

        self.assertGreater(os.path.getsize(files["plot"]), 10000)
        with open(files["report"]) as report:
            text = report.read()
        self.assertIn("| 2 |", text)
        self.assertIn("valid: True", text)
        self.assertIn("B-spline surface (charts tangent-continuous across their borders)", text)

    def test_subdivision_grid_method(self):
        # --grid-method subdivision: the grid is the fit's control mesh marched and refined once.
        output = tempfile.mkdtemp(prefix="bvmesh-example-subdivision-")
        result = example.run(output, max_level=2, log=lambda line: None, grid_method="subdivision")
        files = result["files"]
        with open(files["volume_report"]) as report:
            volume_report = report.read()
        self.assertIn("refined by 1 volumetric Catmull-Clark step(s)", volume_report)
        self.assertIn("Cells with a non-positive scaled Jacobian: 0;", volume_report)
        doc = FreeCAD.openDocument(files["document"])
        try:
            grid_object = doc.getObject("VolumeGrid")
            self.assertEqual(grid_object.Method, "subdivision")
            self.assertGreater(grid_object.CellCount, 600000)
            self.assertIn("{} cells".format(grid_object.CellCount), volume_report)
        finally:
            FreeCAD.closeDocument(doc.Name)
        cgns = subprocess.run(["cgnscheck", files["cgns"]], capture_output=True, text=True, timeout=600).stdout
        self.assertIn("checking complete", cgns)
        self.assertNotRegex(cgns, r"(?i)error", cgns)


if __name__ == "__main__":
    unittest.main()

"""The README's main job (python -m bvmesh example) at two levels: it writes a document that
reopens with every object, a STEP surface that reads back, a plot and a report."""

import os
import tempfile
import unittest

import FreeCAD
import Part

from bvmesh import example


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
            self.assertEqual(kinds, ["BVMesh::BsplineShell", "BVMesh::ControlPolyhedron", "BVMesh::SurfaceFit",
                                     "BVMesh::Target"])
        finally:
            FreeCAD.closeDocument(doc.Name)

        self.assertGreater(os.path.getsize(files["plot"]), 10000)
        with open(files["report"]) as report:
            text = report.read()
        self.assertIn("| 2 |", text)
        self.assertIn("valid: True", text)


if __name__ == "__main__":
    unittest.main()

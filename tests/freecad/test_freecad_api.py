"""The headless API inside FreeCAD (freecadcmd): BREP round trip with Part, errors, document."""

import os
import unittest

import FreeCAD
import Part

from bvmesh import api
from bvmesh.adapters import shapes

DATA = os.environ.get("BVMESH_TEST_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "data"))
WING = os.path.join(DATA, "AileM6_with_sharp_TE.stp")


class BrepRoundTrip(unittest.TestCase):
    def setUp(self):
        self.doc = FreeCAD.newDocument("BVMeshApiTest")

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_wing_read_by_freecad_is_summarized_by_the_core(self):
        shape = Part.read(WING)
        report = api.shape_report(shape)
        self.assertEqual(report["faces"], 11)
        self.assertEqual(report["surface_types"].count("BSplineSurface"), 8)
        # The core's face order is FreeCAD's: Face<i+1> has the reported surface type.
        for i, face in enumerate(shape.Faces):
            expected = {"Part::GeomBSplineSurface": "BSplineSurface", "Part::GeomPlane": "Plane"}[face.Surface.TypeId]
            self.assertEqual(report["surface_types"][i], expected)
            self.assertAlmostEqual(report["face_areas"][i], face.Area, delta=1e-6 * face.Area)
        box = shape.optimalBoundingBox()
        low, high = report["bounds"]
        self.assertAlmostEqual(high[0], box.XMax, delta=1e-3)
        self.assertAlmostEqual(low[2], box.ZMin, delta=1e-3)

    def test_import_cad_adds_a_valid_feature(self):
        feature = api.import_cad(self.doc, WING)
        self.assertEqual(len(feature.Shape.Faces), 11)
        self.assertTrue(feature.Shape.isValid())
        self.assertEqual(feature.Label, "AileM6_with_sharp_TE")

    def test_bspline_face_comes_back_as_a_valid_part_face(self):
        poles = [[[i, j, 0.05 * (i * i - j * j)] for j in range(5)] for i in range(4)]
        face = api.make_bspline_face(poles, [0.0, 1.0], [0.0, 0.5, 1.0], [4, 4], [4, 1, 4])
        self.assertIsInstance(face, Part.Face)
        self.assertTrue(face.isValid())
        surface = face.Surface
        self.assertIsInstance(surface, Part.BSplineSurface)
        self.assertEqual((surface.UDegree, surface.VDegree), (3, 3))
        self.assertEqual((surface.NbUPoles, surface.NbVPoles), (4, 5))
        corner = surface.value(1.0, 1.0)
        self.assertAlmostEqual(corner.z, 0.05 * (9 - 16), places=12)
        feature = self.doc.addObject("Part::Feature", "Patch")
        feature.Shape = face
        self.doc.recompute()
        self.assertTrue(feature.Shape.isValid())

    def test_bad_input_leaves_the_document_untouched(self):
        before = [o.Name for o in self.doc.Objects]
        with self.assertRaisesRegex(ValueError, "does not exist"):
            api.import_cad(self.doc, os.path.join(DATA, "nothing_here.step"))
        with self.assertRaisesRegex(ValueError, "null"):
            api.shape_report(Part.Shape())
        with self.assertRaisesRegex(ValueError, "expected a Part.Shape"):
            api.shape_report(42)
        with self.assertRaisesRegex(ValueError, "expected a Part.Shape"):
            shapes.shape_to_brep("not a shape")
        self.assertEqual([o.Name for o in self.doc.Objects], before)


if __name__ == "__main__":
    unittest.main()

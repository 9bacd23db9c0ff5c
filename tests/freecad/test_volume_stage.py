"""The volume stage's document objects in freecadcmd, on a fitted sphere: volume mesh, grid, cut,
quality and exports through bvmesh.api; the closed forms of the sphere; bad options leave the
document as it was; save, reopen and recompute give identical blocks and points."""

import os
import tempfile
import unittest

import numpy as np

import FreeCAD
import Part

from bvmesh import api, grid as grid_module
from bvmesh.features.common import is_type
from console_capture import console_errors

RADIUS = 1.0
DATA = os.environ.get("BVMESH_TEST_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "data"))


def enumerations(objects):
    """{(object name, property): (choices, value)} of the objects' enumeration properties."""
    return {(obj.Name, prop): (obj.getEnumerationsOfProperty(prop), getattr(obj, prop)) for obj in objects
            for prop in obj.PropertiesList if obj.getTypeIdOfProperty(prop) == "App::PropertyEnumeration"}


def sphere_fit(doc):
    ball = doc.addObject("Part::Feature", "Ball")
    ball.Shape = Part.makeSphere(RADIUS)
    target = api.make_target(doc, ball)
    polyhedron = api.make_polyhedron_from_template(doc, target, "sphere")
    # Converged at level 3 (level 2's samples are 1.7e-4 from the sphere): the tests march from
    # lower levels.
    fit = api.make_surface_fit(doc, target, polyhedron, relative_tolerance=3e-5, max_level=3)
    return api.fit_to_tolerance(fit)


class VolumeObjects(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.mkdtemp(prefix="bvmesh-volume-stage-")
        cls.doc = FreeCAD.newDocument("VolumeStage")
        cls.fit = sphere_fit(cls.doc)
        cls.volume = api.make_volume_mesh(cls.fit, boundary_layer_thickness=0.05, farfield_distance=20.0)
        cls.grid = api.make_volume_grid(cls.volume, "euler", edge_points=9, normal_points=25)

    @classmethod
    def tearDownClass(cls):
        FreeCAD.closeDocument(cls.doc.Name)

    def test_volume_mesh_has_the_sphere_blocks_and_its_faces(self):
        vm = self.volume
        self.assertEqual(vm.BlockCount, 6)
        self.assertAlmostEqual(vm.FarfieldDistanceUsed, 20.0)
        self.assertAlmostEqual(vm.BoundaryLayerThicknessUsed, 0.05)
        self.assertEqual(len(vm.Digest), 40)
        # Shown by default: the wall faces (a closed sphere has no symmetry plane): 6 B-spline faces
        # on the fitted sphere, coloured by block.
        self.assertEqual(len(vm.Shape.Faces), 6)
        self.assertEqual(sorted(vm.FaceBlocks), list(range(6)))
        for face in vm.Shape.Faces:
            for u, v in ((0.2, 0.3), (0.5, 0.5), (0.9, 0.1)):
                low_u, high_u, low_v, high_v = face.ParameterRange
                p = face.valueAt(low_u + u * (high_u - low_u), low_v + v * (high_v - low_v))
                self.assertAlmostEqual(p.Length, RADIUS, delta=1e-3)
        api.set_volume_options(vm, show=("farfield",))
        try:
            self.assertEqual(len(vm.Shape.Faces), 6)
            self.assertAlmostEqual(vm.Shape.Faces[0].valueAt(0.5, 0.5).Length, 20.0, delta=0.01 * 20.0)
        finally:
            api.set_volume_options(vm, show=("wall", "symmetry"))

    def test_grid_layers_are_spheres_and_the_cut_is_in_its_plane(self):
        g = self.grid
        refined = api.grid_of(g)
        self.assertEqual(g.CellCount, refined.grid.cell_count)
        self.assertEqual(g.CellCount, 6 * 8 * 8 * 24)
        points = refined.grid.points(0)
        radii = np.linalg.norm(points, axis=3)
        # The far-field face interpolates the sphere of radius 20 at its poles' Greville points, so
        # between them it stays within the 1 % of the distance.
        self.assertLess(np.abs(radii[:, :, -1] - 20.0).max(), 0.01 * 20.0)
        self.assertLess(np.abs(radii[:, :, 0] - RADIUS).max(), 1e-3)
        cut = api.make_grid_cut(g, point=(0.0, 0.3, 0.0), normal=(0.0, 1.0, 0.0), metric="scaled_jacobian")
        try:
            self.assertGreater(cut.SegmentCount, 100)
            self.assertEqual(len(cut.Shape.Edges), cut.SegmentCount)
            for edge in cut.Shape.Edges[::50]:
                for vertex in edge.Vertexes:
                    self.assertAlmostEqual(vertex.Point.y, 0.3, delta=1e-12)
            report = grid_module.quality(refined)
            self.assertGreaterEqual(cut.ValueMin, report["summary"]["scaled_jacobian"]["min"])
            self.assertLessEqual(cut.ValueMax, report["summary"]["scaled_jacobian"]["max"])
        finally:
            self.doc.removeObject(cut.Name)

    def test_turning_limit_property_sets_the_counts(self):
        # A spacing of a diameter alone gives 2 points per block edge on the sphere; its wall edges
        # turn through about 70 degrees, so a 10-degree limit gives them 8 or more.
        plain = api.make_volume_grid(self.volume, "euler", tangential_spacing=2.0 * RADIUS, normal_points=5)
        turned = api.make_volume_grid(self.volume, "euler", tangential_spacing=2.0 * RADIUS, normal_points=5,
                                      max_turning_angle=10.0)
        try:
            self.assertEqual(plain.MaxTurningAngle, 0.0)
            self.assertEqual(turned.MaxTurningAngle, 10.0)
            sizes = [api.grid_of(g).grid.size(0)[:2] for g in (plain, turned)]
            self.assertEqual(sizes[0], (2, 2))
            self.assertGreaterEqual(min(sizes[1]), 8)
        finally:
            for g in (plain, turned):
                self.doc.removeObject(g.Name)
        names = [o.Name for o in self.doc.Objects]
        with self.assertRaisesRegex(Exception, "max_turning_angle"):
            api.make_volume_grid(self.volume, "euler", max_turning_angle=200.0)
        self.assertEqual([o.Name for o in self.doc.Objects], names)

    def test_spacing_jump_limit_is_on_for_new_grids_and_off_for_restored_ones(self):
        # A grid saved before the option existed is restored without the property: it gets 0, the
        # limit off, so its grid is the one it was saved with (its digest); a new grid gets -1, the
        # preset's limit (euler 3, rans 4), which it passes on by leaving the option out.
        from bvmesh.features import volume_grid

        grid = api.make_volume_grid(self.volume, "euler", edge_points=5, normal_points=5)
        try:
            self.assertEqual(grid.MaxSpacingJump, -1.0)
            self.assertNotIn("max_spacing_jump", volume_grid.refine_options(grid))
            grid.MaxSpacingJump = 4.0
            self.assertEqual(volume_grid.refine_options(grid)["max_spacing_jump"], 4.0)
            grid.removeProperty("MaxSpacingJump")
            grid.Proxy.setup(grid)
            self.assertEqual(grid.MaxSpacingJump, 0.0)
        finally:
            self.doc.removeObject(grid.Name)

    def test_even_far_field_is_on_for_new_grids_and_off_for_restored_ones(self):
        # A new grid slides its far-field lines (the presets' default); turning it off gives the
        # grid of the marching's own distribution, as a grid saved before the property had.
        grid = api.make_volume_grid(self.volume, "euler", edge_points=5, normal_points=9)
        try:
            self.assertTrue(grid.EvenFarField)
            slid = grid.Digest
            api.set_grid_options(grid, even_far_field=False)
            self.assertFalse(grid.EvenFarField)
            self.assertNotEqual(grid.Digest, slid)
            grid.removeProperty("EvenFarField")
            grid.Proxy.setup(grid)
            self.assertFalse(grid.EvenFarField)
        finally:
            self.doc.removeObject(grid.Name)

    def test_feature_edges_set_the_spacing_where_lines_leave_them(self):
        # A line along the sphere's normal through a corner of its cube layout, as a document
        # object's edge: the wall lines leaving that corner start at FeatureSpacing.
        wall = grid_module.wall_points(api.grid_of(self.grid))
        corner = wall[np.argmax(wall.sum(axis=1))]
        line = self.doc.addObject("Part::Feature", "CornerLine")
        line.Shape = Part.makeLine(FreeCAD.Vector(*(0.9 * corner)), FreeCAD.Vector(*(1.1 * corner)))
        spacing = 0.02
        grid = api.make_volume_grid(self.volume, "euler", edge_points=9, normal_points=9,
                                    feature_edges=[(line, "Edge1")], feature_spacing=spacing)
        try:
            points = grid_module.wall_points(api.grid_of(grid))
            distance = np.linalg.norm(points - corner, axis=1)
            self.assertAlmostEqual(distance[distance > 1e-9].min() / spacing, 1.0, delta=1e-3)
            names = [o.Name for o in self.doc.Objects]
            digest = grid.Digest
            with self.assertRaisesRegex(Exception, "not an edge"):
                api.set_grid_options(grid, feature_edges=[(line, "Vertex1")])
            with self.assertRaisesRegex(Exception, "needs FeatureEdges"):
                api.set_grid_options(grid, feature_edges=[])
            # A link to a deleted object, or to one of a closed document, killed FreeCAD at the
            # next read of FeatureEdges (FreeCAD 0.20 keeps a dangling pointer): refused first.
            gone = self.doc.addObject("Part::Feature", "GoneLine")
            gone.Shape = line.Shape
            self.doc.removeObject("GoneLine")
            other = FreeCAD.newDocument("OtherDocument")
            elsewhere = other.addObject("Part::Feature", "Elsewhere")
            elsewhere.Shape = line.Shape
            for bad in (gone, elsewhere):
                with self.assertRaisesRegex(ValueError, r"feature_edges: .* is no object of document"):
                    api.set_grid_options(grid, feature_edges=[(bad, "Edge1")])
            FreeCAD.closeDocument("OtherDocument")
            with self.assertRaisesRegex(ValueError, r"is no object of document"):
                api.make_volume_grid(self.volume, "euler", feature_edges=[(elsewhere, "Edge1")], feature_spacing=0.1)
            with self.assertRaisesRegex(ValueError, r"takes \(object, edge name or names\) pairs"):
                api.set_grid_options(grid, feature_edges=[line])
            self.assertEqual(([o.Name for o in self.doc.Objects], grid.Digest), (names, digest))
            self.assertEqual(len(grid.FeatureEdges), 1)
            # A grid restored from a document saved before the properties existed is unchanged.
            api.set_grid_options(grid, feature_edges=[], feature_spacing=0.0)
            plain = grid.Digest
            for prop in ("FeatureEdges", "FeatureSpacing"):
                grid.removeProperty(prop)
            grid.Proxy.setup(grid)
            grid.touch()
            self.doc.recompute()
            self.assertEqual(grid.Digest, plain)
        finally:
            self.doc.removeObject(grid.Name)
            self.doc.removeObject(line.Name)

    def test_failed_calls_leave_their_objects_as_they_were(self):
        # Each of these raised but kept its bad values (the fit's max_level 3 even made the next,
        # unrelated call refit), and a call on an object whose input had failed returned as if
        # done: FreeCAD skips such an object and leaves it touched.
        fit, poly = self.fit, self.fit.Polyhedron

        def state():
            return (list(poly.Creases), list(poly.Corners), len(poly.Vertices), fit.MaxLevel, fit.Solver,
                    fit.UseSymmetryPlane, tuple(fit.SymmetryNormal), self.volume.Digest, self.grid.Digest)

        before = state()
        for call in (lambda: api.mark_features(poly, creases=[(0, 99)]),
                     lambda: api.set_polyhedron(poly, [(0, 0, 0)] * 3, [[0, 1, 2]]),
                     lambda: api.set_fit_parameters(fit, max_level=3, solver="bogus"),
                     lambda: api.set_fit_parameters(fit, symmetry_plane=((0, 0, 0), (0, 0, 0)))):
            with self.assertRaises(Exception):
                call()
            self.assertEqual(state(), before)
            self.assertTrue(all(o.isValid() and "Touched" not in o.State for o in (poly, fit, self.volume, self.grid)))
        fit.MaxLevel = -1  # set by hand: the fit fails on recompute
        try:
            with self.assertRaisesRegex(RuntimeError, r"VolumeMesh was not computed: SurfaceFit failed: .*max_level"):
                api.set_volume_options(self.volume, farfield_distance=25.0)
            self.assertEqual(self.volume.FarfieldDistance, 20.0)
        finally:
            fit.MaxLevel = before[3]
            self.doc.recompute()
        self.assertEqual(state(), before)

    def test_links_that_would_make_a_dependency_cycle_are_refused(self):
        # FreeCAD 0.20 takes a Target whose Source is the volume mesh made from it: every recompute
        # then ran the target, the fit and the volume mesh again in two passes (the target turned
        # into the volume's wall, the fit refitted to it) and left one touched, with no error.
        target = self.fit.Target
        ball = target.Source
        results = (target.BrepHash, self.fit.MaxDistance, self.volume.Digest, self.grid.Digest)
        with console_errors() as errors:
            target.Source = self.volume
        self.assertEqual(target.Source.Name, ball.Name)
        self.assertIn("Target.Source cannot link VolumeMesh, which depends on it (VolumeMesh -> SurfaceFit -> Target): "
                      "a dependency cycle; Ball is kept", "".join(errors))
        self.doc.recompute()
        self.assertEqual((target.BrepHash, self.fit.MaxDistance, self.volume.Digest, self.grid.Digest), results)
        # Closed by a link of an object that is not BVMesh's (a Part Refine of the volume mesh, the
        # target's Source already), the cycle fails on recompute, named, and nothing on it runs.
        refined = self.doc.addObject("Part::Refine", "Refined")
        cycle = (target, self.fit, self.volume)
        try:
            target.Source = refined
            refined.Source = self.volume
            for _ in range(2):
                self.doc.recompute()
                failed = [o for o in cycle if not o.isValid()]
                self.assertTrue(failed)
                self.assertRegex(failed[0].Proxy.error, r"ValueError: a dependency cycle: \w+( -> \w+){4} \(each uses")
                for obj in cycle + (refined,):
                    self.assertIn(obj.Label, failed[0].Proxy.error)
                self.assertEqual((target.BrepHash, self.fit.MaxDistance, self.volume.Digest, self.grid.Digest),
                                 results)
            with self.assertRaisesRegex(RuntimeError, "a dependency cycle"):
                api.set_volume_options(self.volume, farfield_distance=25.0)
        finally:
            target.Source = ball
            self.doc.removeObject(refined.Name)
            self.doc.recompute()
        self.assertEqual((target.BrepHash, self.fit.MaxDistance, self.volume.Digest, self.grid.Digest), results)
        self.assertEqual(self.volume.FarfieldDistance, 20.0)
        # A grid's feature edge on an object made from the grid is refused by the API.
        cut = api.make_grid_cut(self.grid, point=(0.0, 0.3, 0.0), normal=(0.0, 1.0, 0.0))
        try:
            with self.assertRaisesRegex(ValueError, r"feature_edges: GridCut depends on VolumeGrid \(GridCut -> "
                                                    r"VolumeGrid\): a dependency cycle"):
                api.set_grid_options(self.grid, feature_edges=[(cut, "Edge1")], feature_spacing=0.1)
            self.assertEqual((len(self.grid.FeatureEdges), self.grid.Digest), (0, results[3]))
        finally:
            self.doc.removeObject(cut.Name)
        self.assertTrue(all(o.isValid() and "Touched" not in o.State for o in self.doc.Objects))

    def enumerated_objects(self):
        """A cut and an export beside the fit, volume mesh and grid: every BVMesh feature with an
        enumeration, and {(object, property): (choices, value)} of those enumerations."""
        cut = api.make_grid_cut(self.grid, point=(0.0, 0.3, 0.0), normal=(0.0, 1.0, 0.0), metric="skewness")
        export = api.export_grid(self.grid, os.path.join(self.folder, "choices.cgns"), name="Export")
        objects = (self.fit, self.volume, self.grid, cut, export)
        return objects, enumerations(objects)

    def test_a_list_assigned_to_an_enumeration_is_refused(self):
        # In FreeCAD, assigning a list to an enumeration replaces its choices instead of setting
        # its value: a typo (grid.Preset = ["rans"]) or a macro changed what the property offered
        # and what the recompute read (the first of the new choices), without a word.
        objects, before = self.enumerated_objects()
        cut, export = objects[3:]
        results = (self.fit.MaxDistance, self.volume.Digest, self.grid.Digest, cut.SegmentCount, export.Written)
        names = [o.Name for o in self.doc.Objects]
        try:
            self.assertEqual(sorted(before), [("Export", "Format"), ("Export", "Solver"), ("GridCut", "Metric"),
                                              ("SurfaceFit", "Solver"), ("VolumeGrid", "Distribution"),
                                              ("VolumeGrid", "Method"), ("VolumeGrid", "Preset"),
                                              ("VolumeMesh", "Domain"), ("VolumeMesh", "FarfieldScheme")])
            for (name, prop), (choices, value) in before.items():
                obj = self.doc.getObject(name)
                other = next(choice for choice in choices if choice != value)
                for given in ([other], [value, "typo"], list(reversed(choices)), []):
                    with console_errors() as errors:
                        setattr(obj, prop, given)
                    self.assertEqual((obj.getEnumerationsOfProperty(prop), getattr(obj, prop)), (choices, value))
                    self.assertIn("BVMesh: {}.{} takes one of {} as its value; a list would replace these choices "
                                  "(given: [{}]), refused: its choices are kept and its value stays {}\n".format(
                                      name, prop, ", ".join(choices), ", ".join(given), value), "".join(errors))
                # A value is still set by name.
                with console_errors() as errors:
                    setattr(obj, prop, other)
                    setattr(obj, prop, value)
                self.assertNotIn("BVMesh", "".join(errors))
            # Through the API: raised, the object as it was, no object added.
            with self.assertRaisesRegex(ValueError, r"VolumeGrid.Preset takes one of euler, rans as its value; a list "
                                                    r"would replace these choices \(given: \[rans\]\), refused"):
                api.set_grid_options(self.grid, preset=["rans"])
            with self.assertRaisesRegex(ValueError, r"GridCut\d*.Metric takes one of block, .* \(given: \[block\]\)"):
                api.make_grid_cut(self.grid, point=(0.0, 0.3, 0.0), normal=(0.0, 1.0, 0.0), metric=["block"])
            self.assertEqual([o.Name for o in self.doc.Objects], names)
            self.assertEqual(enumerations(objects), before)
            self.doc.recompute()
            self.assertEqual((self.fit.MaxDistance, self.volume.Digest, self.grid.Digest, cut.SegmentCount,
                              export.Written), results)
            self.assertTrue(all(o.isValid() and "Touched" not in o.State for o in self.doc.Objects))
        finally:
            for obj in (cut, export):
                self.doc.removeObject(obj.Name)

    def test_a_file_with_changed_choices_comes_back_with_the_features_own(self):
        # FreeCAD keeps an enumeration's choices in the file and its value as an index into them:
        # a damaged or edited Document.xml gave the object other choices and, through the index,
        # another value. The value is now saved by name with the proxy as well.
        import base64
        import json
        import re
        import zipfile

        objects, before = self.enumerated_objects()
        try:
            self.assertEqual(before[("VolumeMesh", "FarfieldScheme")], (["smoothed", "hyperbolic"], "hyperbolic"))
            self.assertEqual(before[("GridCut", "Metric")][1], "skewness")
            with console_errors():  # refused, as above
                for (name, prop), (_, value) in before.items():
                    setattr(self.doc.getObject(name), prop, [value, "typo"])
            self.doc.recompute()
            path = os.path.join(self.folder, "choices.FCStd")
            self.doc.saveCopy(path)
        finally:
            for obj in objects[3:]:
                self.doc.removeObject(obj.Name)
        with zipfile.ZipFile(path) as intact:
            members = {name: intact.read(name) for name in intact.namelist()}
        xml = members["Document.xml"].decode()

        def edit(xml, name, prop, change):
            data = xml.index('<Object name="{}">'.format(name), xml.index("<ObjectData"))
            start = xml.index('<Property name="{}"'.format(prop), data)
            end = xml.index("</Property>", start)
            return xml[:start] + change(xml[start:end]) + xml[end:]

        def without_saved_values(text):  # as a file written before the values were saved
            def strip(match):
                state = json.loads(base64.b64decode(match.group(1)))
                del state["enumerations"]
                return 'value="{}"'.format(base64.b64encode(json.dumps(state).encode()).decode())

            return re.sub(r'value="([^"]+)"', strip, text)

        for name, prop, change in (
                ("SurfaceFit", "Solver", lambda text: re.sub(r"<CustomEnumList.*</CustomEnumList>", "", text,
                                                             flags=re.S).replace(' CustomEnum="true"', "")),
                ("VolumeMesh", "Domain", lambda text: text.replace('"sphere"', '"zz"')),
                # An older version's choices, fewer than the feature's: put back without a word.
                ("VolumeMesh", "FarfieldScheme", lambda text: text.replace('<Enum value="smoothed"/>', "").replace(
                    'count="2"', 'count="1"').replace('Integer value="1"', 'Integer value="0"')),
                ("VolumeGrid", "Method", lambda text: text.replace('"bspline"', '"swap"').replace(
                    '"subdivision"', '"bspline"').replace('"swap"', '"subdivision"')),
                ("Export", "Format", lambda text: text.replace('Integer value="0"', 'Integer value="3"')),
                ("GridCut", "Metric", lambda text: re.sub(r'<Enum value="(\w+)"/>', r'<Enum value="\1_"/>', text)),
                ("GridCut", "Proxy", without_saved_values)):
            xml = edit(xml, name, prop, change)
        damaged = os.path.join(self.folder, "choices_damaged.FCStd")
        with zipfile.ZipFile(damaged, "w") as file:
            for member, data in dict(members, **{"Document.xml": xml.encode()}).items():
                file.writestr(member, data)

        def reopen(file_path):
            with console_errors() as errors:
                doc = FreeCAD.openDocument(file_path)
            return doc, "".join(errors)

        doc, errors = reopen(path)
        try:
            self.assertNotIn("BVMesh", errors)
            self.assertEqual(enumerations([doc.getObject(name) for name, _ in before]), before)
        finally:
            FreeCAD.closeDocument(doc.Name)
        doc, errors = reopen(damaged)
        try:
            self.assertEqual(enumerations([doc.getObject(name) for name, _ in before]),
                             {**before, ("GridCut", "Metric"): (before[("GridCut", "Metric")][0], "block")})
            came_back = "BVMesh: {} came back from the file with {} (the file is damaged or was edited): its own " \
                        "choices {} are put back, {}\n"
            for name, prop, what, value in (
                    ("SurfaceFit", "Solver", "the choices [] and no value",
                     "with the value cholesky saved with the object"),
                    ("VolumeMesh", "Domain", "the choices [zz, box, cylinder, cad] and the value zz",
                     "with the value sphere saved with the object"),
                    ("VolumeGrid", "Method", "the choices [subdivision, bspline] and the value subdivision",
                     "with the value bspline saved with the object"),
                    ("Export", "Format", "the value plot3d", "with the value cgns saved with the object"),
                    ("GridCut", "Metric", "the choices [{}] and the value skewness_".format(
                        ", ".join(choice + "_" for choice in before[("GridCut", "Metric")][0])),
                     "but the value it held is lost: it is block until it is set again, and GridCut does not "
                     "recompute until then")):
                self.assertIn(came_back.format(name + "." + prop, what, ", ".join(before[(name, prop)][0]), value),
                              errors)
            self.assertEqual(errors.count("BVMesh"), 5)
            # The cut, whose value is lost, refuses to recompute until it is set again; the rest is
            # as it was saved.
            doc.recompute()
            cut = doc.getObject("GridCut")
            self.assertFalse(cut.isValid())
            self.assertIn("Metric of GridCut came back from the file lost", cut.Proxy.error)
            self.assertEqual([o.Name for o in doc.Objects if not o.isValid() or "Touched" in o.State], ["GridCut"])
            cut.Metric = "skewness"
            doc.recompute()
            self.assertTrue(all(o.isValid() and "Touched" not in o.State for o in doc.Objects))
        finally:
            FreeCAD.closeDocument(doc.Name)

    def test_span_station_cut_of_a_body_without_symmetry_plane(self):
        point, normal = api.span_station(self.grid, 0.5)
        self.assertAlmostEqual(point.y, 0.0, delta=1e-2)
        self.assertEqual(tuple(normal), (0.0, 1.0, 0.0))

    def test_quality_and_exports(self):
        histogram = os.path.join(self.folder, "quality.png")
        quality = api.make_mesh_quality(self.grid, histogram_path=histogram)
        self.assertEqual(quality.Cells, self.grid.CellCount)
        self.assertEqual(quality.NonPositiveCells, 0)
        self.assertGreater(quality.MinScaledJacobian, 0.5)
        self.assertIn("| scaled_jacobian |", quality.Table)
        determinant = quality.Proxy.report(quality)["determinant"]
        self.assertEqual(quality.SmallDeterminantCells, int((determinant < 1e-3).sum()))
        self.assertEqual(quality.MinDeterminant, determinant.min())
        self.assertIn("| determinant |", quality.Table)
        with open(histogram, "rb") as image:
            self.assertEqual(image.read(8), b"\x89PNG\r\n\x1a\n")
        written = {}
        for ending in (".cgns", ".xyz", ".vtm", ".xml", ".blocks", ""):
            path = os.path.join(self.folder, "sphere" + ending if ending else "sphere_case")
            export = api.export_grid(self.grid, path, name="Export")
            written[export.Format] = path
            self.assertEqual(export.Written, self.grid.Digest)
            self.assertTrue(os.path.exists(path), path)
        self.assertEqual(sorted(written), ["blocks", "cgns", "gismo", "openfoam", "plot3d", "vtk"])
        flow_case = os.path.join(self.folder, "sphere_flow")
        api.export_grid(self.grid, flow_case, file_format="openfoam_case", name="Export")
        for part in ("0/p", "0/U", "0/T", "constant/thermophysicalProperties", "system/controlDict",
                     "constant/polyMesh/points"):
            self.assertTrue(os.path.isfile(os.path.join(flow_case, part)), part)
        self.assertTrue(os.path.isfile(os.path.join(written["openfoam"], "constant", "polyMesh", "owner")))
        blocks = grid_module.load_core().read_block_mesh(written["blocks"])
        self.assertEqual(blocks.block_count, 6)
        read = grid_module.read_plot3d(written["plot3d"])
        self.assertTrue(np.array_equal(read[0], api.grid_of(self.grid).grid.points(0)))

    def test_flow_case_takes_its_free_stream_solver_and_references_from_the_export(self):
        import json

        from bvmesh.features import grid_export

        case = os.path.join(self.folder, "sphere_flow_central")
        export = api.export_grid(self.grid, case, file_format="openfoam_case", name="FlowCase",
                                 solver="rhoCentralFoam", mach=0.5, alpha_degrees=2.0, iterations=300,
                                 reference_length=2000.0, reference_area=3.0e6, moment_point=(500.0, 0.0, 0.0))

        def settings():
            with open(os.path.join(case, "bvmesh_case.json")) as file:
                return json.load(file)

        written = settings()
        self.assertEqual((written["solver"], written["model"], written["iterations"]), ("rhoCentralFoam", "euler", 300))
        self.assertAlmostEqual(written["freestream"]["mach"], 0.5)
        self.assertAlmostEqual(written["freestream"]["alpha_degrees"], 2.0)
        self.assertAlmostEqual(written["freestream"]["p"], 1e5)  # euler, no pressure given
        self.assertAlmostEqual(written["reference"]["length"], 2.0)  # mm -> m
        self.assertAlmostEqual(written["reference"]["area"], 3.0)
        self.assertEqual(written["reference"]["moment_point"], [0.5, 0.0, 0.0])
        self.assertEqual(written["length_unit"], 1e-3)
        with open(os.path.join(case, "system", "controlDict")) as file:
            self.assertIn("application     rhoCentralFoam;", file.read())
        # Shown for the flow case only.
        self.assertEqual(export.getEditorMode("Solver"), [])
        cgns_export = api.export_grid(self.grid, os.path.join(self.folder, "hidden.cgns"), name="Export")
        for name in grid_export.FLOW_CASE_PROPERTIES:
            self.assertEqual(cgns_export.getEditorMode(name), ["Hidden"], name)
        # A changed property writes the case again on recompute.
        export.Mach = 0.7
        export.Pressure = 5e4
        export.Solver = "rhoPimpleFoam"
        self.doc.recompute()
        self.assertNotIn("Invalid", export.State)
        written = settings()
        self.assertEqual(written["solver"], "rhoPimpleFoam")
        self.assertAlmostEqual(written["freestream"]["mach"], 0.7)
        self.assertAlmostEqual(written["freestream"]["p"], 5e4)

        names = [o.Name for o in self.doc.Objects]
        with self.assertRaisesRegex(ValueError, "unknown flow case option 'reynolds'"):
            api.export_grid(self.grid, case, file_format="openfoam_case", reynolds=1e6)
        with self.assertRaisesRegex(ValueError, r"flow case options \(mach\) need file_format 'openfoam_case', "
                                                "not 'cgns'"):
            api.export_grid(self.grid, os.path.join(self.folder, "other.cgns"), mach=0.5)
        with self.assertRaisesRegex(RuntimeError, "mach must be a finite number > 0"):
            api.export_grid(self.grid, case, file_format="openfoam_case", mach=-1.0)
        self.assertEqual([o.Name for o in self.doc.Objects], names)

    def test_bad_options_leave_the_document_as_it_was(self):
        names = [o.Name for o in self.doc.Objects]
        with self.assertRaisesRegex(ValueError, "unknown volume mesh option 'farfield'"):
            api.make_volume_mesh(self.fit, farfield=3.0)
        # A value of the wrong kind is named with what the option takes (FreeCAD's own message is
        # a dict of its internals).
        with self.assertRaisesRegex(ValueError, "volume mesh option 'domain' takes one of sphere, box, cylinder, "
                                                "cad, got 'cube'"):
            api.make_volume_mesh(self.fit, domain="cube")
        with self.assertRaisesRegex(ValueError, r"volume mesh option 'flow_direction' takes three numbers, got \(1, 0\)"):
            api.make_volume_mesh(self.fit, domain="box", flow_direction=(1, 0))
        with self.assertRaisesRegex(ValueError, "volume grid option 'normal_points' takes a whole number, got 'many'"):
            api.make_volume_grid(self.volume, "euler", normal_points="many")
        with self.assertRaises(Exception) as raised:
            api.make_volume_mesh(self.fit, boundary_layer_thickness=0.05, farfield_distance=0.01)
        self.assertIn("far", str(raised.exception).lower())
        with self.assertRaisesRegex(ValueError, "no export format for '.doc' files"):
            api.export_grid(self.grid, os.path.join(self.folder, "grid.doc"))
        with self.assertRaises(Exception):
            api.export_grid(self.grid, "/proc/forbidden/grid.cgns")
        self.assertEqual([o.Name for o in self.doc.Objects], names)
        digest = self.volume.Digest
        with self.assertRaises(Exception):
            api.set_volume_options(self.volume, boundary_layer_layers=-3)
        self.assertEqual(self.volume.BoundaryLayerLayers, 4)
        self.assertEqual(self.volume.Digest, digest)
        self.assertTrue(self.volume.isValid())
        with self.assertRaisesRegex(RuntimeError, "no wall at level 9"):
            api.set_volume_options(self.volume, wall_level=9)
        self.assertEqual(self.volume.WallLevel, -1)
        # Levels below -1 were taken as -1.
        for options, message in (({"wall_level": -2}, r"WallLevel -2 must be 0 or more, up to the fit's level 3 "
                                                      r"\(or -1: the fit's own level\)"),
                                 ({"marching_level": -5}, r"MarchingLevel -5 must be below the wall's level 3 and 0 "
                                                          r"or more \(or -1: the wall's own level, or lower ones "
                                                          r"where its marching folds\)")):
            with self.assertRaisesRegex(RuntimeError, message):
                api.set_volume_options(self.volume, **options)
            self.assertEqual((self.volume.WallLevel, self.volume.MarchingLevel, self.volume.Digest), (-1, -1, digest))
            with self.assertRaisesRegex(RuntimeError, message):
                api.make_volume_mesh(self.fit, boundary_layer_thickness=0.05, farfield_distance=20.0, **options)
            self.assertEqual([o.Name for o in self.doc.Objects], names)
        # Set on the object itself: its recompute fails, naming the property.
        self.volume.MarchingLevel = -2
        try:
            self.doc.recompute()
            self.assertFalse(self.volume.isValid())
            self.assertIn("MarchingLevel -2 must be below the wall's level", self.volume.Proxy.error)
        finally:
            self.volume.MarchingLevel = -1
            self.doc.recompute()
        self.assertTrue(self.volume.isValid())
        self.assertEqual(self.volume.Digest, digest)
        # A grid beyond the free memory is refused by its planned size, the grid as it was (it was
        # computed until the memory ran out, taking FreeCAD and the document with it).
        grid_digest, cells = self.grid.Digest, self.grid.CellCount
        with self.assertRaisesRegex(RuntimeError, r"the grid would have [0-9.e+]+ points, more than max_points"):
            api.set_grid_options(self.grid, edge_points=100000)
        self.assertEqual((self.grid.EdgePoints != 100000, self.grid.Digest, self.grid.CellCount),
                         (True, grid_digest, cells))

    def test_box_domain_through_the_document(self):
        vm = api.make_volume_mesh(self.fit, boundary_layer_thickness=0.05, farfield_distance=20.0, domain="box",
                                  box_half_extent=(40.0, 20.0, 20.0), flow_direction=(1.0, 0.0, 0.0), name="Boxed")
        grid = api.make_volume_grid(vm, "euler", edge_points=5, normal_points=9, name="BoxedGrid")
        try:
            self.assertEqual(vm.Domain, "box")
            # The sphere template's charts are not aligned with the box: the faces bending around its
            # edges are counted (the cube layout in tests/python/test_volume.py has none).
            self.assertEqual(vm.FacesAcrossDomainEdges, api.volume_mesh_of(vm).farfield_faces_across_domain_edges)
            # The grid puts those faces' quads on the patch each lies on.
            self.assertGreater(grid.OuterFacesSplit, 0)
            self.assertEqual(grid.OuterFacesSplit, api.grid_of(grid).outer_faces_split)
            case = os.path.join(self.folder, "box_case")
            api.export_grid(grid, case, name="BoxedExport")
            with open(os.path.join(case, "constant", "polyMesh", "boundary")) as boundary:
                text = boundary.read()
            for patch in ("wall", "inlet", "outlet", "side"):
                self.assertRegex(text, r"\n\s*{}\s*\n\s*{{".format(patch))
            self.assertNotIn("farfield", text)
            with self.assertRaisesRegex(ValueError, "volume mesh option 'domain' takes one of sphere, box, cylinder, "
                                                    "cad, got 'cone'"):
                api.set_volume_options(vm, domain="cone")
            self.assertEqual(vm.Domain, "box")
        finally:
            for name in ("BoxedExport", "BoxedGrid", "Boxed"):
                if self.doc.getObject(name) is not None:
                    self.doc.removeObject(name)

    def test_far_field_schemes_through_the_document(self):
        # A new mesh marches hyperbolically; chosen by name; a wrong name leaves the object as it
        # was; back to hyperbolic the blocks are the default object's; an object saved before the
        # property marches smoothed, as it was made.
        self.assertEqual(self.volume.FarfieldScheme, "hyperbolic")
        self.assertEqual(self.volume.FarfieldLayersSmoothed, 0)
        vm = api.make_volume_mesh(self.fit, boundary_layer_thickness=0.05, farfield_distance=20.0,
                                  farfield_scheme="smoothed", name="Smoothed")
        try:
            self.assertEqual(vm.FarfieldScheme, "smoothed")
            self.assertEqual(vm.BlockCount, 6)
            self.assertNotEqual(vm.Digest, self.volume.Digest)
            self.assertGreater(min(self.volume.LayerMinScaledJacobian), 0.3)
            with self.assertRaisesRegex(ValueError, "volume mesh option 'farfield_scheme' takes one of smoothed, "
                                                    "hyperbolic, got 'elliptic'"):
                api.set_volume_options(vm, farfield_scheme="elliptic")
            self.assertEqual(vm.FarfieldScheme, "smoothed")
            smoothed = vm.Digest
            api.set_volume_options(vm, farfield_scheme="hyperbolic")
            self.assertEqual(vm.Digest, self.volume.Digest)
            vm.removeProperty("FarfieldScheme")
            vm.Proxy.setup(vm)
            self.assertEqual(vm.FarfieldScheme, "smoothed")
            vm.touch()
            self.doc.recompute()
            self.assertEqual(vm.Digest, smoothed)
        finally:
            self.doc.removeObject(vm.Name)

    def test_knife_edge_fans_through_the_document(self):
        # Off on a new mesh and on one saved before the property; set, it reaches the marching's
        # options (the sphere has no knife edge: its blocks stay as they are).
        from bvmesh.features import volume_mesh

        self.assertFalse(self.volume.KnifeEdgeFans)
        vm = api.make_volume_mesh(self.fit, boundary_layer_thickness=0.05, farfield_distance=20.0,
                                  knife_edge_fans=True, name="Fans")
        try:
            self.assertTrue(vm.KnifeEdgeFans)
            self.assertIs(volume_mesh.options(vm)["knife_edge_fans"], True)
            self.assertEqual(vm.BlockCount, self.volume.BlockCount)
            self.assertEqual(vm.Digest, self.volume.Digest)
            vm.removeProperty("KnifeEdgeFans")
            vm.Proxy.setup(vm)
            self.assertFalse(vm.KnifeEdgeFans)
            with self.assertRaisesRegex(Exception, "knife_edge_fans"):
                api.set_volume_options(vm, knife_edge_fan=True)
        finally:
            self.doc.removeObject(vm.Name)

    def test_lower_wall_level_refits(self):
        level = self.fit.Level - 1
        vm = api.make_volume_mesh(self.fit, wall_level=level, boundary_layer_thickness=0.05, farfield_distance=20.0,
                                  name="VolumeLower")
        try:
            self.assertEqual(vm.WallLevelUsed, level)
            self.assertNotEqual(vm.Digest, self.volume.Digest)
        finally:
            self.doc.removeObject(vm.Name)

    def test_layers_marched_from_a_lower_level(self):
        # The blocks stand on the fit's own wall (their wall poles are its charts', as the volume
        # marched from it), their layers marched from the fit refitted one level lower.
        vm = api.make_volume_mesh(self.fit, marching_level=self.fit.Level - 1, boundary_layer_thickness=0.05,
                                  farfield_distance=20.0, name="VolumeCarried")
        try:
            self.assertEqual(vm.WallLevelUsed, self.fit.Level)
            self.assertEqual(vm.BlockCount, self.volume.BlockCount)
            carried, own = api.volume_mesh_of(vm).blocks, api.volume_mesh_of(self.volume).blocks
            for b in range(own.block_count):
                np.testing.assert_array_equal(carried.poles(b)[:, :, 0], own.poles(b)[:, :, 0])
            self.assertNotEqual(vm.Digest, self.volume.Digest)
            with self.assertRaisesRegex(RuntimeError, "MarchingLevel {} must be below the wall's level".format(
                    self.fit.Level)):
                api.set_volume_options(vm, marching_level=self.fit.Level)
            self.assertEqual(vm.MarchingLevel, self.fit.Level - 1)
        finally:
            self.doc.removeObject(vm.Name)

    def test_subdivision_method_refines_the_control_volume(self):
        # Method subdivision: the fit's control mesh marched with the volume mesh's options and
        # refined once; its wall points lie on the fitted sphere as the fit's limit samples do.
        grid = api.make_volume_grid(self.volume, method="subdivision", steps=1, name="SubdividedGrid")
        try:
            self.assertTrue(grid.isValid())
            structured = api.grid_of(grid)
            self.assertEqual(grid.CellCount, structured.cell_count)
            self.assertEqual(grid.FirstCellHeightAsked, 0.0)
            wall = np.concatenate([structured.points(b)[:, :, 0, :].reshape(-1, 3) for b in range(structured.block_count)])
            radii = np.linalg.norm(wall, axis=1)
            self.assertLessEqual(np.abs(radii - RADIUS).max(), self.fit.MaxDistance * (1 + 1e-9))
            quality = api.make_mesh_quality(grid, name="SubdividedQuality")
            self.assertEqual(quality.Cells, grid.CellCount)
            self.assertGreater(quality.MinScaledJacobian, 0.2)
            path = os.path.join(self.folder, "subdivided.cgns")
            api.export_grid(grid, path)
            self.assertGreater(os.path.getsize(path), 0)
            cells, digest = grid.CellCount, grid.Digest
            api.set_grid_options(grid, steps=2)
            self.assertEqual(grid.CellCount, 8 * cells)
            # Back to the B-spline blocks: the evaluated grid with its wall law again.
            api.set_grid_options(grid, method="bspline")
            self.assertNotEqual(grid.Digest, digest)
            self.assertGreater(grid.FirstCellHeightMin, 0.0)
        finally:
            for name in ("SubdividedQuality", "SubdividedGrid"):
                if self.doc.getObject(name) is not None:
                    self.doc.removeObject(name)


class FlowDomainDocument(unittest.TestCase):
    """A flow domain's CAD in the document (a box with a ball cut out, as a pre-processor writes
    it): the target takes the ball with no face named, the volume mesh the box."""

    def test_target_takes_the_body_and_the_volume_mesh_the_box(self):
        doc = FreeCAD.newDocument("FlowDomain")
        try:
            box = Part.makeBox(24.0, 12.0, 8.0, FreeCAD.Vector(-10.0, -6.0, -4.0))
            domain = doc.addObject("Part::Feature", "Domain")
            domain.Shape = box.cut(Part.makeSphere(RADIUS, FreeCAD.Vector(1.0, 0.5, 0.0)))
            target = api.make_target(doc, domain)
            self.assertEqual(list(target.Faces), [])
            self.assertEqual(target.FlowDomain, "box")
            self.assertEqual(len(target.Shape.Faces), 1)
            self.assertAlmostEqual(target.Shape.Area, 4.0 * np.pi * RADIUS ** 2, places=6)
            self.assertLess((target.DomainCentre - FreeCAD.Vector(2.0, 0.0, 0.0)).Length, 1e-9)
            self.assertLess((target.DomainSize - FreeCAD.Vector(12.0, 6.0, 4.0)).Length, 1e-9)
            polyhedron = api.make_polyhedron_from_template(doc, target, "sphere")
            fit = api.fit_to_tolerance(api.make_surface_fit(doc, target, polyhedron, relative_tolerance=1e-3,
                                                            max_level=2))
            vm = api.make_volume_mesh(fit, boundary_layer_thickness=0.05)
            self.assertEqual(vm.Domain, "cad")
            mesh = api.volume_mesh_of(vm)
            self.assertEqual(mesh.domain, "box")
            np.testing.assert_allclose(mesh.domain_centre, [2.0, 0.0, 0.0], atol=1e-12)
            np.testing.assert_allclose(mesh.box_half_extent, [12.0, 6.0, 4.0], atol=1e-12)
            # A named face list is the user's choice: no flow domain then.
            target.Faces = ["Face1", "Face2"]
            doc.recompute()
            self.assertEqual(target.FlowDomain, "")
        finally:
            FreeCAD.closeDocument(doc.Name)

    def test_body_running_into_the_outflow_plane(self):
        # The hemisphere-cylinder's flow-domain file: the body lies on the symmetry plane y = 0 and
        # runs into the outflow plane x = 10 of a quarter sphere; the target finds both planes, the
        # volume mesh marches in both and tags the faces in the outflow plane outlet.
        doc = FreeCAD.newDocument("Sting")
        try:
            domain = doc.addObject("Part::Feature", "Domain")
            domain.Shape = Part.read(os.path.join(DATA, "hemisph-cyl.stp"))
            target = api.make_target(doc, domain)
            self.assertEqual(target.FlowDomain, "sphere")
            self.assertEqual(len(target.Shape.Faces), 2)
            self.assertLess((target.OutflowNormal - FreeCAD.Vector(-1.0, 0.0, 0.0)).Length, 1e-12)
            self.assertAlmostEqual(target.OutflowPoint.x, 10.0, places=9)
            polyhedron = api.make_polyhedron_from_template(doc, target, "capsule")
            # The fit takes the flow domain's symmetry plane as the workbench's command does.
            point, normal = api.symmetry_plane_guess(target)
            self.assertAlmostEqual(point[1], 0.0, places=12)
            np.testing.assert_allclose(normal, (0.0, 1.0, 0.0), atol=1e-12)
            fit = api.fit_to_tolerance(api.make_surface_fit(doc, target, polyhedron, relative_tolerance=1e-4,
                                                            max_level=2,
                                                            symmetry_plane=api.symmetry_plane_guess(target)))
            vm = api.make_volume_mesh(fit, reference_length=10.0, reynolds_number=1e6)
            self.assertEqual(vm.Domain, "cad")
            mesh = api.volume_mesh_of(vm)
            conditions = [face["condition"] for b in range(mesh.blocks.block_count)
                          for face in mesh.blocks.faces(b).values()]
            self.assertEqual(conditions.count("outlet"), 3)
            # The far-field display shows the whole domain boundary: the sphere's 4 faces and the
            # outflow plane's 3.
            api.set_volume_options(vm, show=("farfield",))
            self.assertEqual(len(vm.Shape.Faces), 7)
            self.assertEqual(sum(abs(f.BoundBox.XMin - 10.0) < 1e-6 and abs(f.BoundBox.XMax - 10.0) < 1e-6
                                 for f in vm.Shape.Faces), 3)
            np.testing.assert_allclose(mesh.domain_centre, [10.0, 0.0, 0.0], atol=1e-9)
            self.assertAlmostEqual(mesh.farfield_distance, 100.0, places=9)
            # Another domain cannot take the outflow plane: refused by name, the object as it was.
            digest = vm.Digest
            with self.assertRaisesRegex(Exception, "runs into the outflow plane of its flow domain.*choose Domain cad"):
                api.set_volume_options(vm, domain="sphere")
            self.assertEqual((vm.Domain, vm.Digest), ("cad", digest))
        finally:
            FreeCAD.closeDocument(doc.Name)

    def test_cad_domain_without_a_flow_domain_is_refused(self):
        doc = FreeCAD.newDocument("NoFlowDomain")
        try:
            fit = sphere_fit(doc)
            vm = api.make_volume_mesh(fit, boundary_layer_thickness=0.05, farfield_distance=20.0)
            digest = vm.Digest
            with self.assertRaisesRegex(Exception, "Domain 'cad' needs a target on a flow domain's CAD"):
                api.set_volume_options(vm, domain="cad")
            self.assertEqual(vm.Domain, "sphere")
            self.assertEqual(vm.Digest, digest)
        finally:
            FreeCAD.closeDocument(doc.Name)


class SaveAndReopen(unittest.TestCase):
    def test_reopened_document_recomputes_identical_blocks_and_points(self):
        folder = tempfile.mkdtemp(prefix="bvmesh-volume-reopen-")
        doc = FreeCAD.newDocument("VolumeReopen")
        fit = sphere_fit(doc)
        vm = api.make_volume_mesh(fit, boundary_layer_thickness=0.05, farfield_distance=20.0)
        grid = api.make_volume_grid(vm, "rans", reynolds_number=1e6, edge_points=9)
        api.make_mesh_quality(grid)
        digests = (vm.Digest, grid.Digest)
        points = api.grid_of(grid).grid.points(3).copy()
        path = os.path.join(folder, "volume.FCStd")
        doc.saveAs(path)
        FreeCAD.closeDocument(doc.Name)
        doc = FreeCAD.openDocument(path)
        try:
            vm, grid = doc.getObject("VolumeMesh"), doc.getObject("VolumeGrid")
            self.assertTrue(is_type(vm, "BVMesh::VolumeMesh"))
            # Blocks and points are evaluated again on demand, checked against the saved digests.
            self.assertTrue(np.array_equal(api.grid_of(grid).grid.points(3), points))
            for obj in doc.Objects:
                obj.touch()
            doc.recompute()
            self.assertEqual([o.Name for o in doc.Objects if not o.isValid()], [])
            self.assertEqual((vm.Digest, grid.Digest), digests)
            self.assertEqual(doc.getObject("MeshQuality").Cells, grid.CellCount)
        finally:
            FreeCAD.closeDocument(doc.Name)


class AutomaticMarchingLevel(unittest.TestCase):
    """MarchingLevel -1 on the M6 fitted to level 3 (11 257 control points, level 2 2 837): with the
    default point limit the layers are marched from level 2 at once; without a limit the wall's own
    level is marched first, whose boundary layer folds at the trailing edge's tip corner, and the
    layers come from level 2 after all. Both give what MarchingLevel 2 gives."""

    def test_a_wall_too_fine_or_whose_marching_folds_is_marched_from_a_level_down(self):
        from bvmesh import load_core, paths, volume
        from bvmesh.features import volume_mesh

        doc = FreeCAD.newDocument("AutomaticMarchingLevel")
        try:
            wing = api.import_cad(doc, paths.EXAMPLE_WING)
            _, symmetry_face, _ = load_core().remove_symmetry_face(wing.Shape.exportBrepToString())
            faces = ["Face{}".format(i + 1) for i in range(len(wing.Shape.Faces)) if i != symmetry_face]
            target = api.make_target(doc, wing, faces=faces)
            polyhedron = api.make_polyhedron_from_template(doc, target, "half_wing", tip_kinks="follow")
            self.assertAlmostEqual(polyhedron.RootChord, 810.5, delta=0.5)  # as the template measured it
            fit = api.make_surface_fit(doc, target, polyhedron, symmetry_plane=api.symmetry_plane_guess(target),
                                       tolerance=8e-3, max_level=3)
            api.fit_to_tolerance(fit)
            self.assertEqual(fit.Level, 3)
            points = volume_mesh.control_points_per_level(fit)
            self.assertGreater(points[3], volume.MARCHING_POINT_LIMIT)
            self.assertLessEqual(points[2], volume.MARCHING_POINT_LIMIT)
            automatic = api.make_volume_mesh(fit, reference_length=805.0, name="Automatic")
            self.assertEqual(automatic.MarchingPointLimit, volume.MARCHING_POINT_LIMIT)
            self.assertEqual(volume_mesh.marching_levels(automatic), [2, 1])  # level 3 is not tried
            self.assertEqual((automatic.WallLevelUsed, automatic.MarchingLevelUsed), (3, 2))
            unlimited = api.make_volume_mesh(fit, marching_point_limit=0, reference_length=805.0, name="Unlimited")
            self.assertEqual(volume_mesh.marching_levels(unlimited), [3, 2, 1])
            self.assertEqual((unlimited.WallLevelUsed, unlimited.MarchingLevelUsed), (3, 2))  # level 3 folded
            explicit = api.make_volume_mesh(fit, marching_level=2, reference_length=805.0, name="Explicit")
            self.assertEqual(explicit.MarchingLevelUsed, 2)
            self.assertEqual(automatic.Digest, explicit.Digest)
            self.assertEqual(unlimited.Digest, explicit.Digest)
            # ReferenceLength 0: the wing's root chord, not the wall's largest extent (the span, 1196).
            chord = api.make_volume_mesh(fit, marching_level=2, name="RootChord")
            self.assertEqual(chord.ReferenceLength, 0.0)
            self.assertEqual(chord.ReferenceLengthUsed, polyhedron.RootChord)
            self.assertEqual(explicit.ReferenceLengthUsed, 805.0)
            # A limit below every level's size leaves level 1 (the M6's folds there); a negative one is
            # refused by name and the object keeps its options and blocks.
            unlimited.MarchingPointLimit = 100
            self.assertEqual(volume_mesh.marching_levels(unlimited), [1])
            unlimited.MarchingPointLimit = 0
            with self.assertRaisesRegex(RuntimeError, "MarchingPointLimit -1 must be 0"):
                api.set_volume_options(unlimited, marching_point_limit=-1)
            self.assertEqual((unlimited.MarchingPointLimit, unlimited.Digest), (0, explicit.Digest))
            # The subdivision grid's control volume is marched from the level the layers came from.
            grids = [api.make_volume_grid(vm, method="subdivision", steps=1) for vm in (automatic, explicit)]
            self.assertEqual(grids[0].Digest, grids[1].Digest)
        finally:
            FreeCAD.closeDocument(doc.Name)


if __name__ == "__main__":
    unittest.main()

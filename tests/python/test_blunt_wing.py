"""Wings as FreeCAD's Part module lofts them (two NACA 0012 sections, swept and tapered, flat tip),
with a blunt trailing edge (a base 0.25 % of the chord thick between two sharp edges) and with a
sharp one, through the half_wing template, the fit, the volume and the euler grid."""

import math
import unittest

import numpy as np

import bvmesh
import bvmesh.grid
import bvmesh.volume
from bvmesh import polyhedra

try:
    import FreeCAD
    import Part
except ImportError:  # pragma: no cover - FreeCAD is installed on the test machines
    FreeCAD = Part = None

ROOT_CHORD, TIP_LE, TIP_CHORD, SPAN = 1.0, 0.6, 0.5, 2.0
BASE = 0.0025  # trailing-edge thickness over the chord


def half_thickness(x, base):
    """NACA 0012's half thickness with the trailing edge opened linearly to base / 2."""
    closed = 0.6 * (0.2969 * math.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
    return closed + 0.5 * base * x


def section(leading_edge, y, chord, base):
    xs = [0.5 * (1 + math.cos(math.pi * i / 40)) for i in range(41)]  # 1 .. 0
    points = [FreeCAD.Vector(leading_edge + chord * x, y, chord * half_thickness(x, base)) for x in xs]
    curve = Part.BSplineCurve()
    curve.interpolate(points, FinalTangent=FreeCAD.Vector(0, 0, -1))
    upper = curve.toShape()
    lower = upper.mirror(FreeCAD.Vector(0, y, 0), FreeCAD.Vector(0, 0, 1))
    if base == 0.0:
        return Part.Wire([upper, lower])
    edge = Part.LineSegment(points[0], FreeCAD.Vector(points[0].x, y, -points[0].z)).toShape()
    return Part.Wire([upper, lower, edge])


def half_wing(base):
    """The half wing, its root in the plane y = 0 (its root face left out as the symmetry plane)."""
    return Part.makeLoft([section(0.0, 0.0, ROOT_CHORD, base), section(TIP_LE, SPAN, TIP_CHORD, base)], True, False)


def trailing_edge_cells(grid, quality):
    """Scaled Jacobians of the cells with a corner within 1 % of the chord of the trailing edge, away
    from the tip (|y| < 0.9 span)."""
    sj = np.asarray(quality["scaled_jacobian"])
    block_of = np.asarray(quality["cell_block"])
    found = []
    for b in range(grid.grid.block_count):
        corners = np.asarray(grid.grid.points(b))[:-1, :-1, :-1].reshape(-1, 3, order="F")
        trailing = ROOT_CHORD + (TIP_LE + TIP_CHORD - ROOT_CHORD) * corners[:, 1] / SPAN
        near = (np.abs(corners[:, 0] - trailing) < 0.01) & (corners[:, 1] < 0.9 * SPAN) & (np.abs(corners[:, 2]) < 0.01)
        found.append(sj[block_of == b][near])
    return np.concatenate(found)


@unittest.skipIf(Part is None, "FreeCAD is not importable")
class BluntTrailingEdgeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.results = {}
        cls.volumes = {}
        for name, base in (("blunt", BASE), ("sharp", 0.0)):
            target, _, _ = polyhedra.half_model_target(half_wing(base))
            placed = polyhedra.place("half_wing", target)  # strict: every crease and corner mapped
            fitter = bvmesh.SurfaceFitter(target, placed["mesh"], placed["feature_map"],
                                          symmetry_plane=placed["symmetry_plane"], max_level=2, tolerance=1e-4)
            report = fitter.run()
            volume = bvmesh.volume.offset_and_farfield(fitter, reference_length=ROOT_CHORD, reynolds_number=1e6)
            grid = bvmesh.grid.refine(volume, "euler", target_cells=300000)
            cls.results[name] = (target, placed, report, grid, bvmesh.grid.quality(grid))
            cls.volumes[name] = volume

    def test_a_blunt_edge_is_a_base_between_two_creases(self):
        target, placed, _, _, _ = self.results["blunt"]
        self.assertEqual(placed["parameters"]["trailing_edge"], "blunt")
        self.assertEqual(placed["parameters"]["tip"], "flat")
        vertices = np.asarray(placed["mesh"].vertices)
        spanwise = [c for c in placed["chains"] if c["kind"] == "crease"
                    and np.ptp(vertices[c["vertices"], 1]) > 0.9 * SPAN]
        self.assertEqual(len(spanwise), 2)  # the base's upper and lower edges, each on its own CAD curve
        self.assertNotEqual(spanwise[0]["cad_edges"], spanwise[1]["cad_edges"])
        for chain in spanwise:
            self.assertLess(chain["max_distance"], 1e-9)
            # One edge above the chord plane, one below, BASE apart at the root.
            self.assertAlmostEqual(abs(vertices[chain["vertices"], 2]).max(), 0.5 * BASE, delta=1e-9)
        self.assertEqual(self.results["sharp"][1]["parameters"]["trailing_edge"], "sharp")

    def test_both_fit_and_mesh(self):
        # The loft's tip rim is two CAD curves meeting at the leading edge, where the leading edge's
        # kink ends too: the rim is still one curve (it used to end there, the template's rim
        # followed one half of it and the placement stopped with a collapsed face).
        for name in ("blunt", "sharp"):
            _, _, report, grid, quality = self.results[name]
            self.assertEqual(report["reason"], "converged", name)
            self.assertGreater(quality["summary"]["scaled_jacobian"]["min"], 0.0, name)

    def test_the_base_gives_trailing_edge_cells_the_o_topology_cannot(self):
        # An O-grid round a sharp edge has a knife-edge cell (a corner of nearly 180 degrees) on
        # each side; a base's cells have right angles. Measured: 0.632 against 0.142, and no face
        # above 70 degrees on the blunt edge's grid. With the base's lines fanning over its outer
        # halves only (its middle straight): 0.390, and 32 faces above 70 degrees.
        blunt = trailing_edge_cells(*self.results["blunt"][3:])
        sharp = trailing_edge_cells(*self.results["sharp"][3:])
        self.assertGreater(len(blunt), 100)
        self.assertGreater(blunt.min(), 0.5)
        self.assertLess(sharp.min(), 0.15)
        self.assertEqual((np.asarray(self.results["blunt"][4]["non_orthogonality"]) > 70.0).sum(), 0)

    def test_the_default_grid_is_positive_across_the_base(self):
        # The base (0.25 % of the chord) is narrow beside the boundary layer (2.3 %): its lines fan
        # from edge to edge. When only its outer halves fanned and its middle went straight, the
        # blocks' cubic interpolation of that kinked fan crossed the base's middle plane, where its
        # two halves' blocks meet: 632 negative cells at the default point counts (the test's own
        # 300 k cells, above, they did not show). Measured: minimum 0.095.
        grid = bvmesh.grid.refine(self.volumes["blunt"], "euler")
        self.assertGreater(bvmesh.grid.quality(grid)["summary"]["scaled_jacobian"]["min"], 0.05)

    def test_corner_blocks_that_fold_sampled_coarsely_are_refined(self):
        # The wing rectangular (chord 1, span 4) at a finer fit, its layers marched from a coarser
        # level: where the base meets the flat tip, blocks of one cell across wrap round that corner
        # and 4 cells folded at 300 k cells (scaled Jacobian -0.19), though the blocks are positive.
        # Their sets with twice the cells still folded there; with four times, none (397 k cells,
        # minimum 0.046).
        wing = Part.makeLoft([section(0.0, 0.0, 1.0, BASE), section(0.0, 4.0, 1.0, BASE)], True, False)
        target, _, _ = polyhedra.half_model_target(wing)
        placed = polyhedra.place("half_wing", target)
        fitter = bvmesh.SurfaceFitter(target, placed["mesh"], placed["feature_map"],
                                      symmetry_plane=placed["symmetry_plane"], max_level=3, tolerance=1e-5)
        fitter.run()
        volume = bvmesh.volume.offset_and_farfield(fitter, marching_level=-1, reference_length=1.0)
        grid = bvmesh.grid.refine(volume, "euler", target_cells=300000)
        self.assertEqual(grid.fold_refinements, 2)
        self.assertGreater(bvmesh.grid.quality(grid)["summary"]["scaled_jacobian"]["min"], 0.0)

    def test_a_sharp_leading_edge_is_no_base(self):
        # A biconvex section (two circular arcs): sharp leading and trailing edges, a chord apart.
        def biconvex(leading_edge, y, chord):
            v = FreeCAD.Vector
            le, te = v(leading_edge, y, 0), v(leading_edge + chord, y, 0)
            upper = Part.Arc(le, v(leading_edge + 0.5 * chord, y, 0.05 * chord), te).toShape()
            lower = Part.Arc(te, v(leading_edge + 0.5 * chord, y, -0.05 * chord), le).toShape()
            return Part.Wire([upper, lower])

        wing = Part.makeLoft([biconvex(0.0, 0.0, ROOT_CHORD), biconvex(TIP_LE, SPAN, TIP_CHORD)], True, False)
        target, _, _ = polyhedra.half_model_target(wing)
        with self.assertRaisesRegex(ValueError, r"2 sharp spanwise curves cross the section half way along the span, "
                                                r"[0-9.]+ apart on a chord of [0-9.]+ \(a sharp leading edge\?\)"):
            polyhedra.place("half_wing", target)

    def test_full_span_blunt_wing_creases_its_base_where_the_halves_meet(self):
        # The two halves' bases meet at the root at 5.7 degrees along a CAD kink (not sharp): the
        # root ring's base edge is a crease mapped to that kink. Uncreased, the fit bent the
        # one-face-wide base strip across it and stopped 7e-4 from the CAD at level 2 (its inner
        # vertices 2.5e-3 out of the base's plane); creased, 2.4e-5, as the sharp-edged wing.
        whole = half_wing(BASE)
        whole = whole.fuse(whole.mirror(FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(0, 1, 0))).removeSplitter()
        target = bvmesh.Target.from_brep(whole.exportBrepToString())
        placed = polyhedra.place("wing", target)
        self.assertEqual(placed["parameters"]["trailing_edge"], "blunt")
        kinks = {k for k, curve in enumerate(placed["curves"]) if curve["kind"] == "kink"}
        vertices = np.asarray(placed["mesh"].vertices)
        on_kinks = [c for c in placed["chains"] if c["kind"] == "crease" and set(c["curves"]) <= kinks]
        self.assertEqual(len(on_kinks), 1)
        self.assertLess(np.abs(vertices[on_kinks[0]["vertices"], 1]).max(), 1e-9)  # the root's base edge
        fitter = bvmesh.SurfaceFitter(target, placed["mesh"], placed["feature_map"], max_level=2, tolerance=1e-4)
        self.assertEqual(fitter.run()["reason"], "converged")
        volume = bvmesh.volume.offset_and_farfield(fitter, reference_length=ROOT_CHORD, reynolds_number=1e6)
        quality = bvmesh.grid.quality(bvmesh.grid.refine(volume, "euler", target_cells=100000))
        self.assertGreater(quality["summary"]["scaled_jacobian"]["min"], 0.0)

if __name__ == "__main__":
    unittest.main()

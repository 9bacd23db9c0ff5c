"""Half wings as FreeCAD's Part module lofts them smoothly through three NACA 0012 sections, their
leading edges swept more and more towards a flat tip: where the tip's rim meets the swept nose the
wall turns by only 55 degrees, so those rim points are not sharp, yet a flat tip reaching at
least half a boundary layer's thickness from its rim is a face of its own, whose boundary-layer
lines leave along its normal; a smaller one is left to the splay band, whose lines fan across it."""

import unittest

import numpy as np

import bvmesh
import bvmesh.grid
import bvmesh.volume
from bvmesh import polyhedra
from fixtures import naca0012_section

try:
    import FreeCAD
    import Part
except ImportError:  # pragma: no cover - FreeCAD is installed on the test machines
    FreeCAD = Part = None

TIP_Y = 1.3


def euler_grid(sections, level=2):
    """The euler grid (100 k cells) of the half wing lofted through `sections` (leading edge, y,
    chord), fitted to `level` and marched from it at Re 5e6 on a unit root chord (a boundary layer
    0.017 thick)."""
    wing = Part.makeLoft([naca0012_section(*s) for s in sections], True, False)
    target, _, _ = polyhedra.half_model_target(wing)
    placed = polyhedra.place("half_wing", target)
    fitter = bvmesh.SurfaceFitter(target, placed["mesh"], placed["feature_map"],
                                  symmetry_plane=placed["symmetry_plane"], max_level=level, tolerance=1e-5)
    fitter.run()
    volume = bvmesh.volume.offset_and_farfield(fitter, reference_length=1.0, reynolds_number=5e6)
    return bvmesh.grid.refine(volume, "euler", target_cells=100000)


@unittest.skipIf(Part is None, "FreeCAD is not importable")
class FlatTipWingTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.grid = euler_grid([(0.0, 0.0, 1.0), (0.2, 0.6, 0.8), (0.6, TIP_Y, 0.35)])  # tip 0.042 thick

    def test_lines_leave_the_flat_tip_along_its_normal(self):
        # The tip's lines took the wing surfaces' normals, interpolated across the whole tip through
        # the rim points at its nose: 61-85 degrees off the tip's normal (median per block), with
        # about a thousand cells above 70 degrees of non-orthogonality beside it.
        angles = []
        for b in range(self.grid.grid.block_count):
            points = np.asarray(self.grid.grid.points(b))
            wall, first = points[:, :, 0], points[:, :, 1]
            on_tip = np.abs(wall[..., 1] - TIP_Y) < 1e-9
            line = (first - wall)[on_tip]
            angles.extend(np.degrees(np.arccos(line[:, 1] / np.linalg.norm(line, axis=1))))
        self.assertGreater(len(angles), 100)
        self.assertLess(np.median(angles), 20.0)
        non_orthogonality = bvmesh.grid.quality(self.grid)["non_orthogonality"]
        self.assertLess((non_orthogonality > 70.0).sum(), 50)

    def test_a_tip_thinner_than_the_boundary_layer_fans_its_lines_across(self):
        # A tip 0.0096 thick under a boundary layer 0.017 thick: parted off the wing, its lines in
        # a band a quarter of its thickness wide, the far field's first layer folded at its nose
        # (marched from level 3; -0.19).
        grid = euler_grid([(0.0, 0.0, 1.0), (0.3, 0.8, 0.5), (0.7, 1.2, 0.08)], level=3)
        self.assertGreater(bvmesh.grid.quality(grid)["scaled_jacobian"].min(), 0.0)

    def test_a_tip_half_a_boundary_layer_thick_is_parted_off(self):
        # A delta-like wing's tip (chord 0.15, 0.018 thick, reaching 0.009 from its rim): left to
        # the band, its grid had a cell of -0.044 above the tip.
        grid = euler_grid([(0.0, 0.0, 1.0), (0.85, 1.2, 0.15)], level=3)
        self.assertGreater(bvmesh.grid.quality(grid)["scaled_jacobian"].min(), 0.0)


if __name__ == "__main__":
    unittest.main()

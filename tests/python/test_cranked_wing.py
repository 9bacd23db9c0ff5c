"""A cranked half wing as FreeCAD's Part module makes it (two ruled NACA 0012 lofts fused at the
crank, the trailing edge unswept inboard and swept outboard): the half_wing template puts a station
on the crank, and the knife-edge fans of its sharp trailing edge, which turns there, meet end to
end in point-matched grids."""

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

CRANK_Y = 0.4


@unittest.skipIf(Part is None, "FreeCAD is not importable")
class CrankedWingTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        crank = naca0012_section(0.4, CRANK_Y, 0.6)
        inboard = Part.makeLoft([naca0012_section(0.0, 0.0, 1.0), crank], True, True)
        outboard = Part.makeLoft([crank, naca0012_section(0.862, 1.2, 0.25)], True, True)
        target, _, _ = polyhedra.half_model_target(inboard.fuse(outboard).removeSplitter())
        cls.placed = polyhedra.place("half_wing", target)
        cls.fitter = bvmesh.SurfaceFitter(target, cls.placed["mesh"], cls.placed["feature_map"],
                                          symmetry_plane=cls.placed["symmetry_plane"], max_level=2, tolerance=1e-4)
        cls.fitter.run()

    def test_a_station_on_the_crank_with_a_corner_on_the_trailing_edge(self):
        vertices = np.asarray(self.placed["mesh"].vertices)
        corners = vertices[list(self.placed["mesh"].corners)]
        self.assertTrue((np.abs(vertices[:, 1] - CRANK_Y) < 1e-9).any())
        self.assertLess(np.linalg.norm(corners - [1.0, CRANK_Y, 0.0], axis=1).min(), 1e-6)

    def test_knife_edge_fans_meet_end_to_end_at_the_crank(self):
        # The two fans' shared end took its points from each fan's middle line and lay 5e-8 apart:
        # "the distributions disagree across a shared face".
        volume = bvmesh.volume.offset_and_farfield(self.fitter, reference_length=1.0, reynolds_number=5e6,
                                                   knife_edge_fans=True)
        fans = [b for b in range(volume.blocks.block_count) if volume.block_chart[b] == -1]
        self.assertEqual(len(fans), 2)
        grid = bvmesh.grid.refine(volume, "euler", target_cells=30000)
        self.assertGreater(bvmesh.grid.quality(grid)["scaled_jacobian"].min(), 0.0)


if __name__ == "__main__":
    unittest.main()

"""A cut plane through a volume grid: the grid lines where the plane crosses the cells' faces
(computed by the core, bvmesh.grid.plane_cut), as CFD engineers look at a mesh around a section,
each segment carrying a value of its cell (block number or a quality metric) for colouring."""

import numpy as np

from bvmesh.features import volume_grid
from bvmesh.features.common import READ_ONLY, Proxy, add_property

TYPE = "BVMesh::GridCut"
METRICS = ["block", "scaled_jacobian", "non_orthogonality", "skewness", "aspect_ratio", "growth_ratio", "determinant"]


def cell_values(refined, metric):
    """One value per cell of the grid: its block, or a quality metric of bvmesh.grid.quality."""
    from bvmesh import grid

    if metric == "block":
        g = volume_grid.structured_of(refined)
        return np.repeat(np.arange(g.block_count, dtype=float),
                         [int(np.prod(np.asarray(g.size(b)) - 1)) for b in range(g.block_count)])
    return np.asarray(grid.quality(refined)[metric], dtype=float)


class GridCutProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        import FreeCAD

        add_property(obj, "App::PropertyLink", "Grid", "Inputs", "The volume grid to cut")
        add_property(obj, "App::PropertyVector", "Point", "Cut", "A point of the cut plane")
        if "Normal" not in obj.PropertiesList:
            add_property(obj, "App::PropertyVector", "Normal", "Cut", "Normal of the cut plane")
            obj.Normal = FreeCAD.Vector(0, 1, 0)
        self.add_enumeration(obj, "Metric", "Cut", "What colours the grid lines", METRICS, "block")
        r = "Result"
        add_property(obj, "App::PropertyInteger", "SegmentCount", r, "Grid-line segments in the cut", mode=READ_ONLY)
        add_property(obj, "App::PropertyFloatList", "SegmentValues", r,
                     "Value of the metric for each segment (edge order of the shape)", mode=READ_ONLY)
        add_property(obj, "App::PropertyFloat", "ValueMin", r, "Smallest value in the cut", mode=READ_ONLY)
        add_property(obj, "App::PropertyFloat", "ValueMax", r, "Largest value in the cut", mode=READ_ONLY)

    def compute(self, obj):
        import FreeCAD
        import Part

        if obj.Grid is None:
            raise ValueError("the cut needs a volume grid")
        refined = volume_grid.refined_grid(obj.Grid)
        cut = cut_segments(refined, obj.Point, obj.Normal)
        values = cell_values(refined, obj.Metric)[cut["cell"]]
        edges = [Part.LineSegment(FreeCAD.Vector(*a), FreeCAD.Vector(*b)).toShape()
                 for a, b in zip(cut["start"].tolist(), cut["end"].tolist())]
        if not edges:
            raise ValueError("the plane through {} with normal {} does not cut {}".format(
                tuple(obj.Point), tuple(obj.Normal), obj.Grid.Label))
        obj.Shape = Part.makeCompound(edges)
        obj.SegmentCount = len(edges)
        obj.SegmentValues = [float(v) for v in values]
        obj.ValueMin, obj.ValueMax = float(values.min()), float(values.max())


def cut_segments(refined, point, normal):
    """The core's plane cut of a RefinedGrid: 'start', 'end' (n, 3) and 'cell' per segment."""
    from bvmesh import grid

    return grid.plane_cut(refined, (point.x, point.y, point.z), (normal.x, normal.y, normal.z))


def create(doc, name="GridCut"):
    obj = doc.addObject("Part::FeaturePython", name)
    GridCutProxy(obj)
    return obj

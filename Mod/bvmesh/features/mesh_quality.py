"""The mesh quality of a volume grid (bvmesh.grid.quality): the summary table per metric (min,
1 %, median, 99 %, max), the figures a CFD engineer checks first, and the histograms as PNG."""

import numpy as np

from bvmesh.features import volume_grid
from bvmesh.features.common import READ_ONLY, Proxy, add_property, run_work

TYPE = "BVMesh::MeshQuality"

# (property, metric, statistic, description)
FIGURES = (
    ("MinScaledJacobian", "scaled_jacobian", "min", "Smallest scaled Jacobian (min over each cell's corners)"),
    ("MaxNonOrthogonality", "non_orthogonality", "max", "Largest face non-orthogonality (degrees, OpenFOAM's)"),
    ("MaxSkewness", "skewness", "max", "Largest skewness (OpenFOAM's)"),
    ("MaxAspectRatio", "aspect_ratio", "max", "Largest aspect ratio"),
    ("MaxGrowthRatio", "growth_ratio", "max", "Largest volume ratio of neighbouring cells"),
    ("MinDeterminant", "determinant", "min", "Smallest cell determinant (OpenFOAM's; 1 for a cube)"),
    ("WallAngleP99", "wall_angle", "p99", "Wall grid lines off the wall normal, 99th percentile (degrees)"),
    ("WallAngleMax", "wall_angle", "max", "Wall grid lines off the wall normal, worst (degrees)"),
    ("FirstCellHeightMin", "first_cell_height", "min", "Smallest first cell height at the wall"),
    ("FirstCellHeightMax", "first_cell_height", "max", "Largest first cell height at the wall"),
)


# checkMesh -allGeometry fails cells whose determinant is below this.
SMALL_DETERMINANT = 1e-3


def counts(report):
    """Cells with a non-positive scaled Jacobian, with a face above 70 degrees of non-orthogonality,
    and with a determinant that checkMesh -allGeometry calls small."""
    return (int(np.count_nonzero(np.asarray(report["scaled_jacobian"]) <= 0.0)),
            int(np.count_nonzero(np.asarray(report["non_orthogonality"]) > 70.0)),
            int(np.count_nonzero(np.asarray(report["determinant"]) < SMALL_DETERMINANT)))


class MeshQualityProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "Grid", "Inputs", "The volume grid to measure")
        add_property(obj, "App::PropertyFile", "HistogramFile", "Inputs",
                     "PNG the histograms are written to on recompute (empty: none)")
        r = "Result"
        add_property(obj, "App::PropertyString", "Table", r, "The summary table (Markdown)", mode=READ_ONLY)
        add_property(obj, "App::PropertyInteger", "Cells", r, "Cells measured", mode=READ_ONLY)
        add_property(obj, "App::PropertyInteger", "NonPositiveCells", r,
                     "Cells with a scaled Jacobian <= 0 (a solver cannot use the grid)", mode=READ_ONLY)
        add_property(obj, "App::PropertyInteger", "CellsAbove70Degrees", r,
                     "Cells with a face above 70 degrees of non-orthogonality", mode=READ_ONLY)
        add_property(obj, "App::PropertyInteger", "SmallDeterminantCells", r,
                     "Cells with a determinant below 1e-3, which checkMesh -allGeometry fails (thin cells)",
                     mode=READ_ONLY)
        for prop, _, _, doc in FIGURES:
            add_property(obj, "App::PropertyFloat", prop, r, doc, mode=READ_ONLY)

    def report(self, obj):
        """The full quality report (bvmesh.grid.quality) of the linked grid, kept in memory."""
        from bvmesh import grid

        refined = volume_grid.refined_grid(obj.Grid)
        if getattr(self, "_report", None) is None or self._report_digest != obj.Grid.Digest:
            report = run_work("measuring the cells of {}".format(obj.Grid.Label), lambda: grid.quality(refined))
            self._report, self._report_digest = report, obj.Grid.Digest
        return self._report

    def compute(self, obj):
        from bvmesh import grid

        if obj.Grid is None:
            raise ValueError("the mesh quality needs a volume grid")
        report = self.report(obj)
        obj.Table = grid.quality_table(report)
        obj.Cells = len(report["scaled_jacobian"])
        obj.NonPositiveCells, obj.CellsAbove70Degrees, obj.SmallDeterminantCells = counts(report)
        summary = report["summary"]
        for prop, metric, statistic, _ in FIGURES:
            setattr(obj, prop, float(summary[metric][statistic]) if summary[metric]["count"] else 0.0)
        if obj.HistogramFile:
            grid.write_histograms(report, obj.HistogramFile)


def create(doc, name="MeshQuality"):
    obj = doc.addObject("App::FeaturePython", name)
    MeshQualityProxy(obj)
    return obj

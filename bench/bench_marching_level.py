"""The far field of a fine wall marched at its own level against the same fit's lower level carried
onto it (offset_and_farfield's marching_level, the workbench's automatic MarchingLevel): a waisted
body of revolution (length 6, profile 0.6 sqrt(1 - s^2) (1 - 0.35 exp(-((x - 3) / 0.9)^2)),
fuselage template with 16 axial and 20 circumferential segments, Re 1e6). The baseline is the
wall's own level, measured in the same run; each row gives the time, its ratio to the baseline and
the euler grid's quality (the same target cell count).

    PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_marching_level.py [level]
"""

import math
import sys
import time

import numpy as np

sys.path.append("/usr/lib/freecad-python3/lib")
import FreeCAD  # noqa: E402  -- Part needs it loaded first
import Part  # noqa: E402

import bvmesh  # noqa: E402
import bvmesh.grid  # noqa: E402
import bvmesh.volume  # noqa: E402
from bvmesh import polyhedra  # noqa: E402

LENGTH = 6.0


def waisted_body():
    """Solid of revolution about the x axis, its profile interpolated at cosine-spaced stations."""
    v = FreeCAD.Vector
    points = []
    for i in range(81):
        s = -math.cos(math.pi * i / 80)
        x = 0.5 * LENGTH * (1 + s)
        radius = 0.6 * math.sqrt(max(0.0, 1 - s * s)) * (1 - 0.35 * math.exp(-((x - 3) / 0.9) ** 2))
        points.append(v(x, radius, 0))
    curve = Part.BSplineCurve()
    curve.interpolate(points, InitialTangent=v(0, 1, 0), FinalTangent=v(0, -1, 0))
    profile = Part.Wire([curve.toShape(), Part.LineSegment(v(LENGTH, 0, 0), v(0, 0, 0)).toShape()])
    return Part.Face(profile).revolve(v(0, 0, 0), v(1, 0, 0), 360)


def quality_row(volume):
    grid = bvmesh.grid.refine(volume, "euler", target_cells=75000)
    quality = bvmesh.grid.quality(grid)
    return (float(quality["scaled_jacobian"].min()), float(np.percentile(quality["scaled_jacobian"], 1)),
            float(quality["non_orthogonality"].max()), float(np.percentile(quality["wall_angle"], 99)))


def main(level):
    target = bvmesh.Target.from_brep(waisted_body().exportBrepToString())
    placed = polyhedra.place("fuselage", target, {"axial": "16", "circumferential": "20"})
    fitter = bvmesh.SurfaceFitter(target, placed["mesh"], placed["feature_map"], max_level=level, tolerance=1e-9)
    fitter.run()
    points = {record["level"]: record["control_points"] for record in fitter.history}
    print("waisted body, fit at level {} ({} control points)".format(fitter.level, points[fitter.level]))
    print("| marched from | points | volume s | ratio to own level | min scaled Jacobian | 1 % | "
          "max non-orthogonality | wall angle p99 |")
    print("|---|---|---|---|---|---|---|---|")
    baseline = None
    for marching_level in range(fitter.level, 0, -1):
        started = time.perf_counter()
        volume = bvmesh.volume.offset_and_farfield(
            fitter, marching_level=None if marching_level == fitter.level else marching_level,
            reference_length=LENGTH, reynolds_number=1e6)
        seconds = time.perf_counter() - started
        baseline = baseline or seconds
        print("| level {} | {} | {:.2f} | {:.3f} | {:.3f} | {:.3f} | {:.1f} | {:.2f} |".format(
            marching_level, points[marching_level], seconds, seconds / baseline, *quality_row(volume)))
    print("automatic (marching_level=-1, limit {}): levels tried {}".format(
        bvmesh.volume.MARCHING_POINT_LIMIT,
        bvmesh.volume.marching_levels(fitter.level, points)))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2)

"""Closest-point throughput of bvmesh.Target against FreeCAD's own calls, in one run on the same
points (ONERA M6 wing, points within 1% of the model size of its surface):

  shape.distToShape(Part.Vertex(p))            per point (BRepExtrema_DistShapeShape)
  face.Surface.projectPoint(p) for every face  per point (GeomAPI_ProjectPointOnSurf; trims ignored)
  bvmesh.Target.project(points)                cold, and warm from the previous (face, u, v)

Run:  PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_projection_freecad.py [points] [baseline points]
"""

import os
import sys
import time

import numpy as np

sys.path.append("/usr/lib/freecad-python3/lib")
import FreeCAD  # noqa: E402
import Part  # noqa: E402

import bvmesh  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
WING = os.path.join(HERE, "..", "tests", "data", "AileM6_with_sharp_TE.stp")


def main():
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 200000
    baseline_count = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    shape = Part.read(WING)
    start = time.perf_counter()
    target = bvmesh.Target.from_brep(shape.exportBrepToString())
    print("target from FreeCAD BREP text: {:.3f} s, {} triangles".format(
        time.perf_counter() - start, target.report()["triangles"]))
    size = target.report()["diagonal"]
    rng = np.random.default_rng(1)
    nodes = np.asarray(target.mesh_nodes)
    points = nodes[rng.integers(0, len(nodes), count)] + rng.uniform(-0.01 * size, 0.01 * size, (count, 3))
    moved = points + rng.uniform(-1e-3 * size, 1e-3 * size, (count, 3))

    vectors = [FreeCAD.Vector(*p) for p in points[:baseline_count]]
    start = time.perf_counter()
    for v in vectors:
        shape.distToShape(Part.Vertex(v))
    dist_to_shape = (time.perf_counter() - start) / baseline_count

    surfaces = [face.Surface for face in shape.Faces]
    start = time.perf_counter()
    for v in vectors:
        for surface in surfaces:
            try:
                surface.projectPoint(v)
            except Part.OCCError:
                pass
    project_point = (time.perf_counter() - start) / baseline_count

    print("baselines ({} points): distToShape {:.3f} ms/point, Surface.projectPoint x {} faces {:.3f} ms/point".format(
        baseline_count, 1e3 * dist_to_shape, len(surfaces), 1e3 * project_point))
    print("{:<8} {:<5} {:>12} {:>10} {:>13} {:>15}".format(
        "threads", "start", "points/s", "us/point", "x distToShape", "x projectPoint"))
    for threads in (1, 2):
        timed = bvmesh.Target.from_brep(shape.exportBrepToString(), threads=threads)
        previous = timed.project(points)
        start = time.perf_counter()
        cold = timed.project(moved)
        cold_seconds = time.perf_counter() - start
        start = time.perf_counter()
        warm = timed.project(moved, hint_faces=previous["faces"], hint_uv=previous["params"])
        warm_seconds = time.perf_counter() - start
        for name, seconds in (("cold", cold_seconds), ("warm", warm_seconds)):
            per_point = seconds / count
            print("{:<8} {:<5} {:>12.0f} {:>10.2f} {:>13.0f} {:>15.0f}".format(
                threads, name, 1 / per_point, 1e6 * per_point, dist_to_shape / per_point, project_point / per_point))
        print("         max |warm - cold| distance: {:.3g}".format(np.abs(warm["distances"] - cold["distances"]).max()))


if __name__ == "__main__":
    main()

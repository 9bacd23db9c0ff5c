"""Normal jumps across the B-spline charts' smooth borders with and without tangent_continuity,
and what the option costs: the sphere fitted from the cube to level 4 and the M6 main job's fit at
level 3 (docs/fitting.md, "Tangent planes across chart borders"). The jumps are measured at 16
points per edge from the charts' poles (tests/python/fixtures.py); on the M6 also outside 2 mm of
the trailing edge's tip corners, whose cone points have no tangent plane.

    PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_chart_borders.py
"""

import os
import sys
import time

import numpy as np

sys.path.append("/usr/lib/freecad-python3/lib")
sys.path.append(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "python"))
import bvmesh  # noqa: E402
from bvmesh import paths, polyhedra  # noqa: E402
from fixtures import CUBE_FACES, CUBE_VERTICES, smooth_border_normal_jumps, sphere_target  # noqa: E402


def sphere_mesh():
    fitter = bvmesh.SurfaceFitter(sphere_target(), bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), max_level=4,
                                  tolerance=1e-9)
    fitter.run()
    return fitter.mesh


def m6_mesh():
    core = bvmesh.load_core()
    wing, _, _ = polyhedra.half_model_target(core.read_cad_file_as_brep(paths.EXAMPLE_WING))
    placed = polyhedra.place("half_wing", wing)
    fitter = bvmesh.SurfaceFitter(wing, placed["mesh"], placed["feature_map"], symmetry_plane=placed["symmetry_plane"],
                                  max_level=3, tolerance=1e-5 * 805.0, check_samples_per_face=0)
    fitter.run()
    return fitter.mesh


def main():
    print("| surface | tangent_continuity | max jump (deg) | off the tip corners (deg) | max_kink_degrees | "
          "max_distance | max_deviation | poles | conversion s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, mesh in (("sphere level 4", sphere_mesh()), ("M6 level 3", m6_mesh())):
        vertices = np.asarray(mesh.vertices)
        tip = vertices[[c for c in mesh.corners if vertices[c][1] > 1000.0]]
        for continuity in (False, True):
            started = time.perf_counter()
            result = bvmesh.limit_surface_to_bsplines(mesh, tangent_continuity=continuity, sew=False)
            seconds = time.perf_counter() - started
            angles, points = smooth_border_normal_jumps(result)
            off_tip = angles
            if len(tip):
                off_tip = angles[np.linalg.norm(points[:, None, :] - tip[None], axis=2).min(axis=1) >= 2.0]
            poles = sum(chart["poles"].shape[0] * chart["poles"].shape[1] for chart in result["charts"])
            print("| {} | {} | {:.3g} | {:.3g} | {:.3g} | {:.3g} | {:.3g} | {} | {:.2f} |".format(
                name, continuity, angles.max(), off_tip.max(), result["max_kink_degrees"], result["max_distance"],
                result["max_deviation"], poles, seconds))


if __name__ == "__main__":
    main()

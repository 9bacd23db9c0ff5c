"""How dense the two-sided check's target side needs to be: the M6 main-job fit (converged by the
stop rule) and a sphere fit, each checked with the CAD sampled k times denser along every
tessellation triangle side (check_target_subdivisions, Target.surface_samples): target points,
target -> limit (raw and beyond the CAD's own tolerance) and the check's time.

    PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_check_density.py
"""

import sys
import time

sys.path.append("/usr/lib/freecad-python3/lib")
import FreeCAD  # noqa: E402,F401  -- Part needs it loaded first
import Part  # noqa: E402

import bvmesh  # noqa: E402
from bvmesh import paths, polyhedra  # noqa: E402


def table(name, fitter, densities=(1, 2, 4, 8)):
    print("{}: {} control points".format(name, fitter.mesh.num_vertices))
    print("| k | target points | target -> limit | at | beyond CAD tolerance | limit -> target | check s |")
    print("|---|---|---|---|---|---|---|")
    for k in densities:
        started = time.perf_counter()
        check = fitter.two_sided_distance(4, k)
        seconds = time.perf_counter() - started
        at = ", ".join("{:.2f}".format(c) for c in check["target_to_limit_at"])
        print("| {} | {} | {:.3e} | ({}) | {:.3e} | {:.3e} | {:.2f} |".format(
            k, check["target_points"], check["target_to_limit"], at, check["target_to_limit_beyond_cad"],
            check["limit_to_target"], seconds))


def main():
    target, _, plane = polyhedra.half_model_target(Part.read(paths.EXAMPLE_WING))
    mesh, features = polyhedra.place_template(target, "half_wing", tip_kinks="follow")  # as the main job
    fitter = bvmesh.SurfaceFitter(target, mesh, features, symmetry_plane=plane, tolerance=1e-5 * 810.491484116107)
    result = fitter.run()
    table("M6, {} at level {}".format(result["reason"], result["history"][-1]["level"]), fitter)

    sphere = bvmesh.Target.from_brep(Part.makeSphere(1.0).exportBrepToString())
    mesh, features = polyhedra.place_template(sphere, "sphere")
    fitter = bvmesh.SurfaceFitter(sphere, mesh, features, tolerance=1e-5)
    result = fitter.run()
    table("unit sphere, {} at level {}".format(result["reason"], result["history"][-1]["level"]), fitter)


if __name__ == "__main__":
    main()

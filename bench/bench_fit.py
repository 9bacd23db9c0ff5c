"""The M6 fit end to end, step by step: where the time goes per level and how it grows with the
number of control points (3 corrections per level); then the main job's fit to tolerance
(SurfaceFitter.run with its defaults) timed as a whole. Same setting as the main job (half-wing
template, symmetry plane, closest-point projection, CGLS).

    PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_fit.py [max_level]
"""

import math
import os
import sys
import time

sys.path.append("/usr/lib/freecad-python3/lib")
import FreeCAD  # noqa: E402,F401  -- Part needs it loaded first
import Part  # noqa: E402

import bvmesh  # noqa: E402
from bvmesh import paths, polyhedra  # noqa: E402


def timed(work):
    started = time.perf_counter()
    result = work()
    return time.perf_counter() - started, result


def main(max_level):
    wing = Part.read(paths.EXAMPLE_WING)
    build_seconds, (target, _, plane) = timed(lambda: polyhedra.half_model_target(wing))
    place_seconds, (mesh, features) = timed(lambda: polyhedra.place_template(target, "half_wing", tip_kinks="follow"))
    fitter = bvmesh.SurfaceFitter(target, mesh, features, symmetry_plane=plane, check_samples_per_face=0)
    print("target {:.2f} s, template placement {:.2f} s, {} control points".format(
        build_seconds, place_seconds, mesh.num_vertices))
    print("| level | control points | samples | subdivide s | samples s | project s | approximate s | "
          "3 corrections s | level s | max distance |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    total = build_seconds + place_seconds
    for level in range(1, max_level + 1):
        t_sub, _ = timed(fitter.subdivide)
        t_samples, samples = timed(fitter.compute_limit_samples)
        t_project, _ = timed(fitter.project)
        t_approx, _ = timed(fitter.approximate)
        t_correct, _ = timed(lambda: fitter.correct_parameters(3))
        record = fitter.record()
        level_seconds = t_sub + t_samples + t_project + t_approx + t_correct
        total += level_seconds
        points = fitter.mesh.num_vertices
        rows.append((points, level_seconds))
        print("| {} | {} | {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3e} |".format(
            level, points, len(samples), t_sub, t_samples, t_project, t_approx, t_correct, level_seconds,
            record["max_distance"]))
    (p0, s0), (p1, s1) = rows[-2], rows[-1]
    print("growth exponent of the level time in the control points (last two levels): {:.2f}".format(
        math.log(s1 / s0) / math.log(p1 / p0)))
    print("total {:.2f} s for {} levels".format(total, max_level))


def fit_to_tolerance():
    """The main job's fit: target, template, SurfaceFitter.run() with its defaults to 1e-5 of the
    root chord, "converged" by the stop rule (samples and two-sided check within the tolerance);
    the same fit stopped on the samples alone (check off) as the baseline."""
    tolerance = 1e-5 * 810.491484116107
    for label, check_samples in (("samples alone", 0), ("stop rule with the two-sided check", 4)):
        started = time.perf_counter()
        target, _, plane = polyhedra.half_model_target(Part.read(paths.EXAMPLE_WING))
        mesh, features = polyhedra.place_template(target, "half_wing", tip_kinks="follow")  # as the main job
        fitter = bvmesh.SurfaceFitter(target, mesh, features, symmetry_plane=plane, tolerance=tolerance,
                                      check_samples_per_face=check_samples)
        result = fitter.run()
        seconds = time.perf_counter() - started
        last = result["history"][-1]
        print("fit to tolerance {:.3e}, {}: {} at level {} ({} control points, {} passes), max {:.3e}, "
              "{:.2f} s in all".format(tolerance, label, result["reason"], last["level"], last["control_points"],
                                       len(result["history"]), last["max_distance"], seconds))
        if check_samples:
            print("  two-sided check: limit -> target {:.3e}, target -> limit {:.3e} ({:.3e} beyond the CAD's "
                  "own tolerance)".format(last["limit_to_target"], last["target_to_limit"],
                                          last["target_to_limit_beyond_cad"]))
        else:
            baseline = seconds
    print("stop rule / samples alone: {:.2f}x".format(seconds / baseline))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 4)
    fit_to_tolerance()

"""The volume stage on the ONERA M6 (the main job's setting): the block mesh from the fitted wall at
surface levels 2, 3, 4 (time, peak memory, blocks and poles, or where the marching folds; the fit
stops at level 3 when it reaches the main job's tolerance there), each
against the fit to that level measured in the same run; then the Euler grid of about 1 M cells
from the level-2 blocks, against per-point evaluation of the same blocks measured in the same run.

    PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_volume_m6.py [max_level]
"""

import os
import resource
import sys
import time

import numpy as np

sys.path.append("/usr/lib/freecad-python3/lib")
import FreeCAD  # noqa: E402,F401  -- Part needs it loaded first
import Part  # noqa: E402

import bvmesh  # noqa: E402
import bvmesh.grid  # noqa: E402
import bvmesh.volume  # noqa: E402
from bvmesh import paths, polyhedra  # noqa: E402

ROOT_CHORD = 810.5
REYNOLDS_NUMBER = 11.72e6


def timed(work):
    started = time.perf_counter()
    result = work()
    return time.perf_counter() - started, result


def peak_megabytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def fitted(target, mesh, features, plane, level):
    fitter = bvmesh.SurfaceFitter(target, mesh, features, symmetry_plane=plane, max_level=level,
                                  tolerance=1e-5 * ROOT_CHORD, check_samples_per_face=0)
    fitter.run()
    return fitter


def main(max_level):
    target, _, plane = polyhedra.half_model_target(Part.read(paths.EXAMPLE_WING))
    mesh, features = polyhedra.place_template(target, "half_wing")
    print("| level asked / reached | control points | fit s | volume s | volume / fit | peak MB | blocks | poles | "
          "outcome |")
    print("|---|---|---|---|---|---|---|---|---|")
    level2 = None
    for level in range(2, max_level + 1):
        fit_seconds, fitter = timed(lambda: fitted(target, mesh, features, plane, level))
        try:
            seconds, volume = timed(lambda: bvmesh.volume.offset_and_farfield(
                fitter, reference_length=ROOT_CHORD, reynolds_number=REYNOLDS_NUMBER))
        except bvmesh.SolverError as error:
            print("| {} / {} | {} | {:.2f} | - | - | {:.0f} | - | - | {} |".format(
                level, fitter.level, fitter.mesh.num_vertices, fit_seconds, peak_megabytes(), str(error).split(" (")[0]))
            continue
        blocks = volume.blocks
        poles = sum(int(np.prod(blocks.poles(b).shape[:3])) for b in range(blocks.block_count))
        print("| {} / {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.0f} | {} | {} | {} control layers |".format(
            level, fitter.level, fitter.mesh.num_vertices, fit_seconds, seconds, seconds / fit_seconds, peak_megabytes(),
            blocks.block_count, poles, len(volume.layer_distance)))
        if level == 2:
            level2 = volume
    if level2 is None:
        return
    refine_seconds, refined = timed(lambda: bvmesh.grid.refine(level2, "euler", target_cells=1_000_000))
    points = refined.grid.point_count
    # The baseline: the core's per-point evaluation (BlockMesh.evaluate, one basis evaluation per
    # point, threaded) of block 0 at as many random parameters.
    blocks = level2.blocks
    ni, nj, nk = refined.grid.size(0)
    samples = np.random.default_rng(1).random((points // 4, 3))
    per_point_seconds, _ = timed(lambda: blocks.evaluate(0, samples))
    per_point_seconds *= 4
    per_point_rate = points / per_point_seconds
    rate = points / refine_seconds
    print()
    print("Euler grid from the level-2 blocks: {} cells, {} points in {:.2f} s: {:.2f} M points/s; per-point "
          "evaluation {:.3f} M points/s: {:.1f}x".format(refined.grid.cell_count, points, refine_seconds, rate / 1e6,
                                                         per_point_rate / 1e6, rate / per_point_rate))
    print("block 0 grid {} x {} x {}; peak memory {:.0f} MB".format(ni, nj, nk, peak_megabytes()))


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 4)
    sys.stdout.flush()
    os._exit(0)  # FreeCAD's modules keep threads that would hold the exit

"""The volume stage on the ONERA M6 (the main job's setting): the block mesh from the fitted wall at
surface levels 2, 3, 4 (time, peak memory, blocks and poles, or where the marching folds; the fit
stops at level 3 when it reaches the main job's tolerance there), and above level 2 also with the
layers marched from level 2 and carried onto that wall (the main job's way), at level 2 also with
the smoothed far field (farfield_scheme='smoothed'; the default is 'hyperbolic'), each against the fit to that level
measured in the same run; then the euler and rans grids of about
1 M cells from the level-2 blocks, against per-point evaluation of as many points of the same
blocks measured in the same run, and the CGNS and OpenFOAM writers on the euler grid. The
level-2 blocks are left in a file for build/bench/bench_grid, which measures each step's memory.

    PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_volume_m6.py [max_level]
"""

import os
import resource
import sys
import tempfile
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
    level2 = fitter2 = None
    for level in range(2, max_level + 1):
        fit_seconds, fitter = timed(lambda: fitted(target, mesh, features, plane, level))
        if level == 2:
            fitter2 = fitter
        ways = [("marched", {})]
        if fitter2 is not None and fitter.level > 2:
            ways.append(("carried from level 2", {"marching_wall": fitter2}))
        if level == 2:
            ways.append(("marched, smoothed far field", {"farfield_scheme": "smoothed"}))
        for way, extra in ways:
            try:
                seconds, volume = timed(lambda: bvmesh.volume.offset_and_farfield(
                    fitter, reference_length=ROOT_CHORD, reynolds_number=REYNOLDS_NUMBER, **extra))
            except bvmesh.SolverError as error:
                print("| {} / {} | {} | {:.2f} | - | - | {:.0f} | - | - | {}: {} |".format(
                    level, fitter.level, fitter.mesh.num_vertices, fit_seconds, peak_megabytes(), way,
                    str(error).split(" (")[0]))
                continue
            blocks = volume.blocks
            poles = sum(int(np.prod(blocks.poles(b).shape[:3])) for b in range(blocks.block_count))
            print("| {} / {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.0f} | {} | {} | {}: {} control layers |".format(
                level, fitter.level, fitter.mesh.num_vertices, fit_seconds, seconds, seconds / fit_seconds,
                peak_megabytes(), blocks.block_count, poles, way, len(volume.layer_distance)))
            if level == 2 and not extra:
                level2 = volume
    if level2 is None:
        return
    block_file = os.path.join(tempfile.gettempdir(), "bvmesh_m6_level2.blocks")
    level2.blocks.write(block_file)
    print()
    print("Grids of about 1 M cells from the level-2 blocks (written to {}, for bench_grid) against per-point "
          "evaluation (BlockMesh.evaluate) of as many points, block by block at a lattice of each block's grid "
          "size, in the same run:".format(block_file))
    print()
    print("| preset | cells | points | wall-normal points | refinement s | M points/s | per-point M points/s | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    grids = {}
    for preset in ("euler", "rans"):
        refine_seconds, refined = timed(lambda: bvmesh.grid.refine(
            level2, preset, target_cells=1_000_000, reynolds_number=REYNOLDS_NUMBER))
        grids[preset] = refined
        points = refined.grid.point_count
        per_point_seconds = 0.0
        for b in range(refined.grid.block_count):
            parameters = lattice(level2.blocks, b, refined.grid.size(b))
            per_point_seconds += timed(lambda: level2.blocks.evaluate(b, parameters))[0]
        print("| {} | {} | {} | {} | {:.3f} | {:.2f} | {:.2f} | {:.1f} |".format(
            preset, refined.grid.cell_count, points, refined.normal_points, refine_seconds, points / refine_seconds / 1e6,
            points / per_point_seconds / 1e6, per_point_seconds / refine_seconds))
    print()
    print("Writers on the euler grid (bvmesh.grid.write_*, each with its check for non-positive cells):")
    print()
    print("| writer | s |")
    print("|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for name, write in (("CGNS", lambda: bvmesh.grid.write_cgns(grids["euler"], os.path.join(folder, "m6.cgns"))),
                            ("OpenFOAM", lambda: bvmesh.grid.write_openfoam(grids["euler"], os.path.join(folder, "m6")))):
            print("| {} | {:.2f} |".format(name, timed(write)[0]))
    print()
    print("peak memory {:.0f} MB (the fit's; bench_grid on the block file measures each step's own)".format(
        peak_megabytes()))


def lattice(blocks, block, size):
    """Parameters of an ni x nj x nk lattice over the block's parameter box, i fastest."""
    axes = [np.linspace(knots[0], knots[-1], n) for knots, n in zip(blocks.knots(block), size)]
    w, v, u = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    return np.column_stack([u.ravel(), v.ravel(), w.ravel()])


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 4)
    sys.stdout.flush()
    os._exit(0)  # FreeCAD's modules keep threads that would hold the exit

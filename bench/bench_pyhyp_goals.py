"""The volume-core issue's goals against pyHyp, on the same kind of mesh: the ONERA M6 half wing
with its symmetry plane, a y+ ~ 1 grid of about 2.5 M cells. From the main job's fitted walls
(level 3, layers marched from level 2; fits not timed) to the refined grid, timed (march and
refinement, as pyHyp's 300 s on 2 cores includes its marching only), then the quality figures the
goals name. pyHyp is not installed here: its figures are the issue's (measured on this machine
with the MACH-Aero tutorial's settings on its blunt-trailing-edge M6, 2.6 M cells).

    PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 bench/bench_pyhyp_goals.py [cells [fans]]

(`fans`: the sharp trailing edge cut open with a fan of prisms, knife_edge_fans=True.)
"""

import sys
import time

import numpy as np

sys.path.append("/usr/lib/freecad-python3/lib")
import FreeCAD  # noqa: E402,F401  -- Part needs it loaded first
import Part  # noqa: E402

import bvmesh.grid  # noqa: E402
import bvmesh.volume  # noqa: E402
from bench_volume_m6 import REYNOLDS_NUMBER, fitted  # noqa: E402  -- the main job's fit, as that benchmark's
from bvmesh import paths, polyhedra  # noqa: E402

PYHYP_SECONDS = 300.0


def main(cells, fans):
    target, _, plane = polyhedra.half_model_target(Part.read(paths.EXAMPLE_WING))
    mesh, features = polyhedra.place_template(target, "half_wing", tip_kinks="follow")  # as the main job
    wall, marching_wall = (fitted(target, mesh, features, plane, level) for level in (3, 2))
    started = time.perf_counter()
    volume = bvmesh.volume.offset_and_farfield(wall, marching_wall=marching_wall, reference_length=805.0,
                                               reynolds_number=REYNOLDS_NUMBER, knife_edge_fans=fans)
    march_seconds = time.perf_counter() - started
    refined = bvmesh.grid.refine(volume, "rans", reynolds_number=REYNOLDS_NUMBER, target_cells=cells)
    seconds = time.perf_counter() - started
    report = bvmesh.grid.quality(refined)
    jacobian = np.asarray(report["scaled_jacobian"])
    wall_angle = np.asarray(report["wall_angle"])
    heights = np.asarray(report["first_cell_height"])
    asked = refined.first_cell_height_asked
    faces = np.asarray(report["non_orthogonality"])
    height_off = max(heights.max() / asked - 1.0, 1.0 - heights.min() / asked)
    print("M6 rans grid{}: {} cells, {} blocks; march {:.2f} s, refinement {:.2f} s".format(
        " with fans at the trailing edge" if fans else "", refined.grid.cell_count, volume.blocks.block_count, march_seconds, seconds - march_seconds))
    print()
    print("| figure | goal | BVMesh | pyHyp (the issue's) | met |")
    print("|---|---|---|---|---|")
    rows = [
        ("minimum scaled Jacobian", ">= 0.6", "{:.3f} (1 %: {:.3f}; {} cells below 0.6)".format(
            jacobian.min(), np.percentile(jacobian, 1), int((jacobian < 0.6).sum())),
         "0.555", jacobian.min() >= 0.6),
        ("wall angle, 95th percentile (degrees)", "<= 1", "{:.2f} (worst {:.1f})".format(
            np.percentile(wall_angle, 95), wall_angle.max()), "3.4 (30 at the worst corner)",
         np.percentile(wall_angle, 95) <= 1.0),
        ("first-cell height off the asked {:.3g} mm".format(asked), "<= 10 %", "{:.2g} %".format(100 * height_off),
         "4x across the wing", height_off <= 0.1),
        ("cells with a face above 70 degrees", "0", "{} (largest {:.1f})".format(int((faces > 70).sum()), faces.max()),
         "3612 faces", not (faces > 70).any()),
        ("march + refinement (s), 2 cores", "<= {:.0f} (300 / 20)".format(PYHYP_SECONDS / 20), "{:.2f}".format(seconds),
         "300", seconds <= PYHYP_SECONDS / 20),
    ]
    for name, goal, ours, theirs, met in rows:
        print("| {} | {} | {} | {} | {} |".format(name, goal, ours, theirs, "yes" if met else "no"))
    block = np.asarray(report["cell_block"])
    for name, poor in (("below a scaled Jacobian of 0.6", jacobian < 0.6), ("with a face above 70 degrees", faces > 70)):
        blocks, counts = np.unique(block[poor], return_counts=True)
        print("cells {} by block: {}".format(name, ", ".join("{}: {}".format(b, c) for b, c in zip(blocks, counts))))


if __name__ == "__main__":
    main(int(float(sys.argv[1])) if len(sys.argv) > 1 else 2500000, sys.argv[2:] == ["fans"])

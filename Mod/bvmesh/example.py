"""The main job on the bundled example: the ONERA M6 half wing (tests/data), fitted from the
half-wing template with its trailing edge as a crease and its root on the symmetry plane y = 0,
then meshed: the boundary layer and far field as B-spline blocks, evaluated on a point-matched
Euler grid, measured and written for flow solvers. It is bvmesh.pipeline's job with the M6's
settings and a cut picture at a span station of the wind tunnel's.

Writes into the output folder: the FreeCAD document (M6.FCStd: CAD, target, polyhedron, fit,
B-spline shell, volume mesh, grid, cut, quality, exports), the B-spline surface (M6_surface.step),
the convergence plot (M6_convergence.png) and report (M6_report.md), the grid as CGNS (M6.cgns) and
as an OpenFOAM case (M6_openfoam/), the volume report (M6_volume_report.md), the grid around the
section at 44 % of the span (M6_cut_eta044.png) and the quality histograms (M6_quality.png). Runs
headless (plain /usr/bin/python3 or freecadcmd)."""

from bvmesh import api, paths, pipeline

# Wind-tunnel case 2308 of the M6 (AGARD AR-138): Reynolds number on the mean aerodynamic chord.
REYNOLDS_NUMBER = 11.72e6
CUT_ETA = 0.44
# The M6's reference semispan (the wind-tunnel stations' eta = y / b); the CAD's rounded tip cap
# reaches 1218.5 mm.
SEMISPAN = 1196.3
TARGET_CELLS = 1_000_000


def _section_window(grid_object, eta):
    """((leading x, trailing x), mean z, point, normal) of the wing section at span fraction eta,
    from the target's CAD faces sliced there."""
    point, normal = api.span_station(grid_object, eta, SEMISPAN)
    target = grid_object.VolumeMesh.Fit.Target
    wires = target.Shape.slice(normal, point.dot(normal))
    if not wires:
        raise RuntimeError("the cut at {:.0f} % of the span misses the wing".format(100 * eta))
    box = wires[0].BoundBox
    for wire in wires[1:]:
        box.add(wire.BoundBox)
    return (box.XMin, box.XMax), 0.5 * (box.ZMin + box.ZMax), point, normal


def _cut_picture(grid_object, path):
    """The grid around the section at CUT_ETA: the whole domain, the section, the trailing edge.
    Returns (path, point, normal), as pipeline.run_volume's `cut` does."""
    from bvmesh import grid

    (leading, trailing), z, point, normal = _section_window(grid_object, CUT_ETA)
    chord = trailing - leading
    radius = grid_object.VolumeMesh.FarfieldDistanceUsed
    views = [
        ("whole domain", ((leading - radius, z - radius), (trailing + radius, z + radius))),
        ("section", ((leading - 0.15 * chord, z - 0.35 * chord), (trailing + 0.15 * chord, z + 0.35 * chord))),
        ("trailing edge", ((trailing - 0.04 * chord, z - 0.03 * chord), (trailing + 0.04 * chord, z + 0.03 * chord))),
    ]
    title = "ONERA M6: grid at {:.0f} % of the span (y = {:.1f})".format(100 * CUT_ETA, point.y)
    grid.plot_cut(api.grid_of(grid_object), tuple(point), tuple(normal), path, views, title=title)
    return path, tuple(point), tuple(normal)


def run(output_dir, max_level=5, relative_tolerance=1e-5, volume=True, log=print, grid_method="bspline",
        subdivision_steps=1):
    """Runs the example and returns pipeline.run's dict, with the root chord as 'chord'.
    relative_tolerance is relative to the root chord. volume=False stops after the surface stage.
    grid_method, subdivision_steps: as pipeline.run_volume takes them."""
    outcome = pipeline.run(paths.EXAMPLE_WING, output_dir, "half_wing", name="M6", title="ONERA M6 half wing",
                           template_parameters={"tip_kinks": "follow"}, half_model=True,
                           relative_tolerance=relative_tolerance, max_level=max_level,
                           reynolds_number=REYNOLDS_NUMBER, volume=volume, target_cells=TARGET_CELLS,
                           cut=_cut_picture, log=log, grid_method=grid_method, subdivision_steps=subdivision_steps,
                           file_names={"cut": "M6_cut_eta044.png"})
    outcome["chord"] = outcome["reference_length"]
    return outcome

"""The volume grid, headless: the B-spline blocks refined into a solver grid, its quality, and
the files flow solvers read.

    import bvmesh.grid
    refined = bvmesh.grid.refine(volume_mesh, preset="rans", reynolds_number=11.72e6)
    report = bvmesh.grid.quality(refined)
    print(bvmesh.grid.quality_table(report))
    bvmesh.grid.write_openfoam(refined, "M6_openfoam")

One B-spline mesh serves both presets: `euler` (no wall clustering, every wall-normal line grows
by the same ratio) and `rans` (first cell height for y+ ~ 1 by the flat-plate estimate, as many
wall-normal points as keep the growth ratio at most 1.2). `max_turning_angle` (degrees) gathers
tangential points where the wall bends, a wing's nose (docs/grid.md: what it costs on the M6).
Both presets cluster a set of tangential lines at an end where the wall edges continuing it are
more than 3 (euler) or 4 (rans) times finer (`max_spacing_jump`, 0 for none): a wing's span
towards its tip cap (docs/grid.md: why the two differ). Both
slide the far field's wall-normal lines towards points uniform in arc length on the outer
boundary (`even_far_field`; RefinedGrid.even_far_field_used is False where that would fold a
cell and the grid was refined without), so that the marching's fan-out at a wing's tip does not
reach the outer sphere as cells a hundred times apart.
`refine(..., method="subdivision", steps=k)` is the other refinement: k volumetric Catmull-Clark
steps of the blocks' control mesh.
A grid of more points than the free memory holds (point_budget()) is refused with a ValueError
before any point is computed, instead of exhausting the memory of the session.
"""

from . import load_core, memory
from .options import check_options

PRESETS = {
    "euler": dict(normal_points=49, growth=1.2, max_spacing_jump=3.0, even_far_field=True),
    "rans": dict(normal_points=0, y_plus=1.0, growth=1.2, max_spacing_jump=4.0, even_far_field=True),
}

METRICS = ("scaled_jacobian", "non_orthogonality", "skewness", "aspect_ratio", "growth_ratio", "determinant",
           "wall_angle", "first_cell_height")


FACE_NAMES = ("u_min", "u_max", "v_min", "v_max", "w_min", "w_max")

# Peak memory per grid point of a grid, its quality and its solver files (190 bytes per cell,
# measured on the M6's euler grids of 1 M and 4 M cells; docs/grid.md), with some room.
BYTES_PER_POINT = 256


def point_budget():
    """The most grid points the free memory holds (the kernel's MemAvailable over BYTES_PER_POINT),
    or 0 (no limit) where the free memory is not known."""
    return memory.budget(BYTES_PER_POINT)


def face_array(array, face):
    """The (n_a, n_b, ...) sheet of a block's (n_u, n_v, n_w, ...) array (poles or grid points) on
    `face` (u_min .. w_max): a, b its two other directions in increasing order, as BlockMesh.faces
    orients them."""
    import numpy as np

    direction, end = divmod(FACE_NAMES.index(face), 2)
    return np.take(array, -1 if end else 0, axis=direction)


def wall_points(grid):
    """The points of every block face whose condition is 'wall', as one (n, 3) array (points on
    shared face edges repeated)."""
    import numpy as np

    grid = _grid_of(grid)
    sheets = [face_array(grid.points(b), name).reshape(-1, 3)
              for b in range(grid.block_count) for name, face in grid.faces(b).items() if face["condition"] == "wall"]
    return np.concatenate(sheets) if sheets else np.zeros((0, 3))


def _grid_of(grid):
    core = load_core()
    if isinstance(grid, core.RefinedGrid):
        return grid.grid
    if isinstance(grid, core.StructuredGrid):
        return grid
    raise TypeError("expected a bvmesh grid (refine's result or a StructuredGrid), got {}".format(type(grid).__name__))


def _blocks_of(blocks, caller):
    core = load_core()
    if isinstance(blocks, core.VolumeMesh):
        return blocks.blocks
    if isinstance(blocks, core.BlockMesh):
        return blocks
    raise TypeError("{} takes a VolumeMesh or a BlockMesh, got {}".format(caller, type(blocks).__name__))


def refine(blocks, preset="euler", method="bspline", steps=None, **options):
    """Refines the blocks into a point-matched grid.

    blocks: a VolumeMesh (offset_and_farfield's result; its reference length is used) or a
    BlockMesh. method 'bspline': the blocks evaluated on a stretched grid; preset: 'euler' or
    'rans' (see the module doc), or None for options alone; options: those of
    bvmesh._core.refine_blocks (normal_points, first_cell_height, y_plus, reynolds_number,
    reference_length, growth, distribution, edge_points, tangential_spacing, target_cells,
    edge_end_spacing, max_turning_angle, max_spacing_jump, even_far_field,
    feature_spacings, max_points), overriding the preset's. feature_spacings: [{"points": (n, 3)
    polyline, "spacing": s}, ...] clusters the wall edges that leave a feature line (a leading
    edge) to s there (docs/grid.md). max_points: default point_budget(), 0 for no limit. From a
    VolumeMesh in a box or cylinder domain, every outer quad is tagged inlet, outlet or side by
    where it lies (a block face reaching over the domain's edges is split;
    RefinedGrid.outer_faces_split counts them).
    Returns a RefinedGrid (.grid, and the measured first cell heights and growth).

    method 'subdivision': `steps` volumetric Catmull-Clark steps of the control mesh
    (docs/volume.md); no stretching, so preset and options do not apply. blocks may also be a
    ControlVolume (bvmesh.volume.control_volume): its wall points then end on the fitted limit
    surface. Returns a StructuredGrid, which quality() and the writers take as they take a
    RefinedGrid."""
    core = load_core()
    if method == "subdivision":
        if options:
            raise ValueError("method='subdivision' takes steps only, not {}".format(", ".join(sorted(options))))
        if not isinstance(steps, int) or isinstance(steps, bool) or steps < 1:
            raise ValueError("method='subdivision' needs steps, an int >= 1, got {!r}".format(steps))
        if isinstance(blocks, core.ControlVolume):
            return core.subdivide_control_volume(blocks, steps, max_points=point_budget())
        return core.subdivide_blocks(_blocks_of(blocks, "refine"), steps, max_points=point_budget())
    if method != "bspline":
        raise ValueError("method must be 'bspline' or 'subdivision', got {!r}".format(method))
    if steps is not None:
        raise ValueError("steps applies to method='subdivision' only")
    check_options(core.refine_blocks, "refine", options)
    settings = {}
    if preset is not None:
        if preset not in PRESETS:
            raise ValueError("preset must be one of {} or None, got {!r}".format(", ".join(sorted(PRESETS)), preset))
        settings.update(PRESETS[preset])
    settings["max_points"] = point_budget()
    settings.update(options)
    if isinstance(blocks, core.VolumeMesh):
        settings.setdefault("reference_length", blocks.reference_length)
        settings["outer_domain_of"] = blocks  # a box's outer faces patched quad by quad
    blocks = _blocks_of(blocks, "refine")
    if settings.get("y_plus", 0.0) > 0.0 and not settings.get("first_cell_height", 0.0):
        if not settings.get("reynolds_number", 0.0) > 0.0:
            raise ValueError("a y+ target (the rans preset) needs reynolds_number (based on reference_length)")
    return core.refine_blocks(blocks, **settings)


def quality(grid):
    """Cell quality of a grid: per-cell numpy arrays (scaled_jacobian, non_orthogonality, skewness,
    aspect_ratio, growth_ratio, determinant, volume, cell_block), wall_angle per wall cell,
    first_cell_height per wall point, and 'summary' / 'block_summary' (count, min, p01, median,
    p99, max per metric). determinant is OpenFOAM's cell determinant, which checkMesh
    -allGeometry fails below 1e-3 (thin cells: about 729 (h / a)^4 for an h x a x a cell)."""
    return load_core().grid_quality(_grid_of(grid))


def quality_table(report, blocks=False):
    """The summary as a Markdown table (one row per metric; with blocks=True also per block)."""
    lines = ["| metric | min | 1 % | median | 99 % | max |", "|---|---|---|---|---|---|"]

    def rows(summary, prefix=""):
        for name in METRICS:
            if name in summary and summary[name]["count"]:
                s = summary[name]
                lines.append("| {}{} | {:.4g} | {:.4g} | {:.4g} | {:.4g} | {:.4g} |".format(
                    prefix, name, s["min"], s["p01"], s["median"], s["p99"], s["max"]))

    rows(report["summary"])
    if blocks:
        for b, summary in enumerate(report["block_summary"]):
            rows(summary, "block {} ".format(b))
    return "\n".join(lines) + "\n"


def write_histograms(report, path):
    """Histograms of the quality metrics as one PNG (matplotlib, no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    names = [name for name in METRICS if len(report[name])]
    columns = 3
    rows = (len(names) + columns - 1) // columns
    figure, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.2 * rows), squeeze=False)
    for axis, name in zip(axes.flat, names):
        values = np.asarray(report[name])
        # Log axes where the values span decades (a rans grid's first heights are all one value).
        logarithmic = (name in ("aspect_ratio", "determinant", "first_cell_height") and values.min() > 0
                       and values.max() > 10.0 * values.min())
        bins = np.geomspace(values.min(), values.max(), 40) if logarithmic else 40
        axis.hist(values, bins=bins, color="#3a6ea5")
        axis.set_yscale("log")
        if logarithmic:
            axis.set_xscale("log")
        axis.set_title(name.replace("_", " "))
        axis.set_ylabel("count")
    for axis in list(axes.flat)[len(names):]:
        axis.axis("off")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def write_openfoam(grid, case_directory, force=False):
    """An OpenFOAM case's constant/polyMesh (and a minimal system/ when it has none). Patches:
    wall (wall), symmetry (symmetryPlane), farfield (patch). Refuses a grid with a non-positive
    cell unless force=True."""
    load_core().write_openfoam(_grid_of(grid), str(case_directory), force)


def write_cgns(grid, path, force=False):
    """CGNS (HDF5): one structured zone per block, GridConnectivity1to1 on every shared face, BCs by
    family (wall: BCWallViscous for a rans grid, BCWall for euler; symmetry; farfield)."""
    load_core().write_cgns(_grid_of(grid), str(path), force)


def write_plot3d(grid, path, format="binary", force=False):
    """Plot3D multi-block whole grid, 'binary' (Fortran unformatted, double) or 'ascii' (17 digits)."""
    load_core().write_plot3d(_grid_of(grid), str(path), format, force)


def read_plot3d(path):
    """The blocks of a Plot3D whole grid file, each a (ni, nj, nk, 3) array."""
    return load_core().read_plot3d(str(path))


def write_vtk(grid, path, report=None, force=False):
    """VTK XML multiblock (path ending in .vtm, one .vts per block beside it) with the cell quality
    (of `report`, or measured here) and the block number as cell data, for ParaView."""
    import numpy as np

    grid = _grid_of(grid)
    if report is None:
        report = load_core().grid_quality(grid)
    fields = {name: report[name] for name in ("scaled_jacobian", "non_orthogonality", "skewness", "aspect_ratio",
                                               "growth_ratio", "determinant", "volume")}
    fields["block"] = np.asarray(report["cell_block"], dtype=float)
    load_core().write_vtk(grid, str(path), fields, force)


def write_gismo(blocks, path):
    """The B-spline blocks themselves as G+Smo XML, for isogeometric analysis (a VolumeMesh or a
    BlockMesh)."""
    load_core().write_gismo(_blocks_of(blocks, "write_gismo"), str(path))


def plane_cut(grid, point, normal):
    """The grid lines where the plane (point, normal) crosses the cells' faces: 'start' and 'end'
    (n, 3) per segment and its 'cell' (numbered as quality()'s arrays). A plane the grid lies wholly
    on one side of (a half model's symmetry plane) gives the grid lines lying in it."""
    return load_core().grid_plane_cut(_grid_of(grid), point, normal)


def plot_cut(grid, point, normal, path, views, values=None, title=None, value_label=None):
    """Pictures of a plane cut as one PNG: `views` is a list of (title, (low, high)) windows in the
    plane's coordinates (the two axes most nearly in the plane); the segments coloured by `values`
    (one per cell) when given."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.collections import LineCollection

    cut = plane_cut(grid, point, normal)
    axes_in_plane = [a for a in np.argsort(np.abs(np.asarray(normal, dtype=float)))[:2]]
    axes_in_plane.sort()
    names = "xyz"
    segments = np.stack([cut["start"][:, axes_in_plane], cut["end"][:, axes_in_plane]], axis=1)
    figure, axes = plt.subplots(1, len(views), figsize=(6.0 * len(views), 5.0), squeeze=False)
    for axis, (view_title, (low, high)) in zip(axes.flat, views):
        lines = LineCollection(segments, linewidths=0.35, colors="#1f3b5a" if values is None else None)
        if values is not None:
            lines.set_array(np.asarray(values, dtype=float)[cut["cell"]])
            lines.set_cmap("viridis")
        axis.add_collection(lines)
        axis.set_xlim(low[0], high[0])
        axis.set_ylim(low[1], high[1])
        axis.set_aspect("equal")
        axis.set_title(view_title, fontsize=10)
        axis.set_xlabel(names[axes_in_plane[0]])
        axis.set_ylabel(names[axes_in_plane[1]])
        if values is not None:
            figure.colorbar(lines, ax=axis, shrink=0.8, label=value_label or "")
    if title:
        figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(path, dpi=130)
    plt.close(figure)
    return path

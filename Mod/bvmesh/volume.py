"""The volume stage, headless: from a fitted wall to the block-structured B-spline volume mesh.

    import bvmesh.volume
    mesh = bvmesh.volume.offset_and_farfield(fitter, reference_length=805.0)
    mesh.blocks.evaluate_grid(0, u, v, w)        # the mesh function of one block
    refined = bvmesh.volume.subdivide(mesh, steps=2)  # volumetric Catmull-Clark of its control mesh

Works in plain /usr/bin/python3 and in freecadcmd; the geometry is all in the compiled core.
"""

from . import load_core, memory
from .options import check_options

# The level of a wing's wall its layers are marched from when the fit is finer (then carried onto
# the fit's own wall; offset_and_farfield's marching_wall): marched from the M6's level-3 wall the
# boundary layer folds at the corner where the trailing edge meets the tip (the charts' corners
# there are degenerate; docs/volume.md).
WING_MARCHING_LEVEL = 2

# The automatic marching level starts at the highest level whose control mesh has at most this many
# points. The hyperbolic far field's pseudo-steps are as long as the front's short edges, at most 64
# per layer: on a finer front its steps are many edges long and most take a direct solve (a waisted
# body of revolution, fuselage template: 3 586 / 5 922 / 8 834 / 14 338 points marched in 1.4 / 13.7
# / 142 / 245 s); one level down took 0.5-2.7 s with cells as good or better. The M6's level 2 has
# 2 837 points, its level 3 11 257 (docs/volume.md, "Layers marched from a coarser level").
MARCHING_POINT_LIMIT = 4000

# Peak memory per layer point (a marched front point in one layer) of the marching and its blocks
# (about 220 bytes on the sphere's level-4 wall: 27 layers of 1 946 points), with room to spare:
# offset_and_farfield and control_volume march no more layers times points than the free memory
# holds (max_layer_points; 0 for no limit).
BYTES_PER_LAYER_POINT = 512


def marching_levels(level, points_per_level, point_limit=MARCHING_POINT_LIMIT, limit_name="marching_point_limit"):
    """The levels a wall at `level` is marched from, in the order they are tried: the highest up to
    `level` whose control mesh has at most point_limit points (points_per_level: {level: points};
    0: `level` itself), then, where the marching folds, each lower one down to 1."""
    if isinstance(point_limit, bool) or not isinstance(point_limit, int) or point_limit < 0:
        raise ValueError("{} {!r} must be 0 (no limit) or more".format(limit_name, point_limit))
    levels = list(range(level, 0, -1)) or [level]
    if point_limit > 0:
        small = [lv for lv in levels if points_per_level.get(lv, 0) <= point_limit]
        levels = levels[levels.index(small[0]):] if small else levels[-1:]
    return levels


def march_from_first_level_that_holds(levels, march, finer=()):
    """(march(level), level) for the first of `levels` whose marching does not fold (a SolverError
    "marching folds ..."), then of `finer` in ascending order: where every level down folds, a finer
    wall may hold (the full M6 wing, twice a half wing's points, starts a level below the half
    one, and its level 1 folds at the trailing edge); a SolverError listing every level's failure
    when all fail. A level whose layers cannot be carried onto the wall (an InvalidInputError
    "... march a finer wall": the wall lies too far from that level's, as next to a pointed nose's
    apex) gives way to the levels of `finer` above it at once, the lower ones lying farther still."""
    from . import InvalidInputError, SolverError

    failures = []
    finer = sorted(finer)
    queue = list(levels) + [lv for lv in finer if lv > max(levels)]
    while queue:
        level = queue.pop(0)
        try:
            return march(level), level
        except SolverError as error:
            if not str(error).startswith("marching folds"):
                raise
            failures.append((level, error))
        except InvalidInputError as error:
            higher = [lv for lv in finer if lv > level]
            if "march a finer wall" not in str(error) or not higher:
                if not failures:
                    raise
                failures.append((level, error))
                break
            failures.append((level, error))
            queue = higher
    if len(failures) == 1:
        raise failures[0][1]
    folded = all(isinstance(error, SolverError) for _, error in failures)
    raise SolverError("the marching {} from every level tried; ".format("folds" if folded else "fails") +
                      "; ".join("from level {}: {}".format(level, error) for level, error in failures))


def offset_and_farfield(fit_or_mesh, symmetry_plane=None, marching_wall=None, marching_level=None,
                        marching_point_limit=None, **options):
    """The volume mesh around a fitted wall: boundary-layer control layers along the wall normals,
    the far field marched out to a sphere (half sphere on the symmetry plane), one tricubic
    B-spline block per wall patch.

    fit_or_mesh: a bvmesh.SurfaceFitter (its current control mesh and its symmetry plane are used)
    or an all-quad bvmesh.ControlMesh. symmetry_plane: (point, normal) of a half model; taken from
    the fitter when not given. outflow_plane (an option): (point, normal) of the outflow boundary a
    body runs into (a sting, as the hemisphere-cylinder's): the wall's open boundary off the
    symmetry plane lies on it, the grid lines there run in it, the blocks' faces in it are 'outlet';
    the domain is then the sphere around a centre on it (domain_centre, or the wall's centre moved
    onto it), cut by it. marching_wall: the same fit stopped at a lower level (a SurfaceFitter
    or its ControlMesh): the layers are marched from it and carried onto the wall, whose charts stay
    the blocks' wall faces (a fine wall whose own marching folds keeps its accuracy).
    marching_level: for a SurfaceFitter, the level below its own whose mesh (fitter.mesh_at_level)
    is the marching wall, or -1: the highest level whose mesh has at most marching_point_limit
    points (default MARCHING_POINT_LIMIT; 0: the fit's own) and, where that folds, each lower one in turn (marching_levels), then
    the finer ones up to the fit's own (march_from_first_level_that_holds), as the workbench's MarchingLevel -1 does; a wall of more than a few thousand points marches its
    hyperbolic far field in minutes, from a level down in seconds (docs/volume.md). options: those
    of bvmesh.generate_volume_mesh (reference_length, reynolds_number, boundary_layer_thickness,
    boundary_layer_layers, boundary_layer_growth, sharp_edge_splay, farfield_distance,
    farfield_growth, farfield_scheme ('hyperbolic', the default, or 'smoothed'), smoothing,
    min_scaled_jacobian, max_layers, knife_edge_fans: a sharp trailing edge cut open with a fan of
    prisms round it, off by default; max_layer_points, default from the free memory).
    Returns a bvmesh.VolumeMesh; raises ValueError (bvmesh.InvalidInputError) for a bad wall or
    option and bvmesh.SolverError when the marching would fold, naming where.
    """
    automatic = marching_level == -1 and not isinstance(marching_level, bool)
    if marching_point_limit is not None and not automatic:
        raise ValueError("marching_point_limit applies to marching_level=-1 only (the automatic choice of the "
                         "marching wall's level), got marching_level={!r}".format(marching_level))
    if automatic:
        if marching_point_limit is None:
            marching_point_limit = MARCHING_POINT_LIMIT
        fitter = _fitter_for_levels(fit_or_mesh, marching_wall)
        points = {record["level"]: record["control_points"] for record in fitter.history}
        levels = marching_levels(fitter.level, points, marching_point_limit)

        def march(level):
            lower = None if level == fitter.level else fitter.mesh_at_level(level)
            return offset_and_farfield(fitter, symmetry_plane, marching_wall=lower, **options)

        return march_from_first_level_that_holds(levels, march, range(levels[0] + 1, fitter.level + 1))[0]
    wall, symmetry_plane = _wall_of(fit_or_mesh, symmetry_plane, "offset_and_farfield")
    if marching_level is not None:
        marching_wall = _lower_level_of(fit_or_mesh, marching_level, marching_wall)
    if marching_wall is not None:
        marching_wall, _ = _wall_of(marching_wall, symmetry_plane, "offset_and_farfield's marching_wall")
    core = load_core()
    check_options(core.generate_volume_mesh, "offset_and_farfield", options)
    options.setdefault("max_layer_points", memory.budget(BYTES_PER_LAYER_POINT))
    return core.generate_volume_mesh(wall, symmetry_plane=symmetry_plane, marching_wall=marching_wall, **options)


def control_volume(fit_or_mesh, symmetry_plane=None, **options):
    """The volume control mesh marched from the fitted wall's own Catmull-Clark control mesh: the
    fit's control faces (with their creases and corners) are the wall faces, the control vertices
    march along their mean limit normals with the options and rules of offset_and_farfield.

    Its wall refines under bvmesh.volume.subdivide exactly as the surface fit refines, so
    fit_on_volume continues the fit from it at the next level (the B-spline blocks' control nets
    are the charts' clamped nets, about 1 % off the fit), and bvmesh.grid.refine(volume,
    method="subdivision", steps=k) makes a grid of it whose wall lies on the fitted surface.
    fit_or_mesh, symmetry_plane and options as for offset_and_farfield. Returns a
    bvmesh.ControlVolume (.hex_mesh(), .block_count, .cell_count, .layer_distance, ...).
    """
    wall, symmetry_plane = _wall_of(fit_or_mesh, symmetry_plane, "control_volume")
    core = load_core()
    check_options(core.control_volume_mesh, "control_volume", options)
    options.setdefault("max_layer_points", memory.budget(BYTES_PER_LAYER_POINT))
    return core.control_volume_mesh(wall, symmetry_plane=symmetry_plane, **options)


def _fitter_for_levels(fit_or_mesh, marching_wall):
    """fit_or_mesh, a SurfaceFitter whose lower levels marching_level takes (without marching_wall)."""
    if marching_wall is not None:
        raise ValueError("offset_and_farfield takes marching_wall or marching_level, not both")
    if not isinstance(fit_or_mesh, load_core().SurfaceFitter):
        raise TypeError("marching_level needs a bvmesh.SurfaceFitter (its lower levels' meshes), got {}".format(
            type(fit_or_mesh).__name__))
    return fit_or_mesh


def _lower_level_of(fit_or_mesh, marching_level, marching_wall):
    """The mesh of a SurfaceFitter at marching_level, below its own level."""
    fitter = _fitter_for_levels(fit_or_mesh, marching_wall)
    if isinstance(marching_level, bool) or not isinstance(marching_level, int) or \
            not 0 <= marching_level < fitter.level:
        raise ValueError("marching_level must be a level below the fit's level {} and 0 or more (or -1: "
                         "automatic), got {!r}".format(fitter.level, marching_level))
    return fitter.mesh_at_level(marching_level)


def _wall_of(fit_or_mesh, symmetry_plane, caller):
    core = load_core()
    if isinstance(fit_or_mesh, core.SurfaceFitter):
        if symmetry_plane is None:
            symmetry_plane = fit_or_mesh.options.get("symmetry_plane")
        return fit_or_mesh.mesh, symmetry_plane
    if isinstance(fit_or_mesh, core.ControlMesh):
        return fit_or_mesh, symmetry_plane
    raise TypeError("{} takes a bvmesh.SurfaceFitter or a bvmesh.ControlMesh, got {}".format(
        caller, type(fit_or_mesh).__name__))


HEX_MESH_KEYS = ("points", "cells", "boundary_faces", "boundary_conditions", "creases", "corners")


def _hex_mesh_of(mesh, caller):
    core = load_core()
    if isinstance(mesh, core.VolumeMesh):
        mesh = mesh.blocks
    if isinstance(mesh, core.BlockMesh):
        mesh = core.hex_mesh_of_blocks(mesh)
    if isinstance(mesh, core.ControlVolume):
        mesh = mesh.hex_mesh()
    if not isinstance(mesh, dict):
        raise TypeError("{} takes a VolumeMesh, a BlockMesh, a ControlVolume or a hex mesh dict, got {}".format(
            caller, type(mesh).__name__))
    missing = [key for key in HEX_MESH_KEYS[:4] if key not in mesh]
    if missing:
        raise ValueError("the hex mesh has no {}".format(", ".join(missing)))
    return mesh


def subdivide(mesh, steps=1):
    """`steps` volumetric Catmull-Clark steps of a hexahedral mesh (docs/volume.md).

    mesh: a VolumeMesh or BlockMesh (its control mesh, cells made right-handed), a ControlVolume
    (control_volume's result: the wall's creases and corners kept), or a dict with
    'points' (#P, 3), 'cells' (#C, 8; right-handed, corners 000 100 110 010 001 101 111 011),
    'boundary_faces' (#B, 4) with 'boundary_conditions' (#B names), and optionally 'creases'
    (#K, 2 point pairs on the boundary) and 'corners' (point ids). Returns a dict of the same keys
    for the refined mesh, plus 'operator': the scipy.sparse.csr_matrix S with
    points' = S @ points (the product of the steps' operators). Raises ValueError naming the cell,
    face or crease for a mesh it cannot refine, and for more points than the free memory holds."""
    core = load_core()
    mesh = _hex_mesh_of(mesh, "subdivide")
    if not isinstance(steps, int) or isinstance(steps, bool) or steps < 1:
        raise ValueError("steps must be an int >= 1, got {!r}".format(steps))
    from .grid import point_budget

    points, budget = len(mesh["points"]) * 8.0 ** steps, point_budget()
    if budget and points > budget:
        raise ValueError("{} subdivision steps would make about {:.3g} points, more than the free memory holds "
                         "(bvmesh.grid.point_budget(): {})".format(steps, points, budget))
    operator = None
    for _ in range(steps):
        mesh = core.subdivide_hex_mesh(*(mesh.get(key) for key in HEX_MESH_KEYS))
        operator = mesh["operator"] if operator is None else mesh["operator"] @ operator
    mesh["operator"] = operator
    return mesh


def fit_on_volume(mesh, target, passes=3, **options):
    """Fitting that goes on after the volume exists (docs/volume.md): one volumetric Catmull-Clark
    step, `passes` passes of limit samples, projection onto `target` and least squares on the wall
    faces, the interior points following the wall harmonically (the rest of the boundary held).

    mesh: as subdivide takes it. target: a bvmesh.Target. options: those of bvmesh.SurfaceFitter
    (symmetry_plane, tolerance, weights, solver, ...). Returns subdivide's dict for one step with
    the fitted points, plus 'wall' (the last pass's record: max_distance, rms_distance, ...) and
    'min_scaled_jacobian'. Raises bvmesh.SolverError naming the cell when one turns over."""
    return load_core().subdivide_and_fit_volume(_hex_mesh_of(mesh, "fit_on_volume"), target, passes, **options)


def write_hex_vtk(mesh, path):
    """A hex mesh dict (subdivide's result) as a legacy VTK unstructured grid (ASCII): its cells
    as VTK_HEXAHEDRON (same corner order) with cell data 'cell' numbering them. For meshes that are not block-structured; a block mesh's
    refinement is a grid (bvmesh.grid.refine(..., method='subdivision')) with its own writers."""
    import numpy as np

    points = np.asarray(mesh["points"], dtype=float)
    cells = np.asarray(mesh["cells"], dtype=np.int64)
    with open(path, "w") as file:
        file.write("# vtk DataFile Version 3.0\nbvmesh hex mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n")
        file.write("POINTS {} double\n".format(len(points)))
        np.savetxt(file, points, fmt="%.17g")
        file.write("CELLS {} {}\n".format(len(cells), 9 * len(cells)))
        np.savetxt(file, np.hstack([np.full((len(cells), 1), 8), cells]), fmt="%d")
        file.write("CELL_TYPES {}\n".format(len(cells)))
        np.savetxt(file, np.full(len(cells), 12), fmt="%d")
        file.write("CELL_DATA {}\nSCALARS cell int 1\nLOOKUP_TABLE default\n".format(len(cells)))
        np.savetxt(file, np.arange(len(cells)), fmt="%d")
    return path

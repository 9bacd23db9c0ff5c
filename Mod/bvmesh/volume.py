"""The volume stage, headless: from a fitted wall to the block-structured B-spline volume mesh.

    import bvmesh.volume
    mesh = bvmesh.volume.offset_and_farfield(fitter, reference_length=805.0)
    mesh.blocks.evaluate_grid(0, u, v, w)        # the mesh function of one block

Works in plain /usr/bin/python3 and in freecadcmd; the geometry is all in the compiled core.
"""

from . import load_core


def offset_and_farfield(fit_or_mesh, symmetry_plane=None, **options):
    """The volume mesh around a fitted wall: boundary-layer control layers along the wall normals,
    the far field marched out to a sphere (half sphere on the symmetry plane), one tricubic
    B-spline block per wall patch.

    fit_or_mesh: a bvmesh.SurfaceFitter (its current control mesh and its symmetry plane are used)
    or an all-quad bvmesh.ControlMesh. symmetry_plane: (point, normal) of a half model; taken from
    the fitter when not given. options: those of bvmesh.generate_volume_mesh (reference_length,
    reynolds_number, boundary_layer_thickness, boundary_layer_layers, boundary_layer_growth, sharp_edge_splay,
    farfield_distance, farfield_growth, smoothing, min_scaled_jacobian, max_layers).
    Returns a bvmesh.VolumeMesh; raises ValueError (bvmesh.InvalidInputError) for a bad wall or
    option and bvmesh.SolverError when the marching would fold, naming where.
    """
    core = load_core()
    if isinstance(fit_or_mesh, core.SurfaceFitter):
        if symmetry_plane is None:
            symmetry_plane = fit_or_mesh.options.get("symmetry_plane")
        wall = fit_or_mesh.mesh
    elif isinstance(fit_or_mesh, core.ControlMesh):
        wall = fit_or_mesh
    else:
        raise TypeError("offset_and_farfield takes a bvmesh.SurfaceFitter or a bvmesh.ControlMesh, got {}".format(
            type(fit_or_mesh).__name__))
    return core.generate_volume_mesh(wall, symmetry_plane=symmetry_plane, **options)

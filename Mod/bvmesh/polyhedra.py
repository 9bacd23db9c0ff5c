"""Initial polyhedra, headless: the template library (resources/templates, format in
docs/templates.md), automatic placement of a template on a target, the target's feature curves,
the mapping of a polyhedron's creases, boundaries and corners onto them, and the improvement of a
polyhedron before fitting. Works in plain /usr/bin/python3 and in FreeCAD; no document objects.

``place`` returns a dict: ``mesh`` (bvmesh.ControlMesh), ``feature_map`` (curves, edge_curve,
vertex_cad_vertex: bvmesh.SurfaceFitter's ``features``), ``symmetry_plane`` ((point, normal) or
None: SurfaceFitter's ``symmetry_plane`` option), ``planform`` (wings), ``parameters`` (the
values used, ``auto`` choices resolved; wings also report ``trailing_edge``: ``sharp`` or
``blunt``, as found on the target), ``curves`` (the target's feature curves) and the mapping
report (``chains``, ``corners``, ``unmapped_chains``, ``unmapped_corners``, ``complete``,
``report``).
"""

import os

from bvmesh import load_core
from bvmesh.paths import RESOURCES_DIR

TEMPLATES_DIR = os.path.join(RESOURCES_DIR, "templates")


class UnmappedFeatureError(load_core().InvalidInputError):
    """A crease chain, boundary chain or corner of a polyhedron maps to no CAD feature. ``mapping``
    holds the full mapping report (see map_creases)."""

    def __init__(self, message, mapping):
        super().__init__(message)
        self.mapping = mapping


def list_templates(folder=None):
    """The templates of the library (or of `folder`) as dicts: name, description, generator,
    parameters (name, default, description, kind, minimum/maximum or choices), source."""
    return load_core().read_template_library(os.fspath(folder or TEMPLATES_DIR))


def template_names(folder=None):
    return [t["name"] for t in list_templates(folder)]


def _template_path(name_or_path, folder=None):
    if os.path.isfile(os.fspath(name_or_path)):
        return os.fspath(name_or_path)
    for t in list_templates(folder):
        if t["name"] == name_or_path:
            return t["source"]
    raise load_core().InvalidInputError(
        "no template named '{}' (the library has {})".format(name_or_path, ", ".join(template_names(folder)))
    )


def _check_mapping(mapping, strict, what):
    if strict and not mapping["complete"]:
        raise UnmappedFeatureError("{}: unmapped features\n{}".format(what, mapping["report"]), mapping)
    return mapping


def place(template, target, parameters=None, improve=True, strict=True, folder=None, kinks=True):
    """Builds `template` (a library name or a .template path) on `target` (bvmesh.Target) and
    returns the placed polyhedron dict (see the module docstring). Parameter values may be given
    as numbers or strings. With strict=True an unmapped crease, boundary or corner raises
    UnmappedFeatureError naming it and its distance to the nearest candidate. kinks=False leaves
    the target's kinks (edges a smooth surface cannot round within the fit's default tolerance,
    docs/templates.md) out of the feature curves, and so out of the placement."""
    values = {str(k): str(v) for k, v in (parameters or {}).items()}
    placed = load_core().place_template(_template_path(template, folder), target, values, bool(improve), bool(kinks))
    return _check_mapping(placed, strict, "template '{}'".format(placed["template"]))


def place_template(target, name, **parameters):
    """(mesh, feature_map) of library template `name` placed on `target` (place's dict has the rest).
    Unmapped features raise UnmappedFeatureError; the symmetry plane of a half model is
    symmetry_plane(target)."""
    placed = place(name, target, parameters)
    return placed["mesh"], placed["feature_map"]


def symmetry_plane(target):
    """(point, normal) of the target's symmetry plane (a half model's flat free boundary with the
    whole target on one side; normal towards the target), or None."""
    return load_core().symmetry_plane(target)


def detect_feature_curves(target, sharp_angle_deg=30.0, continuity_angle_deg=30.0):
    """The target's sharp curves (dihedral angle >= sharp_angle_deg) and free-boundary curves, as
    dicts: kind, edges (chain order), reversed, start_vertex, end_vertex, length, closed."""
    return load_core().feature_curves(target, float(sharp_angle_deg), float(continuity_angle_deg))


def map_creases(mesh, target, strict=False, sharp_angle_deg=30.0, continuity_angle_deg=30.0,
                relative_max_distance=0.05, max_angle_deg=30.0, relative_corner_distance=0.05):
    """Maps the crease chains, boundary chains and corners of `mesh` onto the target's feature
    curves and vertices. Returns the mapping dict (feature_map, chains, corners, unmapped_*,
    complete, report, curves); with strict=True raises UnmappedFeatureError when incomplete."""
    mapping = load_core().map_features(
        mesh, target, float(sharp_angle_deg), float(continuity_angle_deg), float(relative_max_distance),
        float(max_angle_deg), float(relative_corner_distance),
    )
    return _check_mapping(mapping, strict, "polyhedron")


def improve_polyhedron(mesh, target, feature_map=None, relaxation_passes=3, relaxation=0.5,
                       push_out_passes=3, symmetry_plane=None):
    """A copy of `mesh` moved onto / around the target: tangential relaxation with projection by
    vertex role (creases onto their curves, corners onto their CAD vertices), limit push-out, and
    boundary vertices snapped to `symmetry_plane` ((point, normal))."""
    return load_core().improve_polyhedron(
        mesh, target, feature_map, int(relaxation_passes), float(relaxation), int(push_out_passes), symmetry_plane
    )


def half_model_target(shape_or_brep, **target_options):
    """For a half model whose symmetry plane is closed by a planar face (e.g. a wing root face):
    (Target of the other faces, the removed face's index, the plane (point, normal)). Accepts a
    Part.Shape or BREP text."""
    brep = shape_or_brep if isinstance(shape_or_brep, str) else shape_or_brep.exportBrepToString()
    core = load_core()
    rest, face, plane = core.remove_symmetry_face(brep)
    return core.Target.from_brep(rest, **target_options), face, plane


def faces_target(shape_or_brep, faces, **target_options):
    """Target of some faces of a shape (0-based, FreeCAD's Face<i+1>), e.g. a body inside a domain."""
    brep = shape_or_brep if isinstance(shape_or_brep, str) else shape_or_brep.exportBrepToString()
    core = load_core()
    return core.Target.from_brep(core.select_faces(brep, [int(f) for f in faces]), **target_options)


def flow_domain(shape_or_brep, **target_options):
    """A flow domain's CAD (a box or sphere, or its half on a symmetry plane, with the body cut out,
    as CFD pre-processors write it) split with no face selection: a face bounds the domain when the
    whole shape lies on one side of its tangent plane everywhere on it, the others are the body's.
    Returns a dict: 'target' (Target of the body's faces), 'body_faces' and 'outer_faces' (0-based,
    FreeCAD's Face<i+1>), 'shape' ('sphere' or 'box'), 'symmetry_face', 'symmetry_plane'
    ((point, normal towards the domain) or None), 'outflow_face', 'outflow_plane' (of a sphere
    domain's plane that the body runs into, a sting, or None), and 'volume_options': the domain as
    bvmesh.volume.offset_and_farfield takes it (domain, domain_centre, farfield_distance or
    box_half_extent, outflow_plane). Raises ValueError naming what is not a flow domain."""
    brep = shape_or_brep if isinstance(shape_or_brep, str) else shape_or_brep.exportBrepToString()
    core = load_core()
    split = core.split_flow_domain(brep)
    split["target"] = core.Target.from_brep(core.select_faces(brep, split["body_faces"]), **target_options)
    split["volume_options"] = domain_volume_options(split["shape"], split["centre"], domain_size(split),
                                                    split["outflow_plane"])
    return split


def domain_size(split):
    """A split flow domain's size as three numbers: a box's half sizes, a sphere's radius thrice."""
    return [split["radius"]] * 3 if split["shape"] == "sphere" else list(split["half_extent"])


def domain_volume_options(shape, centre, size, outflow_plane=None):
    """bvmesh.volume.offset_and_farfield's keywords for a flow domain: 'sphere' of radius size[0]
    or 'box' of half sizes `size`, around `centre`; with the outflow plane (point, normal) that the
    body runs into, if any."""
    options = {"domain": shape, "domain_centre": tuple(centre)}
    if shape == "sphere":
        options["farfield_distance"] = size[0]
    else:
        options["box_half_extent"] = tuple(size)
    if outflow_plane is not None:
        options["outflow_plane"] = (tuple(outflow_plane[0]), tuple(outflow_plane[1]))
    return options


def plot_polyhedron(mesh, path, target=None, title=None, views=((25, -60), (90, -90), (0, -90)), min_aspect=0.2,
                    region=None):
    """Writes a PNG of the polyhedron (edges blue, creases red, corners black) over the target's
    tessellation (grey), offscreen with matplotlib, from the given (elevation, azimuth) views.
    Directions thinner than min_aspect of the largest extent are drawn stretched. region: an
    optional box (low corner, high corner) to close in on; only what touches it is drawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    vertices = np.asarray(mesh.vertices)
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    if target is not None:
        nodes = np.asarray(target.mesh_nodes)
        low, high = np.minimum(low, nodes.min(axis=0)), np.maximum(high, nodes.max(axis=0))
    if region is not None:
        low, high = (np.asarray(corner, dtype=float) for corner in region)

    def touching(points, elements):
        """The elements (index rows into points) with a point inside the shown box."""
        elements = np.asarray(elements, dtype=int)
        if region is None or elements.size == 0:
            return elements
        inside = np.all((points >= low) & (points <= high), axis=1)
        return elements[inside[elements].any(axis=1)]
    # Thin directions (a wing's thickness) are stretched to at least `min_aspect` of the largest
    # extent, so that sections stay visible.
    extent = np.maximum(high - low, min_aspect * (high - low).max())
    centre = (low + high) / 2
    figure = plt.figure(figsize=(6 * len(views), 6))
    for k, (elevation, azimuth) in enumerate(views):
        axes = figure.add_subplot(1, len(views), k + 1, projection="3d")
        if target is not None:
            triangles = nodes[touching(nodes, target.mesh_triangles)]
            axes.add_collection3d(Poly3DCollection(triangles, facecolor=(0.8, 0.8, 0.8, 0.25), edgecolor="none"))
        axes.add_collection3d(Line3DCollection(vertices[touching(vertices, mesh.edges)], colors="tab:blue",
                                               linewidths=0.7))
        creases = touching(vertices, mesh.creases)
        if len(creases):
            axes.add_collection3d(Line3DCollection(vertices[creases], colors="red", linewidths=2.0))
        shown = touching(vertices, np.arange(len(vertices)).reshape(-1, 1))[:, 0]
        corners = np.intersect1d(np.asarray(mesh.corners, dtype=int), shown)
        axes.scatter(*vertices[shown].T, s=3, c="tab:blue")
        if len(corners):
            axes.scatter(*vertices[corners].T, s=25, c="black")
        for set_limits, c, e in zip((axes.set_xlim, axes.set_ylim, axes.set_zlim), centre, extent):
            set_limits(c - e / 2, c + e / 2)
        axes.view_init(elevation, azimuth)
        axes.set_box_aspect(tuple(extent))
    if title:
        figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(os.fspath(path), dpi=80)
    plt.close(figure)
    return path

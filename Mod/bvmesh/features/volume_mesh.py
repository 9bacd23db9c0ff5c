"""The volume mesh: block-structured tricubic B-spline volumes around the wall of a surface fit
(boundary layer and far field by marching, bvmesh.volume.offset_and_farfield). The marching is
deterministic, so the blocks are not stored in the document: the object keeps its options, what the
marching measured and a digest of the blocks, and rebuilds the blocks from the fit when they are
asked for after loading (checking the digest). Its shape is the blocks' boundary faces."""

import hashlib

import numpy as np

from bvmesh import volume
from bvmesh.features import surface_fit
from bvmesh.features.common import READ_ONLY, RecomputedProxy, add_property, run_work, shown_conditions
from bvmesh.grid import FACE_NAMES, face_array

TYPE = "BVMesh::VolumeMesh"

# (property, option of bvmesh.volume.offset_and_farfield, type, default, description)
OPTIONS = (
    ("ReferenceLength", "reference_length", "App::PropertyFloat", 0.0,
     "Reference length L (root chord of a wing, body length), model units; 0: the root chord of a wing template's "
     "polyhedron (its RootChord), else the wall's largest extent"),
    ("ReynoldsNumber", "reynolds_number", "App::PropertyFloat", 5e6,
     "Reynolds number on L, for the default boundary-layer thickness"),
    ("BoundaryLayerThickness", "boundary_layer_thickness", "App::PropertyFloat", 0.0,
     "Total boundary-layer thickness; 0: the turbulent flat-plate estimate 0.37 L Re^-0.2"),
    ("BoundaryLayerLayers", "boundary_layer_layers", "App::PropertyInteger", 4, "Control layers in the boundary layer"),
    ("BoundaryLayerGrowth", "boundary_layer_growth", "App::PropertyFloat", 1.2,
     "Thickness ratio of successive boundary-layer control layers"),
    ("SharpEdgeSplay", "sharp_edge_splay", "App::PropertyFloat", 2.0,
     "Width of the band around sharp convex edges where grid lines fan out, in boundary-layer thicknesses"),
    ("FarfieldDistance", "farfield_distance", "App::PropertyFloat", 0.0,
     "Radius of the far-field sphere around the body's centre; 0: 20 L"),
    ("FarfieldGrowth", "farfield_growth", "App::PropertyFloat", 1.3, "Thickness ratio of successive far-field layers"),
    ("Smoothing", "smoothing", "App::PropertyFloat", 1.0, "Scale of the far field's implicit and explicit smoothing"),
    ("MinScaledJacobian", "min_scaled_jacobian", "App::PropertyFloat", 0.05,
     "Cells below this scaled Jacobian get local smoothing rounds while marching"),
    ("MaxLayers", "max_layers", "App::PropertyInteger", 400, "Control layers at most"),
)
# Switches: (property, option, default, description).
SWITCHES = (
    ("KnifeEdgeFans", "knife_edge_fans", False,
     "Cut knife edges (a sharp trailing edge) open with a fan of prisms round them: their surfaces' grid lines "
     "leave the wall along their own normals; the fan closes where the edge ends inside the wall (a wing tip)"),
)
DISPLAY = (("ShowWall", "wall", True), ("ShowSymmetry", "symmetry", True), ("ShowFarfield", "farfield", False))
# cad: the flow domain of the fit's target (Target.FlowDomain), as its CAD gives it.
DOMAINS = ["sphere", "box", "cylinder", "cad"]
# How the far field is marched (bvmesh.volume.offset_and_farfield's farfield_scheme), and the scheme of
# a new mesh (create(), the task panel; "smoothed" in documents saved before the property).
FARFIELD_SCHEMES = ["smoothed", "hyperbolic"]
NEW_MESH_FARFIELD_SCHEME = "hyperbolic"
# The domain's vector options: (property, option, default, description).
VECTORS = (
    ("FlowDirection", "flow_direction", (1.0, 0.0, 0.0),
     "Flow direction: box and cylinder faces facing it are inlets, facing away outlets, the rest sides"),
    ("BoxHalfExtent", "box_half_extent", (0.0, 0.0, 0.0),
     "Half sizes of a box domain along x, y, z (from the symmetry plane on a half model); 0: FarfieldDistance"),
)


def options(obj):
    """The marching options of a VolumeMesh object, as offset_and_farfield's keywords."""
    settings = {option: getattr(obj, prop) for prop, option, _, _, _ in OPTIONS}
    if not settings["reference_length"]:
        polyhedron = getattr(obj.Fit, "Polyhedron", None) if obj.Fit is not None else None
        settings["reference_length"] = getattr(polyhedron, "RootChord", 0.0)  # 0 in documents saved before it
    settings.update({option: bool(getattr(obj, prop)) for prop, option, _, _ in SWITCHES})
    settings["domain"] = obj.Domain
    settings["farfield_scheme"] = obj.FarfieldScheme
    for prop, option, _, _ in VECTORS:
        settings[option] = tuple(getattr(obj, prop))
    if obj.Domain == "cad":
        domain = cad_domain(obj.Fit)
        if obj.FarfieldDistance != 0.0 or any(obj.BoxHalfExtent):
            raise ValueError("Domain 'cad' takes the far field from the CAD's flow domain: leave FarfieldDistance "
                             "and BoxHalfExtent at 0, or choose sphere, box or cylinder to set them")
        settings.update(domain)
    elif outflow_plane(getattr(obj.Fit, "Target", None)) is not None:
        raise ValueError("the fit's target runs into the outflow plane of its flow domain, which only Domain 'cad' "
                         "marches in: choose Domain cad")
    return settings


def cad_domain(fit):
    """The domain options of the flow domain the fit's target was read from."""
    target = fit.Target if fit is not None else None
    if target is None or not getattr(target, "FlowDomain", ""):
        raise ValueError("Domain 'cad' needs a target on a flow domain's CAD (a box or sphere with the body cut "
                         "out, its Faces left empty): choose sphere, box or cylinder")
    from bvmesh import polyhedra

    return polyhedra.domain_volume_options(target.FlowDomain, target.DomainCentre, tuple(target.DomainSize),
                                           outflow_plane(target))


def outflow_plane(target):
    """(point, normal) of the outflow plane that a Target's flow-domain body runs into, or None."""
    normal = tuple(getattr(target, "OutflowNormal", (0.0, 0.0, 0.0)))
    return (tuple(target.OutflowPoint), normal) if any(normal) else None


def symmetry_plane(fit):
    if not fit.UseSymmetryPlane:
        return None
    point, normal = fit.SymmetryPoint, fit.SymmetryNormal
    return (point.x, point.y, point.z), (normal.x, normal.y, normal.z)


def marching_inputs(obj):
    """(function giving the wall's control mesh, symmetry plane, marching options) of a VolumeMesh
    object: what its blocks are marched from, and what a control volume of the same fit is."""
    fit = obj.Fit
    if fit is None or not fit.ControlVertices:
        raise ValueError("the volume mesh needs a computed surface fit")
    if obj.WallLevel < -1:
        raise ValueError("WallLevel {} must be 0 or more, up to the fit's level {} (or -1: the fit's own level)".format(
            obj.WallLevel, fit.Level))
    wall, _ = surface_fit.wall_at_level(fit, obj.WallLevel)
    return wall, symmetry_plane(fit), options(obj)


def wall_level(obj):
    """The subdivision level of the wall a VolumeMesh object's blocks stand on."""
    return obj.Fit.Level if obj.WallLevel < 0 else obj.WallLevel


def control_points_per_level(fit):
    """{level: control points} of a SurfaceFit object, from its convergence table."""
    return dict(zip(fit.HistoryLevel, fit.HistoryControlPoints))


def marching_levels(obj):
    """The levels a VolumeMesh object's layers may be marched from, in the order they are tried: its
    MarchingLevel alone, or for -1 (automatic) the highest level up to the wall's whose control mesh
    has at most MarchingPointLimit points (0: the wall's own level) and then, where the marching
    folds, each lower level down to 1 in turn (for a fit made by one 'Fit to tolerance' step, whose
    lower levels can be refitted; the wall's own alone otherwise)."""
    level = wall_level(obj)
    if obj.MarchingLevel == -1:
        if list(obj.Fit.Steps) != ["fit"]:
            return [level]
        return volume.marching_levels(level, control_points_per_level(obj.Fit), obj.MarchingPointLimit,
                                      "MarchingPointLimit")
    if not 0 <= obj.MarchingLevel < level:
        raise ValueError("MarchingLevel {} must be below the wall's level {} and 0 or more (or -1: the wall's own "
                         "level, or lower ones where its marching folds)".format(obj.MarchingLevel, level))
    return [obj.MarchingLevel]


def marching_wall(obj, level):
    """A function giving the control mesh a VolumeMesh object's layers are marched from at `level`
    (the fit refitted to it), or None for the wall's own level."""
    if level == wall_level(obj):
        return None
    wall, _ = surface_fit.wall_at_level(obj.Fit, level)
    return wall


def marching_wall_used(obj):
    """marching_wall at the level the object's layers were marched from (MarchingLevelUsed; the
    wall's own before it is known)."""
    used = obj.MarchingLevelUsed
    return marching_wall(obj, used) if 0 <= used < wall_level(obj) else None


def blocks_digest(blocks):
    """SHA-1 of every block's degrees, knots and poles (bit for bit)."""
    digest = hashlib.sha1()
    for b in range(blocks.block_count):
        digest.update(repr(blocks.degrees(b)).encode())
        for knots in blocks.knots(b):
            digest.update(np.asarray(knots, dtype=float).tobytes())
        digest.update(np.ascontiguousarray(blocks.poles(b)).tobytes())
    return digest.hexdigest()


def knots_and_multiplicities(full):
    knots, counts = np.unique(np.asarray(full, dtype=float), return_counts=True)
    return [float(k) for k in knots], [int(c) for c in counts]


def face_surface(blocks, block, face):
    """(poles (n_a, n_b, 3), knots a, knots b) of a block face."""
    direction = FACE_NAMES.index(face) // 2
    others = [d for d in range(3) if d != direction]
    knots = blocks.knots(block)
    return face_array(blocks.poles(block), face), knots[others[0]], knots[others[1]]


def boundary_faces_shape(blocks, conditions):
    """A compound of the block faces whose condition is in `conditions`, as B-spline faces, and
    the block of each face in compound order."""
    import Part

    from bvmesh import api

    faces, face_blocks = [], []
    for b in range(blocks.block_count):
        for name, face in blocks.faces(b).items():
            if face["condition"] not in conditions:
                continue
            poles, knots_a, knots_b = face_surface(blocks, b, name)
            ka, ma = knots_and_multiplicities(knots_a)
            kb, mb = knots_and_multiplicities(knots_b)
            faces.append(api.make_bspline_face(poles, ka, kb, ma, mb))
            face_blocks.append(b)
    return (Part.makeCompound(faces) if faces else Part.Shape()), face_blocks


class VolumeMeshProxy(RecomputedProxy):
    Type = TYPE
    what = "blocks"

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "Fit", "Inputs", "The surface fit whose wall the volume is built on")
        add_property(obj, "App::PropertyInteger", "WallLevel", "Inputs",
                     "Subdivision level of the wall: -1 the fit's own; a lower level refits the fit's target "
                     "and polyhedron to that level", -1)
        add_property(obj, "App::PropertyInteger", "MarchingLevel", "Inputs",
                     "Subdivision level the layers are marched from: -1 the wall's own (or the highest below it "
                     "within MarchingPointLimit), or where its marching folds each lower level in turn, then "
                     "the finer ones (MarchingLevelUsed says which); a lower level marches the fit refitted to it and carries the "
                     "layers onto the wall (whose charts stay the blocks' wall faces)", -1)
        # 0 (no limit, the wall's own level first) in a document saved before the property; create()
        # gives new meshes bvmesh.volume.MARCHING_POINT_LIMIT.
        add_property(obj, "App::PropertyInteger", "MarchingPointLimit", "Inputs",
                     "MarchingLevel -1 starts at the highest level whose control mesh has at most this many "
                     "points (a finer front makes the hyperbolic far field take minutes); 0: the wall's own "
                     "level", 0)
        for prop, _, type_name, default, doc in OPTIONS:
            add_property(obj, type_name, prop, "Marching", doc, default)
        for prop, _, default, doc in SWITCHES:
            add_property(obj, "App::PropertyBool", prop, "Marching", doc, default)
        # A document saved before 'cad' gains it.
        self.add_enumeration(obj, "Domain", "Marching",
                             "Outer boundary: sphere (half sphere on a symmetry plane), box or cylinder along the "
                             "flow, or cad: the flow domain the target's CAD holds", DOMAINS, "sphere")
        # "smoothed": the scheme of documents saved before the property (create() gives new meshes the default).
        self.add_enumeration(obj, "FarfieldScheme", "Marching",
                             "Far-field marching: hyperbolic, Chan & Steger's orthogonality and cell-volume "
                             "equations, or smoothed directions (2-5 times faster, poorer far-field cells)",
                             FARFIELD_SCHEMES, "smoothed")
        for prop, _, default, doc in VECTORS:
            if prop not in obj.PropertiesList:
                import FreeCAD

                add_property(obj, "App::PropertyVector", prop, "Marching", doc)
                setattr(obj, prop, FreeCAD.Vector(*default))
        for prop, condition, default in DISPLAY:
            add_property(obj, "App::PropertyBool", prop, "Display", "Show the {} faces of the blocks".format(condition),
                         default)
        r = "Result"
        for name, type_name, doc in (
            ("BlockCount", "App::PropertyInteger", "Blocks (one per wall patch)"),
            ("ControlLayers", "App::PropertyInteger", "Control layers from the wall to the far field"),
            ("WallLevelUsed", "App::PropertyInteger", "Subdivision level of the wall the blocks stand on"),
            ("ReferenceLengthUsed", "App::PropertyFloat", "Reference length used"),
            ("BoundaryLayerThicknessUsed", "App::PropertyFloat", "Boundary-layer thickness used"),
            ("FarfieldDistanceUsed", "App::PropertyFloat", "Far-field radius used"),
            ("FacesAcrossDomainEdges", "App::PropertyInteger",
             "Far-field block faces bending around an edge of a box or cylinder domain (off its faces there)"),
            ("FarfieldLayersSmoothed", "App::PropertyInteger",
             "Far-field layers the hyperbolic scheme would have folded, marched by the smoothed step"),
            ("WallMaxDistance", "App::PropertyFloat",
             "Largest distance of the blocks' wall faces from the fitted limit surface (at 9 x 9 points per "
             "control face, along the limit normal)"),
            ("LayerMinScaledJacobian", "App::PropertyFloatList", "Minimum scaled Jacobian of the control cells per layer"),
            ("FaceBlocks", "App::PropertyIntegerList", "Block of each face of the shape"),
            ("Digest", "App::PropertyString", "SHA-1 of the blocks' knots and poles"),
        ):
            add_property(obj, type_name, name, r, doc, mode=READ_ONLY)
        add_property(obj, "App::PropertyInteger", "MarchingLevelUsed", r,
                     "Subdivision level the layers were marched from (-1 in a document saved before the property: "
                     "the wall's own)", -1, mode=READ_ONLY)

    def key(self, obj):
        fit = obj.Fit
        data = repr((fit.Name, [(v.x, v.y, v.z) for v in fit.ControlVertices], list(fit.ControlFaceSizes),
                     list(fit.ControlFaceIndices), list(fit.ControlCreases), list(fit.ControlCorners),
                     symmetry_plane(fit), obj.WallLevel, obj.MarchingLevel, obj.MarchingPointLimit,
                     sorted(options(obj).items())))
        return hashlib.sha1(data.encode()).hexdigest()

    def make(self, obj):
        wall, plane, settings = marching_inputs(obj)
        levels = marching_levels(obj)
        # Finer levels for when the wall lies too far from a coarse one's to carry its layers, or
        # every level down folds.
        finer = list(range(levels[0] + 1, wall_level(obj) + 1)) if obj.MarchingLevel == -1 else []
        coarse = {level: marching_wall(obj, level) for level in levels + finer}  # read here, not in the worker

        def march_from(level):
            marching = coarse[level]
            return volume.offset_and_farfield(wall(), symmetry_plane=plane,
                                              marching_wall=None if marching is None else marching(), **settings)

        def march():
            result, self._marching_level_used = volume.march_from_first_level_that_holds(levels, march_from, finer)
            return result

        return run_work("marching the boundary layer and the far field of {}".format(obj.Label), march)

    def digest_of(self, volume_mesh):
        return blocks_digest(volume_mesh.blocks)

    def compute(self, obj):
        if obj.Fit is None:
            raise ValueError("the volume mesh needs a computed surface fit")
        volume_mesh, made = self.fresh_result(obj)
        blocks = volume_mesh.blocks
        if made:
            obj.BlockCount = blocks.block_count
            obj.ControlLayers = len(volume_mesh.layer_distance)
            obj.WallLevelUsed = wall_level(obj)
            obj.MarchingLevelUsed = self._marching_level_used
            obj.ReferenceLengthUsed = volume_mesh.reference_length
            obj.BoundaryLayerThicknessUsed = volume_mesh.boundary_layer_thickness
            obj.FarfieldDistanceUsed = volume_mesh.farfield_distance
            obj.WallMaxDistance = volume_mesh.wall_max_distance
            obj.FacesAcrossDomainEdges = volume_mesh.farfield_faces_across_domain_edges
            obj.FarfieldLayersSmoothed = volume_mesh.farfield_layers_smoothed
            obj.LayerMinScaledJacobian = [float(j) for j in volume_mesh.layer_min_scaled_jacobian]
        self._show(obj, blocks)

    def _show(self, obj, blocks):
        conditions = shown_conditions(obj, DISPLAY)
        obj.Shape, face_blocks = boundary_faces_shape(blocks, conditions)
        obj.FaceBlocks = face_blocks


def volume_mesh(obj):
    """The bvmesh.VolumeMesh of a VolumeMesh object."""
    return obj.Proxy.result(obj)


def create(doc, name="VolumeMesh"):
    obj = doc.addObject("Part::FeaturePython", name)
    VolumeMeshProxy(obj)
    obj.FarfieldScheme = NEW_MESH_FARFIELD_SCHEME
    obj.MarchingPointLimit = volume.MARCHING_POINT_LIMIT
    return obj

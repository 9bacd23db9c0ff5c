"""The volume grid: a volume mesh's B-spline blocks evaluated on a stretched, point-matched grid
(bvmesh.grid.refine), the grid a flow solver reads; or (Method subdivision) the control volume of
the same fit and options refined by volumetric Catmull-Clark, its wall on the fitted surface. Like
the volume mesh, the points are not stored in the document (a million-cell grid is tens of
megabytes): they are evaluated again when asked for after loading, and must match the saved
digest. Its shape is the grid lines on the shown boundary faces."""

import hashlib

import numpy as np

from bvmesh.features import volume_mesh as volume_mesh_feature
from bvmesh.features.common import READ_ONLY, RecomputedProxy, add_property, run_work, shown_conditions
from bvmesh.grid import face_array

TYPE = "BVMesh::VolumeGrid"
PRESETS = ["euler", "rans"]
METHODS = ["bspline", "subdivision"]
DISTRIBUTIONS = ["geometric", "tanh"]

# (property, option of bvmesh.grid.refine, type, default, description); a value of -1 (counts, the
# spacing jump) or 0 (sizes) leaves the option to the preset.
OPTIONS = (
    ("NormalPoints", "normal_points", "App::PropertyInteger", -1,
     "Points on the wall-normal lines; -1: the preset's (euler 49, rans: as many as the growth needs)"),
    ("FirstCellHeight", "first_cell_height", "App::PropertyFloat", 0.0,
     "First cell height at the wall (model units); 0: from YPlus, or none for euler"),
    ("YPlus", "y_plus", "App::PropertyFloat", 0.0, "y+ of the first cell; 0: the preset's (rans 1)"),
    ("ReynoldsNumber", "reynolds_number", "App::PropertyFloat", 0.0,
     "Reynolds number on the reference length; 0: the volume mesh's"),
    ("Growth", "growth", "App::PropertyFloat", 0.0, "Largest growth ratio of wall-normal spacings; 0: the preset's"),
    ("EdgePoints", "edge_points", "App::PropertyInteger", 17, "Points on every tangential block edge"),
    ("TangentialSpacing", "tangential_spacing", "App::PropertyFloat", 0.0,
     "Tangential spacing instead of EdgePoints (model units); 0: EdgePoints"),
    ("TargetCells", "target_cells", "App::PropertyInteger", 0,
     "About this many cells (sets the tangential spacing); 0: EdgePoints"),
    ("EdgeEndSpacing", "edge_end_spacing", "App::PropertyFloat", 0.0,
     "Spacing at the ends of tangential block edges (leading and trailing edge, tip); 0: uniform"),
    ("MaxTurningAngle", "max_turning_angle", "App::PropertyFloat", 0.0,
     "Largest turning of the wall per tangential cell in degrees, points gathered where the wall bends "
     "(a wing's nose); 0: none"),
    ("MaxSpacingJump", "max_spacing_jump", "App::PropertyFloat", -1.0,
     "Largest ratio of tangential spacings across a block corner: lines continued by much finer ones "
     "are clustered at that end (a wing's span at its tip cap); -1: the preset's (euler 3, rans 4); 0: none"),
)
# Switches: (property, option, default, description).
SWITCHES = (
    ("EvenFarField", "even_far_field", True,
     "Far-field lines slide towards points uniform in arc length on the outer boundary, so its cells do not "
     "inherit the wall's clustering and the tip's fan-out (not where that would fold a cell)"),
)
# Options added after documents were saved with grids: a restored object without one takes this
# value, which gives the grid it was saved with (its digest).
RESTORED_WITHOUT = {"MaxSpacingJump": 0.0, "EvenFarField": False}
# Refinement by subdivision (Method subdivision): (property, option, type, default, description).
SUBDIVISION_OPTIONS = (
    ("SubdivisionSteps", "steps", "App::PropertyInteger", 1,
     "Method subdivision: volumetric Catmull-Clark steps of the control volume (8 times the cells each)"),
)
# Feature lines: edges of any shape (a wing's leading edge in its CAD) along which the tangential
# lines leaving them start at FeatureSpacing (bvmesh.grid.refine's feature_spacings).
FEATURE_PROPERTIES = (
    ("FeatureEdges", "App::PropertyLinkSubList",
     "Edges (of the CAD or any shape) where the tangential lines leaving them start at FeatureSpacing: "
     "a wing's leading edge"),
    ("FeatureSpacing", "App::PropertyFloat", "Tangential spacing at the FeatureEdges (model units); 0: none"),
)
DISPLAY = (("ShowWall", "wall", True), ("ShowSymmetry", "symmetry", True), ("ShowFarfield", "farfield", False))


def refine_options(obj):
    """bvmesh.grid.refine's keywords from the object's properties (unset ones left to the preset)."""
    settings = {"distribution": obj.Distribution}
    for prop, option, type_name, default, _ in OPTIONS:
        value = getattr(obj, prop)
        if default < 0 and value < 0:
            if value != -1:
                raise ValueError("{} is -1 (the preset's) or not negative, got {:g}".format(prop, value))
            continue
        if type_name == "App::PropertyFloat" and value == 0.0 and option in ("y_plus", "growth", "reynolds_number"):
            continue
        settings[option] = value
    settings.update({option: bool(getattr(obj, prop)) for prop, option, _, _ in SWITCHES})
    if "reynolds_number" not in settings:
        settings["reynolds_number"] = obj.VolumeMesh.ReynoldsNumber
    if obj.FeatureSpacing != 0.0 or obj.FeatureEdges:
        settings["feature_spacings"] = [{"points": points, "spacing": obj.FeatureSpacing}
                                        for points in feature_lines(obj.FeatureEdges)]
    return settings


def feature_lines(links):
    """The edges of a PropertyLinkSubList value as polylines (lists of (x, y, z)), each within
    1e-6 of its length of the edge."""
    if not links:
        raise ValueError("FeatureSpacing needs FeatureEdges: the edges it applies to")
    lines = []
    for shape_object, names in links:
        for name in (names if isinstance(names, (list, tuple)) else [names]):
            if not name.startswith("Edge"):
                raise ValueError("feature edge {}.{} is not an edge".format(shape_object.Label, name))
            edge = shape_object.Shape.getElement(name)
            points = edge.discretize(Deflection=1e-6 * max(edge.Length, 1e-300))
            lines.append([(p.x, p.y, p.z) for p in points])
    return lines


def grid_digest(grid):
    digest = hashlib.sha1()
    for b in range(grid.block_count):
        digest.update(repr(grid.size(b)).encode())
        digest.update(np.ascontiguousarray(grid.points(b)).tobytes())
    return digest.hexdigest()


def boundary_lines_shape(grid, conditions):
    """A compound of the grid lines on the block faces whose condition is in `conditions`."""
    import FreeCAD
    import Part

    wires = []
    for b in range(grid.block_count):
        points = grid.points(b)
        for name, face in grid.faces(b).items():
            if face["condition"] not in conditions:
                continue
            sheet = face_array(points, name)
            for line in list(sheet) + list(np.swapaxes(sheet, 0, 1)):
                wires.append(Part.makePolygon([FreeCAD.Vector(*map(float, p)) for p in line]))
    return Part.makeCompound(wires) if wires else Part.Shape()


class VolumeGridProxy(RecomputedProxy):
    Type = TYPE
    what = "grid"

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "VolumeMesh", "Inputs", "The volume mesh whose blocks are evaluated")
        self.add_enumeration(obj, "Preset", "Refinement",
                             "euler: no wall clustering; rans: first cell for y+ ~ 1 (flat-plate estimate)",
                             PRESETS, "euler")
        self.add_enumeration(obj, "Method", "Refinement",
                             "bspline: the blocks evaluated with the wall law; subdivision: volumetric "
                             "Catmull-Clark of the fit's control mesh marched (wall on the fitted surface, "
                             "no wall clustering)", METHODS, "bspline")
        for prop, _, type_name, default, doc in SUBDIVISION_OPTIONS:
            add_property(obj, type_name, prop, "Refinement", doc, default)
        self.add_enumeration(obj, "Distribution", "Refinement", "Wall-normal point distribution", DISTRIBUTIONS,
                             "geometric")
        restored = "Digest" in obj.PropertiesList  # an object of a saved document, or a new one
        for prop, _, type_name, default, doc in OPTIONS:
            add_property(obj, type_name, prop, "Refinement", doc, RESTORED_WITHOUT.get(prop, default) if restored else default)
        for prop, _, default, doc in SWITCHES:
            add_property(obj, "App::PropertyBool", prop, "Refinement", doc,
                         RESTORED_WITHOUT.get(prop, default) if restored else default)
        for prop, type_name, doc in FEATURE_PROPERTIES:
            add_property(obj, type_name, prop, "Refinement", doc)
        for prop, condition, default in DISPLAY:
            add_property(obj, "App::PropertyBool", prop, "Display",
                         "Show the grid lines on the {} faces".format(condition), default)
        r = "Result"
        for name, type_name, doc in (
            ("CellCount", "App::PropertyInteger", "Hexahedral cells"),
            ("PointCount", "App::PropertyInteger", "Points over all blocks (shared ones once per block)"),
            ("NormalPointsUsed", "App::PropertyInteger", "Points on the wall-normal lines"),
            ("FirstCellHeightAsked", "App::PropertyFloat", "First cell height asked (0: none)"),
            ("FirstCellHeightMin", "App::PropertyFloat", "Smallest first cell height of the wall-normal lines"),
            ("FirstCellHeightMax", "App::PropertyFloat", "Largest first cell height of the wall-normal lines"),
            ("GrowthMax", "App::PropertyFloat", "Largest growth ratio of the wall-normal lines"),
            ("OuterFacesSplit", "App::PropertyInteger",
             "Outer block faces of a box or cylinder domain whose quads go to more than one of inlet, outlet, side"),
            ("FoldRefinements", "App::PropertyInteger",
             "Where a cell folded, the blocks it was in took 2^FoldRefinements times their tangential cells"),
            ("Digest", "App::PropertyString", "SHA-1 of the grid's points"),
        ):
            add_property(obj, type_name, name, r, doc, mode=READ_ONLY)

    def key(self, obj):
        if obj.Method == "subdivision":
            data = repr((obj.VolumeMesh.Proxy.key(obj.VolumeMesh), obj.Method, obj.SubdivisionSteps))
        else:
            data = repr((obj.VolumeMesh.Digest, obj.Preset, sorted(refine_options(obj).items())))
        return hashlib.sha1(data.encode()).hexdigest()

    def make(self, obj):
        from bvmesh import grid, volume

        if obj.Method == "subdivision":
            wall, plane, settings = volume_mesh_feature.marching_inputs(obj.VolumeMesh)
            # The control volume is marched from the level the blocks' layers are marched from.
            wall = volume_mesh_feature.marching_wall_used(obj.VolumeMesh) or wall
            steps = obj.SubdivisionSteps

            def subdivide():
                control = volume.control_volume(wall(), symmetry_plane=plane, **settings)
                return grid.refine(control, method="subdivision", steps=steps)

            return run_work("subdividing the control volume of {}".format(obj.Label), subdivide)
        blocks = volume_mesh_feature.volume_mesh(obj.VolumeMesh)
        preset, settings = obj.Preset, refine_options(obj)
        return run_work("evaluating the grid of {}".format(obj.Label), lambda: grid.refine(blocks, preset, **settings))

    def digest_of(self, result):
        return grid_digest(structured_of(result))

    def compute(self, obj):
        if obj.VolumeMesh is None:
            raise ValueError("the volume grid needs a volume mesh")
        result, made = self.fresh_result(obj)
        structured = structured_of(result)
        if made:
            obj.CellCount = structured.cell_count
            obj.PointCount = structured.point_count
            if obj.Method == "subdivision":
                # No wall law was asked: the wall-normal lines are the control layers' refinement.
                walls = [b for b in range(structured.block_count) if structured.faces(b)["w_min"]["condition"] == "wall"]
                obj.NormalPointsUsed = structured.size(walls[0])[2] if walls else 0
                obj.FirstCellHeightAsked = obj.FirstCellHeightMin = obj.FirstCellHeightMax = obj.GrowthMax = 0.0
                obj.OuterFacesSplit = obj.FoldRefinements = 0
            else:
                obj.NormalPointsUsed = result.normal_points
                obj.FirstCellHeightAsked = result.first_cell_height_asked
                obj.FirstCellHeightMin = result.first_cell_height_min
                obj.FirstCellHeightMax = result.first_cell_height_max
                obj.GrowthMax = result.growth_max
                obj.OuterFacesSplit = result.outer_faces_split
                obj.FoldRefinements = result.fold_refinements
        conditions = shown_conditions(obj, DISPLAY)
        obj.Shape = boundary_lines_shape(structured, conditions)


def structured_of(result):
    """The StructuredGrid of a refinement's result (a RefinedGrid, or the StructuredGrid itself)."""
    return getattr(result, "grid", result)


def refined_grid(obj):
    """The grid of a VolumeGrid object as bvmesh.grid's functions take it: a bvmesh.RefinedGrid, or
    for Method subdivision a bvmesh.StructuredGrid."""
    return obj.Proxy.result(obj)


def structured_grid(obj):
    """The bvmesh.StructuredGrid (points and blocks) of a VolumeGrid object."""
    return structured_of(refined_grid(obj))


def create(doc, name="VolumeGrid"):
    obj = doc.addObject("Part::FeaturePython", name)
    VolumeGridProxy(obj)
    return obj

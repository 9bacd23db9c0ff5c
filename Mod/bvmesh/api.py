"""BVMesh's headless API for FreeCAD: works in freecadcmd, in the GUI's Python console and in
plain /usr/bin/python3 with FreeCAD's library on sys.path. GUI commands call these functions
through FreeCADGui.doCommand, so a recorded macro replays them without the GUI."""

import numpy as np

from bvmesh import load_core, polyhedra
from bvmesh.adapters.shapes import as_shape, brep_to_shape, shape_to_brep


def shape_report(shape_or_object, sharp_angle_degrees=30.0, sew=None, sew_tolerance=0.0):
    """What a CAD shape holds, as a dict: face count and surface types, bounding box, and edges
    classified as sharp / smooth / free / seam / non-manifold / degenerate with their dihedral
    angles, under "repair" what sewing did (gaps closed and left open, watertight or not), and under
    "flow_domain" the split of a flow domain's CAD (api.flow_domain_of) or None. Face i is FreeCAD's
    Face<i+1>, edge j its Edge<j+1>: of the sewn shape for a file (sewn on reading, as import_cad
    does; sew=False: as written), of the shape given otherwise (sew=True reports on its sewn copy
    instead, and then no flow domain). sew_tolerance: absolute, 0 = automatic."""
    import os

    core = load_core()
    if isinstance(shape_or_object, (str, os.PathLike)):
        path = os.fspath(shape_or_object)
        report = core.summarize_file(path, float(sharp_angle_degrees), sew is not False, float(sew_tolerance))
        brep = core.read_cad_file_as_brep(path, sew=sew is not False, sew_tolerance=float(sew_tolerance))
    else:
        brep = shape_to_brep(as_shape(shape_or_object))
        report = core.summarize_brep(brep, float(sharp_angle_degrees), bool(sew), float(sew_tolerance))
    # Face numbers as the report's: a sewn copy of a shape given may number its faces otherwise.
    report["flow_domain"] = None if sew and not isinstance(shape_or_object, (str, os.PathLike)) else flow_domain_of(brep)
    report["overlapping_solids"] = core.overlapping_solids(brep) if report["solids"] > 1 else []
    return report


def overlapping_solids_message(overlaps):
    """The overlaps of core.overlapping_solids in words, or "" for none."""
    if not overlaps:
        return ""
    pairs = ", ".join("{} and {} (at ({:.6g}, {:.6g}, {:.6g}))".format(
        o["solid"] + 1, o["other_solid"] + 1, *o["where"]) for o in overlaps[:5])
    return ("solids that run into each other: {}{}; their faces are no body's surface (one solid's faces lie "
            "inside the other): fuse them into one solid first (FreeCAD: Part, Boolean, Union)").format(
                pairs, ", ..." if len(overlaps) > 5 else "")


def flow_domain_of(shape_or_brep):
    """The split of a flow domain's CAD (bvmesh.polyhedra.flow_domain's dict without the target),
    or None when the shape is not one (a body alone, or a domain the volume stage cannot take)."""
    core = load_core()
    brep = shape_or_brep if isinstance(shape_or_brep, str) else shape_to_brep(as_shape(shape_or_brep))
    try:
        return core.split_flow_domain(brep)
    except ValueError:
        return None


def format_shape_report(report):
    """The report of shape_report as readable lines."""
    counts = report["edge_counts"]
    types = {}
    for name in report["surface_types"]:
        types[name] = types.get(name, 0) + 1
    low, high = report["bounds"]
    lines = [
        "{} faces ({}), {} edges, {} vertices, {} solid(s)".format(
            report["faces"],
            ", ".join("{} {}".format(n, t) for t, n in sorted(types.items())),
            len(report["edges"]),
            report["vertices"],
            report["solids"],
        ),
        "edges: {sharp} sharp, {smooth} smooth, {free} free, {seam} seam, "
        "{nm} non-manifold, {degenerate} degenerate".format(nm=counts["non-manifold"], **counts),
        "bounding box: ({:.6g}, {:.6g}, {:.6g}) .. ({:.6g}, {:.6g}, {:.6g})".format(*low, *high),
    ]
    sharp = [
        "Edge{} ({:.1f} deg)".format(j + 1, edge["max_dihedral_degrees"])
        for j, edge in enumerate(report["edges"])
        if edge["kind"] == "sharp"
    ]
    if sharp:
        lines.append("sharp edges: " + ", ".join(sharp))
    lines.extend(report.get("repair", {}).get("lines", []))
    overlaps = overlapping_solids_message(report.get("overlapping_solids"))
    if overlaps:
        lines.append(overlaps)
    domain = report.get("flow_domain")
    if domain:
        faces = lambda indices: ", ".join("Face{}".format(i + 1) for i in indices)  # noqa: E731
        size = ("radius {:.6g}".format(domain["radius"]) if domain["shape"] == "sphere"
                else "half sizes ({:.6g}, {:.6g}, {:.6g})".format(*domain["half_extent"]))
        lines.append("flow domain: {}{} around ({:.6g}, {:.6g}, {:.6g}), {}; body (the target): {}; domain: {}".format(
            "half " if domain["symmetry_face"] is not None else "", domain["shape"], *domain["centre"], size,
            faces(domain["body_faces"]), faces(domain["outer_faces"])))
        if domain.get("outflow_face") is not None:
            lines.append("the body runs into the outflow plane of Face{} (normal ({:.6g}, {:.6g}, {:.6g}))".format(
                domain["outflow_face"] + 1, *[c + 0.0 for c in domain["outflow_plane"][1]]))  # no -0
    return lines


def make_bspline_face(poles, u_knots, v_knots, u_multiplicities, v_multiplicities,
                      u_degree=3, v_degree=3, weights=None):
    """A Part.Face on the B-spline surface with the given poles (n_u x n_v x 3), knots and
    multiplicities, built and checked by the core."""
    poles = np.asarray(poles, dtype=float)
    brep = load_core().bspline_face_brep(
        poles, int(u_degree), int(v_degree), list(u_knots), list(v_knots),
        list(u_multiplicities), list(v_multiplicities), weights,
    )
    shape = brep_to_shape(brep)
    return shape.Faces[0]


def import_cad(doc, path, name=None):
    """Reads a STEP / IGES / BREP file with the core (its faces sewn, shape_report) and adds it to
    `doc` as a Part::Feature, which is returned; what sewing did goes to FreeCAD's console.
    Nothing is added when the file cannot be read."""
    import os

    import FreeCAD

    from bvmesh.adapters.shapes import brep_to_shape

    brep, repair = load_core().read_cad_file(os.fspath(path))
    shape = brep_to_shape(brep)
    label = name or os.path.splitext(os.path.basename(os.fspath(path)))[0]
    FreeCAD.Console.PrintMessage("".join("BVMesh import {}: {}\n".format(label, line) for line in repair["lines"]))
    feature = doc.addObject("Part::Feature", "CAD")
    feature.Label = label
    feature.Shape = shape
    doc.recompute()
    return feature


def print_shape_report(shape_or_object, sharp_angle_degrees=30.0):
    """Writes shape_report's summary to FreeCAD's console (the Report view in the GUI) and
    returns the report."""
    import FreeCAD

    report = shape_report(shape_or_object, sharp_angle_degrees)
    name = getattr(shape_or_object, "Label", "shape")
    FreeCAD.Console.PrintMessage("BVMesh report for {}:\n".format(name))
    for line in format_shape_report(report):
        FreeCAD.Console.PrintMessage("  {}\n".format(line))
    return report


# -- document objects of the surface stage ---------------------------------------------------------
# Every make_* adds one object, recomputes, and raises (leaving no half-made object) when the
# recompute fails. The step functions append a step to a SurfaceFit and recompute; on failure
# the fit is left as it was. The GUI calls exactly these functions through doCommand.


def _attach_view_provider(obj):
    import FreeCAD

    if FreeCAD.GuiUp:
        from bvmesh.gui import view_providers

        view_providers.attach(obj)


def _error_of(obj):
    return getattr(getattr(obj, "Proxy", None), "error", "") or "see the Report view"


def _recompute(obj):
    """Recomputes obj's document; raises RuntimeError with the object's error if obj failed, or
    naming the object it depends on that failed: FreeCAD then skips obj and leaves it touched,
    which isValid() does not tell (the call returned as if done, the result stale)."""
    from bvmesh.features.common import upstream

    obj.Document.recompute()
    if not obj.isValid():
        raise RuntimeError("{} failed: {}".format(obj.Label, _error_of(obj)))
    if "Touched" in obj.State:
        # Not OutListRecursive: it raises on a dependency cycle, naming nothing.
        failed = [o for o, _ in upstream(obj) if not o.isValid()]
        cause = "{} failed: {}".format(failed[0].Label, _error_of(failed[0])) if failed else "its inputs did not compute"
        raise RuntimeError("{} was not computed: {}".format(obj.Label, cause))


def _refusing(obj, change):
    """change(), raising ValueError with the first change obj's proxy refused (it puts back a list
    given for an enumeration, which in FreeCAD replaces its choices, and says so in the Report view
    only)."""
    proxy = obj.Proxy
    proxy.refused = []
    try:
        change()
    finally:
        refused, proxy.refused = proxy.refused, None
    if refused:
        raise ValueError(refused[0])


def _change_and_recompute(obj, names, change):
    """change(), then a recompute; on a failure the properties `names` of obj get their values
    back and the document is recomputed, so that a failed call leaves it as it was."""
    saved = {name: getattr(obj, name) for name in names}
    try:
        _refusing(obj, change)
        _recompute(obj)
    except Exception:
        for name, value in saved.items():
            setattr(obj, name, value)
        obj.Document.recompute()
        raise
    return obj


def _new_object(create, doc, name, fill):
    obj = create(doc, name)
    try:
        _refusing(obj, lambda: fill(obj))
        _attach_view_provider(obj)
        _recompute(obj)
    except Exception:
        doc.removeObject(obj.Name)
        raise
    return obj


def format_target_report(report):
    """Readable lines of bvmesh.Target.report()."""
    types = {}
    for name in report["surface_types"]:
        types[name] = types.get(name, 0) + 1
    low, high = report["bounds"]
    lines = [
        "{} faces ({})".format(report["faces"], ", ".join("{} {}".format(n, t) for t, n in sorted(types.items()))),
        "{} edges: {} sharp, {} free, {} non-manifold".format(
            len(report["edges"]), len(report["sharp_edges"]), len(report["free_edges"]),
            len(report["non_manifold_edges"])),
        "bounding box ({:.6g}, {:.6g}, {:.6g}) .. ({:.6g}, {:.6g}, {:.6g}), diagonal {:.6g}".format(
            *low, *high, report["diagonal"]),
        "tolerance {:.3g}, {} triangles in the projection index".format(report["tolerance"], report["triangles"]),
    ]
    if report["gaps"]:
        widest = max(gap["width"] for gap in report["gaps"])
        lines.append("{} gaps between faces, widest {:.3g}".format(len(report["gaps"]), widest))
    if report["untessellated_faces"]:
        lines.append("faces without tessellation: {}".format(report["untessellated_faces"]))
    lines.extend(report.get("repair", {}).get("lines", []))
    return lines


def make_target(doc, source, faces=None, name="Target"):
    """A BVMesh Target on `source` (an object with a Shape): its faces named in `faces`
    (["Face1", ...]), or all of them; on a flow domain's CAD (a box or sphere with the body cut
    out) the body's, and the Target's FlowDomain, DomainCentre and DomainSize give the domain."""
    from bvmesh.features import target

    def fill(obj):
        obj.Source = source
        obj.Faces = list(faces or [])

    obj = _new_object(target.create, doc, name, fill)
    if getattr(source, "ViewObject", None) is not None:
        source.ViewObject.Visibility = False  # the target shows the fitted faces
    return obj


def _set_polyhedron_data(obj, vertices, faces, creases, corners):
    import FreeCAD

    from bvmesh.features.polyhedron import flatten_faces

    sizes, indices = flatten_faces(faces)
    obj.Vertices = [FreeCAD.Vector(*map(float, v)) for v in vertices]
    obj.FaceSizes = sizes
    obj.FaceIndices = indices
    obj.Creases = [int(i) for pair in creases for i in pair]
    obj.Corners = [int(i) for i in corners]


def make_polyhedron(doc, vertices, faces, creases=(), corners=(), features=None, name="ControlPolyhedron",
                    root_chord=0.0):
    """A ControlPolyhedron from vertices [(x, y, z)], faces [[vertex ids, counter-clockwise]],
    crease vertex pairs and corner vertex ids; `features` optionally maps features to the target
    ({curves, edge_curve, vertex_cad_vertex} as bvmesh.SurfaceFitter takes it); root_chord: of the
    wing it was placed on (its RootChord, a VolumeMesh's default reference length), 0 for none."""
    from bvmesh.features import polyhedron

    def fill(obj):
        _set_polyhedron_data(obj, vertices, faces, creases, corners)
        obj.RootChord = float(root_chord)
        if features:
            obj.FeatureCurves = [" ".join(str(int(e)) for e in curve) for curve in features.get("curves", [])]
            obj.EdgeCurves = [int(i) for i in features.get("edge_curve", [])]
            obj.VertexCadVertices = [int(i) for i in features.get("vertex_cad_vertex", [])]

    return _new_object(polyhedron.create, doc, name, fill)


_POLYHEDRON_DATA = ("Vertices", "FaceSizes", "FaceIndices", "Creases", "Corners")


def set_polyhedron(polyhedron, vertices, faces, creases=(), corners=()):
    """Replaces the data of a ControlPolyhedron (and recomputes what depends on it); on a failure
    the polyhedron keeps its data."""
    return _change_and_recompute(polyhedron, _POLYHEDRON_DATA,
                                 lambda: _set_polyhedron_data(polyhedron, vertices, faces, creases, corners))


def make_polyhedron_from_mesh(doc, mesh_object, name="ControlPolyhedron"):
    """A ControlPolyhedron with the points and triangles of a Mesh object."""
    points, triangles = mesh_object.Mesh.Topology
    return make_polyhedron(doc, [(p.x, p.y, p.z) for p in points], [list(t) for t in triangles], name=name)


def polygons_of_shape(shape, relative_tolerance=1e-7):
    """(vertices, faces) of a shape made of planar polygon faces: vertices merged where they
    coincide (within relative_tolerance of the size), each face counter-clockwise about its
    normal. ValueError for a face that is not a planar polygon."""
    import FreeCAD

    tolerance = relative_tolerance * max(shape.BoundBox.DiagonalLength, 1e-300)
    vertices, faces = [], []

    def vertex_id(point):
        for i, known in enumerate(vertices):
            if (known - point).Length <= tolerance:
                return i
        vertices.append(point)
        return len(vertices) - 1

    for k, face in enumerate(shape.Faces):
        if face.Surface.TypeId != "Part::GeomPlane" or len(face.Wires) != 1 or any(
                edge.Curve.TypeId != "Part::GeomLine" for edge in face.Edges):
            raise ValueError("Face{} is not a planar polygon without holes".format(k + 1))
        points = [v.Point for v in face.OuterWire.OrderedVertexes]
        normal = FreeCAD.Vector()
        for i, p in enumerate(points):
            normal += p.cross(points[(i + 1) % len(points)])
        u0, u1, v0, v1 = face.ParameterRange
        if normal.dot(face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))) < 0:
            points.reverse()
        faces.append([vertex_id(p) for p in points])
    return [(v.x, v.y, v.z) for v in vertices], faces


def make_polyhedron_from_shape(doc, shape_object, name="ControlPolyhedron"):
    """A ControlPolyhedron from a Part object made of planar polygon faces (e.g. a Draft or
    Part design of the coarse mesh)."""
    vertices, faces = polygons_of_shape(shape_object.Shape)
    return make_polyhedron(doc, vertices, faces, name=name)


def make_polyhedron_from_template(doc, target, template, name="ControlPolyhedron", **parameters):
    """A ControlPolyhedron from template `template` placed on a BVMesh Target, with its feature
    map and, from a wing template, the wing's root chord (RootChord; see
    bvmesh.extensions.place_template)."""
    from bvmesh import extensions

    placed = extensions.place_template(target.Proxy.core_target(target), template, **parameters)
    mesh, planform = placed["mesh"], placed.get("planform")
    return make_polyhedron(doc, mesh.vertices, mesh.faces, creases=mesh.creases, corners=mesh.corners,
                           features=placed["feature_map"], name=name,
                           root_chord=planform["root_chord"] if planform else 0.0)


def mark_features(polyhedron, creases=(), corners=(), unmark=False):
    """Marks (or with unmark, clears) crease edges (vertex pairs) and corner vertices; on a
    failure (an edge or vertex the polyhedron does not have) it keeps its marks."""
    from bvmesh.features.polyhedron import pairs

    current = {tuple(sorted(p)) for p in pairs(polyhedron.Creases)}
    chosen = {tuple(sorted(int(i) for i in p)) for p in creases}
    current = current - chosen if unmark else current | chosen
    corner_set = set(polyhedron.Corners)
    chosen_corners = {int(i) for i in corners}
    corner_set = corner_set - chosen_corners if unmark else corner_set | chosen_corners

    def change():
        polyhedron.Creases = [i for pair in sorted(current) for i in pair]
        polyhedron.Corners = sorted(corner_set)

    return _change_and_recompute(polyhedron, ("Creases", "Corners"), change)


def find_creases(polyhedron, target, relative_distance=0.01):
    """Interior edges of the polyhedron that lie along the target's sharp edges: end points and
    the points at 1/4, 1/2, 3/4 within relative_distance x edge length of a sharp edge."""
    import numpy as np

    from bvmesh.features import polyhedron as polyhedron_feature

    core_target = target.Proxy.core_target(target)
    sharp = list(core_target.sharp_edges(target.SharpAngle))
    mesh = polyhedron_feature.control_mesh(polyhedron)
    if not sharp:
        return []
    vertices = mesh.vertices
    found = []
    for (a, b), (left, right) in zip(mesh.edges, mesh.edge_faces):
        if left < 0 or right < 0:
            continue
        p, q = vertices[a], vertices[b]
        points = np.array([p + t * (q - p) for t in (0.0, 0.25, 0.5, 0.75, 1.0)])
        distances = core_target.project_to_edges(points, sharp)["distances"]
        if distances.max() <= relative_distance * np.linalg.norm(q - p):
            found.append([int(a), int(b)])
    return found


def detect_creases(polyhedron, target, relative_distance=0.01):
    """Marks the polyhedron's edges along the target's sharp edges as creases (see
    find_creases) and returns them."""
    found = find_creases(polyhedron, target, relative_distance)
    mark_features(polyhedron, creases=found)
    return found


_FIT_PARAMETERS = {
    "tolerance": "Tolerance", "relative_tolerance": "RelativeTolerance", "max_level": "MaxLevel",
    "max_corrections": "MaxCorrections", "stagnation_ratio": "StagnationRatio", "solver": "Solver",
    "project_along_normals": "ProjectAlongNormals", "check_samples_per_face": "CheckSamplesPerFace",
    "check_target_subdivisions": "CheckTargetSubdivisions",
    "correction_passes": "CorrectionPasses", "smooth_iterations": "SmoothIterations",
    "smooth_lambda": "SmoothLambda", "smooth_mu": "SmoothMu",
}


_FIT_WEIGHTS = ("smooth", "crease", "boundary", "corner")


def _set_fit_parameters(fit, parameters):
    import FreeCAD

    for key, value in parameters.items():
        if key == "weights":
            for kind, weight in value.items():
                if kind not in _FIT_WEIGHTS:
                    raise ValueError("unknown weight '{}'; known: {}".format(kind, ", ".join(_FIT_WEIGHTS)))
                setattr(fit, "Weight" + kind.capitalize(), float(weight))
        elif key == "symmetry_plane":
            fit.UseSymmetryPlane = value is not None
            if value is not None:
                fit.SymmetryPoint = FreeCAD.Vector(*map(float, value[0]))
                fit.SymmetryNormal = FreeCAD.Vector(*map(float, value[1]))
        elif key in _FIT_PARAMETERS:
            setattr(fit, _FIT_PARAMETERS[key], value)
        else:
            raise ValueError("unknown fit parameter '{}'; known: {}".format(
                key, ", ".join(sorted(list(_FIT_PARAMETERS) + ["weights", "symmetry_plane"]))))


def symmetry_plane_guess(target):
    """((point), (normal)) of the first planar face of the target's source left out of the fit
    (e.g. the root face of a half wing), or of the symmetry plane of the flow domain the target
    took its body from, or else of the plane the target's open side lies in with the whole target
    on one side (a half model read without its symmetry face, as the templates find it); else
    None."""
    normal = getattr(target, "SymmetryNormal", None)
    if not target.Faces and normal is not None and normal.Length > 0:
        point = target.SymmetryPoint
        return (point.x, point.y, point.z), (normal.x, normal.y, normal.z)
    kept = set(target.Faces)
    for i, face in enumerate(target.Source.Shape.Faces if target.Faces else []):
        if "Face{}".format(i + 1) not in kept and face.Surface.TypeId == "Part::GeomPlane":
            point, normal = face.Surface.Position, face.Surface.Axis
            return (point.x, point.y, point.z), (normal.x, normal.y, normal.z)
    plane = polyhedra.symmetry_plane(target.Proxy.core_target(target))
    if plane is None:
        return None
    return tuple(float(x) for x in plane[0]), tuple(float(x) for x in plane[1])


def make_surface_fit(doc, target, polyhedron, name="SurfaceFit", **parameters):
    """A SurfaceFit of `polyhedron` to `target` (no steps yet: the result is the polyhedron
    measured against the target). Parameters as set_fit_parameters."""
    from bvmesh.features import surface_fit

    def fill(obj):
        obj.Target = target
        obj.Polyhedron = polyhedron
        _set_fit_parameters(obj, parameters)

    return _new_object(surface_fit.create, doc, name, fill)


def set_fit_parameters(fit, **parameters):
    """Sets fitting parameters: tolerance, relative_tolerance, max_level, max_corrections,
    stagnation_ratio, solver ('cholesky' | 'cgls'), weights {smooth, crease, boundary, corner},
    symmetry_plane ((point), (normal)) or None, project_along_normals, check_samples_per_face,
    check_target_subdivisions,
    correction_passes, smooth_iterations, smooth_lambda, smooth_mu; then recomputes. On a failure
    (a bad value, one the fit refuses) the fit keeps every parameter it had."""
    names = list(_FIT_PARAMETERS.values()) + ["Weight" + kind.capitalize() for kind in _FIT_WEIGHTS]
    names += ["UseSymmetryPlane", "SymmetryPoint", "SymmetryNormal"]
    return _change_and_recompute(fit, names, lambda: _set_fit_parameters(fit, parameters))


def _add_step(fit, line):
    from bvmesh.features.surface_fit import parse_step

    parse_step(line)
    previous = list(fit.Steps)
    fit.Steps = previous + [line]
    try:
        _recompute(fit)
    except Exception:
        fit.Steps = previous
        fit.purgeTouched()
        raise
    return fit


def subdivide(fit):
    """Step 1: one Catmull-Clark subdivision of the fit's control mesh."""
    return _add_step(fit, "subdivide")


def project(fit):
    """Step 3: projects the limit samples onto the target (updates the sample distances)."""
    return _add_step(fit, "project")


def approximate(fit):
    """Step 4: least-squares control points for the current projections."""
    return _add_step(fit, "approximate")


def correct_parameters(fit, passes=None):
    """Steps 2-4 again at the same level (CorrectionPasses times unless `passes` is given)."""
    return _add_step(fit, "correct {}".format(int(fit.CorrectionPasses if passes is None else passes)))


def smooth(fit, iterations=None, lambda_=None, mu=None):
    """Taubin smoothing of the control mesh (the fit's Smooth* parameters unless given)."""
    return _add_step(fit, "smooth {} {!r} {!r}".format(
        int(fit.SmoothIterations if iterations is None else iterations),
        float(fit.SmoothLambda if lambda_ is None else lambda_), float(fit.SmoothMu if mu is None else mu)))


def fit_to_tolerance(fit):
    """Subdivides, projects, approximates and corrects level after level until the tolerance,
    stagnation or MaxLevel (the fit's parameters)."""
    return _add_step(fit, "fit")


def convergence_table(fit):
    """One dict per pass: level, correction, control_points, max_distance, rms_distance,
    limit_to_target, target_to_limit and target_to_limit_beyond_cad (None when not checked)."""
    from bvmesh.features.surface_fit import convergence_table as table

    return table(fit)


def fitted_mesh(fit):
    """The fitted control mesh (bvmesh.ControlMesh) of a SurfaceFit."""
    from bvmesh.features.surface_fit import result_mesh

    return result_mesh(fit)


def make_distance_map(fit, samples_per_face=3, color_max=0.0, name="DistanceMap"):
    """The fit's limit surface as a mesh coloured by distance to the target (blue 0 .. red at
    color_max and above; 0: the 99th percentile of the distances)."""
    from bvmesh.features import distance_map

    def fill(obj):
        obj.Fit = fit
        obj.SamplesPerFace = int(samples_per_face)
        obj.ColorMax = float(color_max)

    return _new_object(distance_map.create, fit.Document, name, fill)


def make_bspline_shell(fit, name="BsplineShell", tangent_continuity=False):
    """The fit's limit surface as a shell of B-spline faces (needs the core's conversion);
    tangent_continuity: neighbouring faces share their tangent planes along smooth borders."""
    from bvmesh.features import bspline_shell

    def fill(obj):
        obj.Fit = fit
        obj.TangentContinuity = bool(tangent_continuity)

    return _new_object(bspline_shell.create, fit.Document, name, fill)


def export_step(obj, path):
    """Writes the shape of `obj` (e.g. a BsplineShell) to a STEP file."""
    import os

    if obj.Shape.isNull():
        raise ValueError("{} has no shape to export".format(obj.Label))
    obj.Shape.exportStep(os.fspath(path))
    return path


def plot_convergence(fit, path, title=None):
    """Saves the convergence plot of a SurfaceFit (max and RMS sample distance per pass, log
    scale, tolerance line, two-sided checks) as a PNG at `path` and returns the path."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    rows = convergence_table(fit)
    if not rows:
        raise ValueError("{} has no convergence history yet".format(fit.Label))
    passes = list(range(len(rows)))
    figure = Figure(figsize=(7.0, 4.2), dpi=100)
    FigureCanvasAgg(figure)
    axes = figure.add_subplot(1, 1, 1)
    axes.semilogy(passes, [r["max_distance"] for r in rows], "o-", color="tab:red", label="max distance")
    axes.semilogy(passes, [r["rms_distance"] for r in rows], "s-", color="tab:blue", label="RMS distance")
    checked = [(i, r) for i, r in zip(passes, rows) if r["limit_to_target"] is not None]
    if checked:
        # What the stop rule holds against the tolerance; the raw target side, where the CAD's own
        # tolerance at its edges is larger, as open symbols.
        axes.semilogy([i for i, _ in checked],
                      [max(r["limit_to_target"], r["target_to_limit_beyond_cad"] or 0.0) for _, r in checked],
                      "D", color="black", label="two-sided check")
        axes.semilogy([i for i, _ in checked], [r["target_to_limit"] for _, r in checked], "D", color="black",
                      markerfacecolor="none", label="target -> limit, before the CAD edge tolerance")
    if fit.AbsoluteTolerance > 0:
        axes.axhline(fit.AbsoluteTolerance, color="tab:green", linestyle="--", label="tolerance")
    for i in range(1, len(rows)):
        if rows[i]["level"] != rows[i - 1]["level"]:
            axes.axvline(i - 0.5, color="0.8", linewidth=0.8)
    axes.set_xticks(passes)
    axes.set_xticklabels(["{}.{}".format(r["level"], r["correction"]) for r in rows], fontsize=7)
    axes.set_xlabel("pass (level.correction)")
    axes.set_ylabel("distance to target (model units)")
    label = title or "Convergence of {}".format(fit.Label)
    if fit.StopReason:
        label += " ({} at level {})".format(fit.StopReason, fit.Level)
    axes.set_title(label, fontsize=10)
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(str(path))
    return path


# -- volume stage ---------------------------------------------------------------------------------


def _set_options(obj, table, options, what):
    """Sets the properties of `table` (property, option, ...) named by their option keywords
    (sequences of three numbers for vector properties)."""
    import FreeCAD

    by_option = {row[1]: row[0] for row in table}
    _check_option_names(table, options, what)
    for option, value in options.items():
        prop = by_option[option]
        try:
            if isinstance(getattr(obj, prop), FreeCAD.Vector):
                numbers = tuple(map(float, value))
                if len(numbers) != 3:
                    raise ValueError("not three numbers")
                value = FreeCAD.Vector(*numbers)
            setattr(obj, prop, value)
        except (TypeError, ValueError):
            # FreeCAD's own message is a dict of its internals: say what the option takes.
            raise ValueError("{} option '{}' takes {}, got {!r}".format(what, option, _property_kind(obj, prop),
                                                                       value)) from None


def _check_option_names(table, options, what):
    known = sorted(row[1] for row in table)
    for option in options:
        if option not in known:
            raise ValueError("unknown {} option '{}'; known: {}".format(what, option, ", ".join(known)))


def check_option_names(volume_options=None, grid_options=None):
    """Raises ValueError for an option that make_volume_mesh (volume_options) or make_volume_grid
    (grid_options) does not take: a batch run checks them before its surface fit, which they
    would otherwise fail only after."""
    from bvmesh.features import volume_grid

    _check_option_names(_volume_option_table(), volume_options or {}, "volume mesh")
    _check_option_names(_grid_option_table(volume_grid), grid_options or {}, "volume grid")


def _grid_option_table(volume_grid):
    return volume_grid.OPTIONS + volume_grid.SWITCHES + volume_grid.SUBDIVISION_OPTIONS


def _property_kind(obj, prop):
    """What a property takes, in words."""
    type_id = obj.getTypeIdOfProperty(prop)
    if type_id == "App::PropertyEnumeration":
        return "one of " + ", ".join(obj.getEnumerationsOfProperty(prop))
    return {"App::PropertyInteger": "a whole number", "App::PropertyBool": "true or false",
            "App::PropertyVector": "three numbers"}.get(type_id, "a number")


def make_volume_mesh(fit, name="VolumeMesh", wall_level=-1, marching_level=-1, marching_point_limit=None, show=None,
                     **options):
    """The block-structured B-spline volume mesh around a SurfaceFit's wall: boundary-layer control
    layers along the wall normals and the far field marched out to a sphere (half sphere on the
    fit's symmetry plane), one tricubic block per wall patch. wall_level: -1 the fit's level, or a
    lower one (the same fit refitted to it). marching_level: -1 march the wall itself, or the
    highest level below it whose control mesh has at most marching_point_limit points (default
    bvmesh.volume.MARCHING_POINT_LIMIT; 0: no limit), and, where that folds, each lower level
    in turn, then the finer ones up to the wall's (MarchingLevelUsed says which), or a level below the wall's whose marched layers are
    carried onto the wall (its charts stay the blocks' wall faces). options: those of bvmesh.volume.offset_and_farfield
    (reference_length, reynolds_number, boundary_layer_thickness, boundary_layer_layers,
    boundary_layer_growth, sharp_edge_splay, farfield_distance, farfield_growth, smoothing,
    min_scaled_jacobian, max_layers, knife_edge_fans; farfield_scheme 'hyperbolic' (default) | 'smoothed'; domain
    'sphere' | 'box' | 'cylinder' | 'cad', flow_direction, box_half_extent). domain 'cad', the
    default when the fit's target is a flow domain's body: the domain its CAD holds. show: the
    block faces shown, e.g. ('wall', 'symmetry')."""
    from bvmesh.features import volume_mesh

    if "domain" not in options and getattr(fit.Target, "FlowDomain", ""):
        options = dict(options, domain="cad")

    def fill(obj):
        obj.Fit = fit
        obj.WallLevel = int(wall_level)
        obj.MarchingLevel = int(marching_level)
        if marching_point_limit is not None:
            obj.MarchingPointLimit = int(marching_point_limit)
        _set_options(obj, _volume_option_table(), options, "volume mesh")
        _set_display(obj, volume_mesh.DISPLAY, show)

    return _new_object(volume_mesh.create, fit.Document, name, fill)


def _set_display(obj, table, show):
    if show is None:
        return
    known = {condition for _, condition, _ in table}
    unknown = set(show) - known
    if unknown:
        raise ValueError("show takes boundary conditions among {}, got {}".format(", ".join(sorted(known)),
                                                                                 ", ".join(sorted(unknown))))
    for prop, condition, _ in table:
        setattr(obj, prop, condition in show)


def set_volume_options(volume_mesh_object, wall_level=None, marching_level=None, marching_point_limit=None, show=None,
                       **options):
    """Changes options of a VolumeMesh (as make_volume_mesh) and recomputes; on a failure the
    object keeps its previous options."""
    from bvmesh.features import volume_mesh

    return _set_and_recompute(volume_mesh_object, _volume_option_table(), volume_mesh.DISPLAY, options, show,
                              "volume mesh", {"WallLevel": wall_level, "MarchingLevel": marching_level,
                                              "MarchingPointLimit": marching_point_limit})


def _volume_option_table():
    """(property, option) of every VolumeMesh option: the marching numbers, the domain and its
    vectors."""
    from bvmesh.features import volume_mesh

    return ([row[:2] for row in volume_mesh.OPTIONS] + [row[:2] for row in volume_mesh.SWITCHES]
            + [("Domain", "domain"), ("FarfieldScheme", "farfield_scheme")] + [row[:2] for row in volume_mesh.VECTORS])


def _set_and_recompute(obj, table, display, options, show, what, extra):
    names = [row[0] for row in table] + [prop for prop, _, _ in display] + list(extra)

    def change():
        for prop, value in extra.items():
            if value is not None:
                setattr(obj, prop, value)
        _set_options(obj, table, options, what)
        _set_display(obj, display, show)

    return _change_and_recompute(obj, names, change)


def volume_mesh_of(volume_mesh_object):
    """The bvmesh.VolumeMesh (blocks, marching report) of a VolumeMesh object."""
    from bvmesh.features import volume_mesh

    return volume_mesh.volume_mesh(volume_mesh_object)


def _feature_edge_links(feature_edges, document, grid=None):
    """feature_edges as a PropertyLinkSubList value, each object checked to be alive in
    `document`: FreeCAD 0.20 keeps a dangling pointer for a link to a deleted object (or one of a
    closed document), and the next read of the property kills the process with the document. For
    an existing grid, no object may depend on it (a dependency cycle)."""
    from bvmesh.features.common import describe_path, link_path

    links = []
    for entry in feature_edges:
        try:
            shape_object, names = entry
        except (TypeError, ValueError):
            raise ValueError("feature_edges takes (object, edge name or names) pairs, got {!r}".format(entry)) from None
        try:
            alive = shape_object.Document is document and document.getObject(shape_object.Name) is shape_object
            what = repr(shape_object)
        except (ReferenceError, AttributeError):
            alive, what = False, "a deleted object"
        if not alive:
            raise ValueError("feature_edges: {} is no object of document {!r} (deleted, or of another document)".format(
                what, document.Name))
        cycle = None if grid is None else link_path(shape_object, grid)
        if cycle is not None:
            raise ValueError("feature_edges: {} depends on {} ({}): a dependency cycle".format(
                shape_object.Label, grid.Label, describe_path(cycle)))
        links.append((shape_object, names))
    return links


def make_volume_grid(volume_mesh_object, preset="euler", name="VolumeGrid", show=None, distribution="geometric",
                     method="bspline", feature_edges=None, feature_spacing=0.0, **options):
    """The B-spline blocks of a VolumeMesh evaluated on a stretched, point-matched grid. preset:
    'euler' (no wall clustering) or 'rans' (first cell for y+ ~ 1). options: those of
    bvmesh.grid.refine (normal_points, first_cell_height, y_plus, reynolds_number, growth,
    edge_points, tangential_spacing, target_cells, edge_end_spacing, max_turning_angle,
    max_spacing_jump, even_far_field); reynolds_number defaults to the volume mesh's. feature_edges: edges of
    document objects, [(object, "Edge3"), (object, ("Edge1", "Edge5")), ...] (a wing's leading
    edge in its CAD), where the tangential lines leaving them start at feature_spacing (model
    units; bvmesh.grid.refine's feature_spacings). method 'subdivision'
    (option steps, default 1): instead, the control volume of the same fit, wall level and
    marching options (bvmesh.volume.control_volume) refined by volumetric Catmull-Clark, its wall
    on the fitted surface, no wall clustering. show: the boundary faces whose grid lines are
    shown."""
    from bvmesh.features import volume_grid

    def fill(obj):
        obj.VolumeMesh = volume_mesh_object
        obj.Preset = preset
        obj.Distribution = distribution
        obj.Method = method
        _set_options(obj, _grid_option_table(volume_grid), options, "volume grid")
        obj.FeatureEdges = _feature_edge_links(feature_edges or [], volume_mesh_object.Document)
        obj.FeatureSpacing = feature_spacing
        _set_display(obj, volume_grid.DISPLAY, show)

    return _new_object(volume_grid.create, volume_mesh_object.Document, name, fill)


def set_grid_options(grid_object, preset=None, distribution=None, method=None, show=None, feature_edges=None,
                     feature_spacing=None, **options):
    """Changes the refinement of a VolumeGrid (as make_volume_grid; feature_edges [] clears them)
    and recomputes; on a failure the object keeps its previous options."""
    from bvmesh.features import volume_grid

    return _set_and_recompute(grid_object, _grid_option_table(volume_grid), volume_grid.DISPLAY,
                              options, show, "volume grid",
                              {"Preset": preset, "Distribution": distribution, "Method": method,
                               "FeatureEdges": None if feature_edges is None else _feature_edge_links(
                                   feature_edges, grid_object.Document, grid_object),
                               "FeatureSpacing": feature_spacing})


def grid_of(grid_object):
    """The grid of a VolumeGrid object for bvmesh.grid's functions: a bvmesh.RefinedGrid, or a
    bvmesh.StructuredGrid for method 'subdivision'."""
    from bvmesh.features import volume_grid

    return volume_grid.refined_grid(grid_object)


def span_station(grid_object, eta, span=None):
    """(point, normal) of the cut at fraction `eta` of the span of a VolumeGrid's wall: from the
    symmetry plane (its normal the span direction) to the wall's far end, or over `span` (e.g. a
    wing's reference semispan without its tip cap) when given; without a symmetry plane, across the
    wall's extent along y."""
    import FreeCAD

    from bvmesh import grid as grid_module
    from bvmesh.features import volume_grid

    wall = grid_module.wall_points(volume_grid.structured_grid(grid_object))
    fit = grid_object.VolumeMesh.Fit
    if fit.UseSymmetryPlane:
        origin = np.array(tuple(fit.SymmetryPoint))
        normal = np.array(tuple(fit.SymmetryNormal))
        normal = normal / np.linalg.norm(normal)
        if -((wall - origin) @ normal).min() > ((wall - origin) @ normal).max():
            normal = -normal  # the span runs to the side the wall is on
        low, high = 0.0, float(((wall - origin) @ normal).max()) if span is None else float(span)
    else:
        origin, normal = np.zeros(3), np.array([0.0, 1.0, 0.0])
        low, high = float(wall[:, 1].min()), float(wall[:, 1].max())
        if span is not None:
            high = low + float(span)
    point = origin + (low + eta * (high - low)) * normal
    return FreeCAD.Vector(*point), FreeCAD.Vector(*normal)


def make_grid_cut(grid_object, point=None, normal=None, eta=None, span=None, metric="block", name="GridCut"):
    """A cut plane through a VolumeGrid showing the grid lines around the section: through
    `point` with `normal`, or at span fraction `eta` of `span` (see span_station). metric colours the lines:
    'block' or a quality metric (scaled_jacobian, non_orthogonality, skewness, aspect_ratio,
    growth_ratio, determinant)."""
    import FreeCAD

    from bvmesh.features import grid_cut

    if eta is not None:
        if point is not None or normal is not None:
            raise ValueError("give either eta or point and normal, not both")
        point, normal = span_station(grid_object, float(eta), span)
    if point is None or normal is None:
        raise ValueError("the cut needs eta, or point and normal")

    def fill(obj):
        obj.Grid = grid_object
        obj.Point = FreeCAD.Vector(*point)
        obj.Normal = FreeCAD.Vector(*normal)
        obj.Metric = metric

    return _new_object(grid_cut.create, grid_object.Document, name, fill)


def make_mesh_quality(grid_object, histogram_path=None, name="MeshQuality"):
    """The quality of a VolumeGrid: summary table, key figures, and the histograms as PNG at
    histogram_path (when given)."""
    from bvmesh.features import mesh_quality

    import os

    def fill(obj):
        obj.Grid = grid_object
        if histogram_path:
            obj.HistogramFile = os.fspath(histogram_path)

    return _new_object(mesh_quality.create, grid_object.Document, name, fill)


def quality_report(quality_object):
    """The full report (per-cell arrays and summaries, bvmesh.grid.quality) of a MeshQuality object."""
    return quality_object.Proxy.report(quality_object)


def export_grid(source, path, file_format=None, force=False, name="Export", **flow_case):
    """Writes a VolumeGrid (cgns, openfoam, plot3d, vtk, or openfoam_case: a complete flow case)
    or the B-spline blocks (gismo, blocks; a VolumeMesh or a VolumeGrid's mesh) to `path`, as an
    Export object that writes again on recompute. file_format: from the path's ending when None
    (no ending: an OpenFOAM case directory's polyMesh). A grid with a non-positive cell is refused
    unless force=True. flow_case (openfoam_case only; the Export's "Flow case" properties): solver,
    mach, alpha_degrees, temperature (K), pressure (Pa; 0: from the volume mesh's Reynolds number
    on a rans grid, else 1e5), iterations, reference_length (mm), reference_area (mm^2),
    moment_point (mm); defaults: the ONERA M6 wind-tunnel case."""
    import os

    from bvmesh.features import grid_export

    file_format = file_format or grid_export.format_of_path(path)
    properties = {keyword: prop for prop, (keyword, _, _, _) in grid_export.FLOW_CASE_PROPERTIES.items()}
    unknown = sorted(set(flow_case) - set(properties))
    if unknown:
        raise ValueError("unknown flow case option {!r}; known: {}".format(unknown[0], ", ".join(properties)))
    if flow_case and file_format != "openfoam_case":
        raise ValueError("flow case options ({}) need file_format 'openfoam_case', not {!r}".format(
            ", ".join(sorted(flow_case)), file_format))

    def fill(obj):
        obj.Source = source
        obj.Format = file_format
        obj.Path = os.fspath(path)
        obj.Force = bool(force)
        for keyword, value in flow_case.items():
            setattr(obj, properties[keyword], 0.0 if keyword == "pressure" and value is None else value)

    return _new_object(grid_export.create, source.Document, name, fill)


def write_openfoam_case(grid, case_directory, **options):
    """An OpenFOAM case (mesh, fields, thermophysics, schemes, function objects) on a BVMesh grid
    or an existing polyMesh case directory: bvmesh.openfoam_case.write_case (its options: mach,
    alpha_degrees, model, length_unit, iterations, solver, ...). Returns the case directory."""
    from bvmesh import openfoam_case

    return openfoam_case.write_case(grid, case_directory, **options)

"""The surface fit: links a target and a control polyhedron, holds the fitting parameters and the
list of steps the user asked for (Steps), and recomputes the result by replaying those steps on a
fresh bvmesh.SurfaceFitter. Results (control mesh, convergence table, per-sample distances) are
properties, so they are saved, restored by Undo, and recomputed identically after reopening.

A step is one line of Steps:
    subdivide | project | approximate | correct <passes> | smooth <iterations> <lambda> <mu> | fit
`fit` runs the fitter to the tolerance with the parameters of the object. While the object keeps
the fitter of its last recompute, a recompute that only appends steps applies just those."""

import contextlib
import hashlib

from bvmesh import memory
from bvmesh.features import polyhedron as polyhedron_feature
from bvmesh.features.common import READ_ONLY, Proxy, add_property

TYPE = "BVMesh::SurfaceFit"
# Peak memory per control point of a fit level (18 kB measured on the M6 from level 4 to 5), with
# some room: the fitter makes no level the free memory cannot hold (max_control_points).
BYTES_PER_CONTROL_POINT = 24_000
SOLVERS = ["cholesky", "cgls"]
STEP_NAMES = ("subdivide", "project", "approximate", "correct", "smooth", "fit")


def default_run(fitter):
    """Runs the fitter (built with the fit's options) to the tolerance without progress display
    (scripts, freecadcmd)."""
    return fitter.run()


_runner = default_run


@contextlib.contextmanager
def fit_runner(runner):
    """Makes `runner(fitter) -> summary` run the `fit` steps while the block runs (the
    GUI shows progress and offers Cancel this way; the macro line stays the plain API call)."""
    global _runner
    previous, _runner = _runner, runner
    try:
        yield
    finally:
        _runner = previous


class FitCancelled(RuntimeError):
    """The fit step was cancelled: the recompute fails and the caller restores the document."""


def parse_step(line):
    """(name, arguments) of a step line; ValueError for anything else."""
    words = line.split()
    if not words or words[0] not in STEP_NAMES:
        raise ValueError("unknown fitting step '{}'; known: {}".format(line, ", ".join(STEP_NAMES)))
    name, args = words[0], words[1:]
    expected = {"correct": 1, "smooth": 3}.get(name, 0)
    if len(args) != expected:
        raise ValueError("step '{}' takes {} argument(s), got '{}'".format(name, expected, line))
    if name == "correct":
        return name, (int(args[0]),)
    if name == "smooth":
        return name, (int(args[0]), float(args[1]), float(args[2]))
    return name, ()


class SurfaceFitProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "Target", "Inputs", "The BVMesh target to fit to")
        add_property(obj, "App::PropertyLink", "Polyhedron", "Inputs", "The control polyhedron to start from")
        add_property(obj, "App::PropertyStringList", "Steps", "Inputs",
                     "Fitting steps replayed on every recompute (subdivide, project, approximate, "
                     "correct N, smooth N lambda mu, fit)")
        p = "Parameters"
        add_property(obj, "App::PropertyFloat", "Tolerance", p,
                     "Absolute max distance to reach (model units); 0: use RelativeTolerance", 0.0)
        add_property(obj, "App::PropertyFloat", "RelativeTolerance", p,
                     "Max distance to reach, relative to the target's bounding-box diagonal", 1e-4)
        add_property(obj, "App::PropertyInteger", "MaxLevel", p, "Subdivision levels at most", 4)
        add_property(obj, "App::PropertyInteger", "MaxCorrections", p,
                     "Parameter-correction passes per level at most", 4)
        add_property(obj, "App::PropertyFloat", "StagnationRatio", p,
                     "A pass not below this fraction of the previous max distance ends the level", 0.9)
        self.add_enumeration(obj, "Solver", p, "Least-squares solver", SOLVERS, "cholesky")
        for kind in ("Smooth", "Crease", "Boundary", "Corner"):
            add_property(obj, "App::PropertyFloat", "Weight" + kind, p,
                         "Least-squares weight of {} samples".format(kind.lower()), 1.0)
        add_property(obj, "App::PropertyBool", "UseSymmetryPlane", p,
                     "Keep boundary control points on the symmetry plane (half models)", False)
        add_property(obj, "App::PropertyVector", "SymmetryPoint", p, "A point of the symmetry plane")
        if "SymmetryNormal" not in obj.PropertiesList:
            add_property(obj, "App::PropertyVector", "SymmetryNormal", p, "Normal of the symmetry plane")
            import FreeCAD

            obj.SymmetryNormal = FreeCAD.Vector(0, 1, 0)
        add_property(obj, "App::PropertyBool", "ProjectAlongNormals", p,
                     "Project along limit normals instead of to the closest point", False)
        add_property(obj, "App::PropertyInteger", "CheckSamplesPerFace", p,
                     "Samples per face and direction of the two-sided distance check", 4)
        add_property(obj, "App::PropertyInteger", "CheckTargetSubdivisions", p,
                     "CAD points of the two-sided check per side of a tessellation triangle (1: its nodes)", 1)
        add_property(obj, "App::PropertyInteger", "CorrectionPasses", p,
                     "Passes of the Parameter correction command", 2)
        add_property(obj, "App::PropertyInteger", "SmoothIterations", p, "Iterations of the Smooth command", 10)
        add_property(obj, "App::PropertyFloat", "SmoothLambda", p, "Taubin lambda of the Smooth command", 0.6307)
        add_property(obj, "App::PropertyFloat", "SmoothMu", p, "Taubin mu of the Smooth command", -0.6732)
        r = "Result"
        for name, type_name, doc in (
            ("Level", "App::PropertyInteger", "Subdivision level of the control mesh"),
            ("ControlVertices", "App::PropertyVectorList", "Control points of the fitted mesh (#V)"),
            ("ControlFaceSizes", "App::PropertyIntegerList", "Vertex count per face of the fitted mesh"),
            ("ControlFaceIndices", "App::PropertyIntegerList", "Vertex ids of the fitted mesh's faces"),
            ("ControlCreases", "App::PropertyIntegerList", "Crease vertex pairs of the fitted mesh, flattened"),
            ("ControlCorners", "App::PropertyIntegerList", "Corner vertices of the fitted mesh"),
            ("StopReason", "App::PropertyString", "Why the last fit step stopped"),
            ("StopDetail", "App::PropertyString",
             "Which distance was above the tolerance at the stop, and where (empty when converged)"),
            ("AbsoluteTolerance", "App::PropertyFloat", "The tolerance in model units"),
            ("MaxDistance", "App::PropertyFloat", "Max distance of the limit samples to the target"),
            ("RmsDistance", "App::PropertyFloat", "RMS distance of the limit samples to the target"),
            ("SampleDistances", "App::PropertyFloatList", "Distance of each limit sample to the target"),
            ("HistoryLevel", "App::PropertyIntegerList", "Convergence table: level of each pass"),
            ("HistoryCorrection", "App::PropertyIntegerList", "Convergence table: correction of each pass"),
            ("HistoryControlPoints", "App::PropertyIntegerList", "Convergence table: control points"),
            ("HistoryMax", "App::PropertyFloatList", "Convergence table: max sample distance"),
            ("HistoryRms", "App::PropertyFloatList", "Convergence table: RMS sample distance"),
            ("HistoryLimitToTarget", "App::PropertyFloatList",
             "Convergence table: two-sided check, limit surface to target (-1: not checked)"),
            ("HistoryTargetToLimit", "App::PropertyFloatList",
             "Convergence table: two-sided check, target to limit surface (-1: not checked)"),
            ("HistoryTargetToLimitBeyondCad", "App::PropertyFloatList",
             "Convergence table: target to limit surface beyond the CAD's own tolerance at each "
             "target point, the side the stop rule holds against the tolerance (-1: not checked)"),
        ):
            add_property(obj, type_name, name, r, doc, mode=READ_ONLY)

    # -- recompute ------------------------------------------------------------------------------

    def options(self, obj):
        """The fitter's keyword options from the parameter properties."""
        options = {
            "tolerance": obj.Tolerance,
            "relative_tolerance": obj.RelativeTolerance,
            "max_level": obj.MaxLevel,
            "max_corrections": obj.MaxCorrections,
            "stagnation_ratio": obj.StagnationRatio,
            "solver": obj.Solver,
            "weights": {"smooth": obj.WeightSmooth, "crease": obj.WeightCrease,
                        "boundary": obj.WeightBoundary, "corner": obj.WeightCorner},
            "project_along_normals": obj.ProjectAlongNormals,
            "check_samples_per_face": obj.CheckSamplesPerFace,
            "check_target_subdivisions": obj.CheckTargetSubdivisions,
            "symmetry_plane": None,
        }
        if obj.UseSymmetryPlane:
            point, normal = obj.SymmetryPoint, obj.SymmetryNormal
            options["symmetry_plane"] = ((point.x, point.y, point.z), (normal.x, normal.y, normal.z))
        return options

    def _inputs_key(self, obj):
        """Identifies everything but Steps that the result depends on."""
        poly = obj.Polyhedron
        data = repr((
            obj.Target.BrepHash, obj.Target.RelativeDeflection, obj.Target.SharpAngle,
            [(v.x, v.y, v.z) for v in poly.Vertices], list(poly.FaceSizes), list(poly.FaceIndices),
            list(poly.Creases), list(poly.Corners), list(poly.FeatureCurves), list(poly.EdgeCurves),
            list(poly.VertexCadVertices), sorted(self.options(obj).items(), key=lambda item: item[0]),
        ))
        return hashlib.sha1(data.encode()).hexdigest()

    def _new_fitter(self, obj, max_level=None):
        from bvmesh import load_core

        target = obj.Target.Proxy.core_target(obj.Target)
        mesh = polyhedron_feature.control_mesh(obj.Polyhedron)
        options = self.options(obj)
        if max_level is not None:
            options["max_level"] = max_level
        # Set here, not among the options that key the result: the budget follows the free memory.
        options["max_control_points"] = min(memory.budget(BYTES_PER_CONTROL_POINT), 2**31 - 1)
        return load_core().SurfaceFitter(target, mesh, polyhedron_feature.feature_map(obj.Polyhedron), **options)

    def wall_at_level(self, obj, level):
        """A function giving the control mesh of the same fit stopped at `level` (below the
        object's own): the properties are read now, the refit runs when the function is called
        (possibly in a worker thread); the mesh is kept while the inputs stay the same."""
        key = (self._inputs_key(obj), level)
        cached = getattr(self, "_level_mesh", None)
        if cached is not None and cached[0] == key:
            return lambda: cached[1]
        fitter = self._new_fitter(obj, max_level=level)

        def refit():
            default_run(fitter)
            self._level_mesh = (key, fitter.mesh)  # one level at a time is what the volume stage asks for
            return fitter.mesh

        return refit

    def _apply(self, obj, fitter, line, summary):
        name, args = parse_step(line)
        if name == "fit":
            result = _runner(fitter)
            if result["reason"] == "cancelled":
                raise FitCancelled("the fit was cancelled")
            summary["reason"] = result["reason"]
            summary["detail"] = result["detail"]
            return
        if name == "subdivide":
            fitter.subdivide()
        elif name == "project":
            fitter.project()
        elif name == "approximate":
            fitter.approximate()
        elif name == "correct":
            fitter.correct_parameters(*args)
        elif name == "smooth":
            fitter.smooth(*args)
        fitter.record(False)

    def compute(self, obj):
        if obj.Target is None or obj.Polyhedron is None:
            raise ValueError("the surface fit needs a Target and a Polyhedron")
        steps = list(obj.Steps)
        for line in steps:
            parse_step(line)
        key = self._inputs_key(obj)
        state = getattr(self, "_state", None)
        try:
            if state is not None and state["key"] == key and steps[:len(state["applied"])] == state["applied"]:
                fitter, applied, summary, projection = (state[k] for k in ("fitter", "applied", "summary", "projection"))
            else:
                self._state = None
                fitter, applied, summary = self._new_fitter(obj), [], {"reason": "", "detail": ""}
                fitter.record(False)
                projection = fitter.project()
            # Every step is followed by the same calls whether it is replayed or appended, so
            # both ways give identical results (projections warm-start from the previous ones).
            for line in steps[len(applied):]:
                self._apply(obj, fitter, line, summary)
                projection = fitter.project()
                applied = applied + [line]
        except BaseException:
            self._state = None  # the fitter may be half-way through a step
            raise
        self._state = {"key": key, "fitter": fitter, "applied": applied, "summary": summary,
                       "projection": projection}
        self._store(obj, fitter, projection, summary)

    def _store(self, obj, fitter, projection, summary):
        import FreeCAD

        mesh = fitter.mesh
        obj.Level = fitter.level
        obj.ControlVertices = [FreeCAD.Vector(*map(float, p)) for p in mesh.vertices]
        obj.ControlFaceSizes = [int(s) for s in mesh.face_sizes]
        obj.ControlFaceIndices = [int(i) for i in mesh.face_indices]
        obj.ControlCreases = [int(i) for pair in mesh.creases for i in pair]
        obj.ControlCorners = [int(i) for i in mesh.corners]
        obj.StopReason = summary["reason"]
        obj.StopDetail = summary["detail"]
        obj.AbsoluteTolerance = fitter.absolute_tolerance
        distances = [float(d) for d in projection["distances"]]
        obj.SampleDistances = distances
        obj.MaxDistance = max(distances) if distances else 0.0
        obj.RmsDistance = (sum(d * d for d in distances) / len(distances)) ** 0.5 if distances else 0.0
        history = fitter.history
        obj.HistoryLevel = [r["level"] for r in history]
        obj.HistoryCorrection = [r["correction"] for r in history]
        obj.HistoryControlPoints = [r["control_points"] for r in history]
        obj.HistoryMax = [r["max_distance"] for r in history]
        obj.HistoryRms = [r["rms_distance"] for r in history]
        obj.HistoryLimitToTarget = [-1.0 if r["limit_to_target"] is None else r["limit_to_target"] for r in history]
        obj.HistoryTargetToLimit = [-1.0 if r["target_to_limit"] is None else r["target_to_limit"] for r in history]
        obj.HistoryTargetToLimitBeyondCad = [-1.0 if r["target_to_limit_beyond_cad"] is None
                                             else r["target_to_limit_beyond_cad"] for r in history]
        obj.Shape = polyhedron_feature.wireframe(mesh.vertices, mesh.edges)


def result_mesh(obj):
    """The fitted control mesh of a SurfaceFit object as a bvmesh.ControlMesh."""
    from bvmesh import load_core

    faces = polyhedron_feature.unflatten_faces(obj.ControlFaceSizes, obj.ControlFaceIndices)
    return load_core().ControlMesh([(v.x, v.y, v.z) for v in obj.ControlVertices], faces,
                                   creases=polyhedron_feature.pairs(obj.ControlCreases) or None,
                                   corners=list(obj.ControlCorners) or None)


def wall_at_level(obj, level):
    """(function giving the control mesh, level) of a SurfaceFit object for the volume stage: the
    fitted mesh when level is -1 or the fit's own level; for a lower level, the same fit run to that
    level (only for a fit made by one Fit to tolerance step, whose intermediate levels that run
    reproduces). Everything is read from the object now; the function may run in another thread."""
    if level < 0 or level == obj.Level:
        mesh = result_mesh(obj)
        return (lambda: mesh), obj.Level
    if level > obj.Level:
        raise ValueError("{} is at level {}: there is no wall at level {}".format(obj.Label, obj.Level, level))
    if list(obj.Steps) != ["fit"]:
        raise ValueError("a wall below the fit's level needs a fit made by one 'Fit to tolerance' step; {} has "
                         "steps {}".format(obj.Label, list(obj.Steps)))
    return obj.Proxy.wall_at_level(obj, level), level


def convergence_table(obj):
    """The convergence table of a SurfaceFit object: one dict per pass."""
    rows = []
    beyond_cad = list(obj.HistoryTargetToLimitBeyondCad)  # empty in documents saved before it existed
    for i, level in enumerate(obj.HistoryLevel):
        check = (obj.HistoryLimitToTarget[i], obj.HistoryTargetToLimit[i],
                 beyond_cad[i] if i < len(beyond_cad) else -1.0)
        rows.append({
            "level": level, "correction": obj.HistoryCorrection[i],
            "control_points": obj.HistoryControlPoints[i],
            "max_distance": obj.HistoryMax[i], "rms_distance": obj.HistoryRms[i],
            "limit_to_target": None if check[0] < 0 else check[0],
            "target_to_limit": None if check[1] < 0 else check[1],
            "target_to_limit_beyond_cad": None if check[2] < 0 else check[2],
        })
    return rows


def create(doc, name="SurfaceFit"):
    obj = doc.addObject("Part::FeaturePython", name)
    SurfaceFitProxy(obj)
    return obj

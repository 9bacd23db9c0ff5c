"""The whole job on a CAD file, as a batch run: the body's faces as the target, a template
polyhedron placed on them, the fit to tolerance, the B-spline shell (STEP), the volume mesh, its
solver grid, quality, solver files, pictures and reports, all built as the workbench's objects in
a FreeCAD document that is saved beside them. `python3 -m bvmesh mesh` runs it; the main job
(bvmesh.example) is this on the bundled ONERA M6.

What is meshed: on a flow domain's CAD (a box or sphere with the body cut out) the body, inside
that domain; with half_model=True the shape without its symmetry-plane face (the largest planar
face with the whole shape on one side, e.g. a half wing's root), on that plane; otherwise the
whole shape, a closed body.

Files in the output folder, named after `name`: NAME.FCStd, NAME_surface.step,
NAME_convergence.png, NAME_report.md; with the volume stage NAME_volume_report.md,
NAME_quality.png, NAME_cut.png and the grid in the formats asked (NAME.cgns, NAME_openfoam/,
NAME.xyz, NAME.vtm, NAME.xml, NAME.blocks)."""

import math
import os
import shutil
import subprocess
import time

from bvmesh import api, load_core

# Export format -> the file (or folder) name's ending after NAME.
FORMAT_ENDINGS = {"cgns": ".cgns", "openfoam": "_openfoam", "plot3d": ".xyz", "vtk": ".vtm", "gismo": ".xml",
                  "blocks": ".blocks"}
DEFAULT_FORMATS = ("cgns", "openfoam")
PRESETS = ("euler", "rans")


def check_mesh(case):
    """checkMesh's verdict on an OpenFOAM case ('Mesh OK.' or the failed checks), or why it did
    not run. checkMesh exits 0 whatever it finds, so its output is read."""
    if shutil.which("checkMesh") is None:
        return "checkMesh not installed (Debian package openfoam)"
    environment = dict(os.environ, WM_PROJECT_DIR=os.environ.get("WM_PROJECT_DIR", "/usr/share/openfoam"))
    result = subprocess.run(["checkMesh", "-case", case], env=environment, capture_output=True, text=True,
                            timeout=900)
    output = result.stdout + result.stderr
    if "Mesh OK." in output:
        return "Mesh OK."
    failed = [line.strip() for line in output.splitlines() if line.strip().startswith("***")]
    return "; ".join(failed) or "no verdict (exit {}): {}".format(result.returncode, output[-300:])


def wall_distance(grid_object):
    """Largest distance of the grid's wall points from the CAD faces of its fit's target."""
    from bvmesh import grid

    target = grid_object.VolumeMesh.Fit.Target
    return float(target.Proxy.core_target(target).project(grid.wall_points(api.grid_of(grid_object)))["distances"].max())


def _extent_in_plane(shape, plane):
    """Largest extent of the shape's edges that lie in `plane` ((point), (normal)), measured on
    points along them: a half body's outline on its symmetry plane. None when no edge lies in it."""
    import FreeCAD

    point, normal = FreeCAD.Vector(*plane[0]), FreeCAD.Vector(*plane[1]).normalize()
    tolerance = 1e-7 * shape.BoundBox.DiagonalLength
    box = FreeCAD.BoundBox()
    for edge in shape.Edges:
        if edge.Degenerated:  # a pole's seam point
            continue
        samples = edge.discretize(65)
        if all(abs((s - point).dot(normal)) <= max(tolerance, edge.Tolerance) for s in samples):
            for s in samples:
                box.add(s)
    return max(box.XLength, box.YLength, box.ZLength) if box.isValid() else None


def _body_target(doc, cad, half_model):
    """(Target object, what it holds in words, reference length or None, symmetry plane or None):
    the reference length is the body's largest extent on its symmetry plane in a half model (the
    symmetry face's, or in a flow domain or a half model without its symmetry face the outline of
    the body's open side: a wing's root chord, a body's length), else left to the caller; the plane
    as api.symmetry_plane_guess gives it."""
    if not half_model:
        # A Target on all faces finds a flow domain's body itself (FlowDomain names the domain).
        target = api.make_target(doc, cad)
        plane = api.symmetry_plane_guess(target)
        if target.FlowDomain:
            return target, "the body inside the CAD's flow domain ({}, {} faces)".format(
                target.FlowDomain, len(target.Shape.Faces)), plane and _extent_in_plane(target.Shape, plane), plane
        if plane is not None:  # an open half model: its open side lies on the symmetry plane
            return target, "all {} faces of the CAD, a half model open on its symmetry plane".format(
                len(cad.Shape.Faces)), _extent_in_plane(target.Shape, plane), plane
        return target, "all {} faces of the CAD".format(len(cad.Shape.Faces)), None, None
    if api.flow_domain_of(cad.Shape) is not None:
        raise ValueError("the CAD is a flow domain, whose symmetry plane the domain itself gives: "
                         "leave out the half model")
    _, symmetry_face, _ = load_core().remove_symmetry_face(cad.Shape.exportBrepToString())
    faces = ["Face{}".format(i + 1) for i in range(len(cad.Shape.Faces)) if i != symmetry_face]
    box = _tight_box(cad.Shape.Faces[symmetry_face])
    target = api.make_target(doc, cad, faces=faces)
    return (target, "the CAD's faces without Face{}, its symmetry-plane face".format(symmetry_face + 1),
            max(box.XLength, box.YLength, box.ZLength), api.symmetry_plane_guess(target))


def _tight_box(shape):
    """The shape's bounding box from its surfaces themselves: Shape.BoundBox is taken from the
    B-spline poles, which a stretched sphere's lie far outside (a 4 x 1.4 x 1 ellipsoid's box was
    6 long)."""
    return shape.optimalBoundingBox()


def _reference_length(target, given):
    """The given reference length, or the target's largest extent (the volume stage's default)."""
    if given is not None:
        if not (math.isfinite(given) and given > 0):
            raise ValueError("the reference length must be a positive number, got {!r}".format(given))
        return float(given)
    box = _tight_box(target.Shape)
    return max(box.XLength, box.YLength, box.ZLength)


def _report_lines(title, what, fit, shell, reference_length, tolerance, seconds, files):
    rows = api.convergence_table(fit)
    lines = [
        "# {}: surface fit".format(title),
        "",
        "Target: {}; reference length {:.4g}; tolerance {:.3g} ({:.0e} of the reference length).".format(
            what, reference_length, tolerance, tolerance / reference_length),
        "Stop: **{}** at level {} after {:.1f} s; {} control points.{}".format(
            fit.StopReason, fit.Level, seconds, len(fit.ControlVertices),
            " " + fit.StopDetail[:1].upper() + fit.StopDetail[1:] + "." if fit.StopDetail else ""),
        "'converged' means the limit samples and the two-sided check (denser limit points to the CAD, "
        "CAD tessellation nodes to the limit surface) are both within the tolerance; a CAD node on an "
        "edge counts beyond the CAD's own tolerance there (OCCT's edge tolerance: the faces meeting at "
        "that edge may be that far apart).",
        "",
        "| level | correction | control points | max distance | RMS distance | max / reference length | "
        "limit -> target | target -> limit | beyond CAD tolerance |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        def checked(value):
            return "-" if value is None else "{:.3e}".format(value)
        lines.append("| {level} | {correction} | {control_points} | {max_distance:.3e} | {rms_distance:.3e} | "
                     "{ratio:.2e} | {lt} | {tl} | {tb} |".format(ratio=row["max_distance"] / reference_length,
                                                                lt=checked(row["limit_to_target"]),
                                                                tl=checked(row["target_to_limit"]),
                                                                tb=checked(row["target_to_limit_beyond_cad"]), **row))
    solid = shell.Shape
    lines += [
        "",
        "B-spline surface ({}): {} faces, valid: {}, closed shells: {}, free edges: {}; largest distance from "
        "the fitted limit surface {:.3g} ({} the tolerance), largest normal jump across smooth face borders "
        "{:.2g} degrees.".format(
            "charts tangent-continuous across their borders" if shell.TangentContinuity else "charts on their own",
            len(solid.Faces), solid.isValid(), sum(1 for s in solid.Shells if s.isClosed()),
            len([e for e in solid.Edges if len(solid.ancestorsOfType(e, type(solid.Faces[0]))) == 1]),
            shell.MaxDistance, "within" if shell.MaxDistance <= tolerance else "above", shell.MaxKinkDegrees),
        "",
        "Files: " + ", ".join(os.path.basename(f) for f in files),
    ]
    return lines


def _smoothed_layers(vm):
    count = vm.FarfieldLayersSmoothed  # 0 unless the scheme is hyperbolic
    if count == 0:
        return ""
    return " ({} layer{} by the smoothed step where the hyperbolic one would fold)".format(
        count, "" if count == 1 else "s")


def _domain_words(vm):
    shape = vm.Fit.Target.FlowDomain if vm.Domain == "cad" else vm.Domain
    return "{} {} {:.6g} ({:.1f} reference lengths)".format(
        shape, "of radius" if shape == "sphere" else "at a distance of", vm.FarfieldDistanceUsed,
        vm.FarfieldDistanceUsed / vm.ReferenceLengthUsed)


def _grid_line(grid_object):
    if grid_object.Method == "subdivision":
        return ("Grid: the fit's control mesh marched (the volume mesh's options) and refined by {} volumetric "
                "Catmull-Clark step(s), the wall on the fitted surface, no wall law; {} cells, {} points over the "
                "blocks, {} points on the wall-normal lines.".format(
                    grid_object.SubdivisionSteps, grid_object.CellCount, grid_object.PointCount,
                    grid_object.NormalPointsUsed))
    folds = ("" if not grid_object.FoldRefinements else
             " The blocks with a folded cell took {} times their tangential cells (sampled coarser, a block whose "
             "layers wrap round a corner of the wall folded).".format(2 ** grid_object.FoldRefinements))
    return ("Grid: preset {}, {} cells, {} points over the blocks, {} points on the wall-normal lines, first cell "
            "height {:.4g} .. {:.4g}, largest wall-normal growth {:.4g}.{}".format(
                grid_object.Preset, grid_object.CellCount, grid_object.PointCount, grid_object.NormalPointsUsed,
                grid_object.FirstCellHeightMin, grid_object.FirstCellHeightMax, grid_object.GrowthMax, folds))


def _marching_words(vm):
    if vm.MarchingLevelUsed == vm.WallLevelUsed:
        return ""
    how = ("the level asked for" if vm.MarchingLevel != -1 else
           "the automatic marching level: the first that holds of the highest with at most {} control points, "
           "the lower ones, then the finer ones".format(vm.MarchingPointLimit))
    return ", layers marched from the fit refitted to level {} and carried onto it ({}; docs/volume.md)".format(
        vm.MarchingLevelUsed, how)


def _volume_report(title, vm, grid_object, quality, written, case, verdict, seconds, fans=None):
    lines = [
        "# {}: volume mesh".format(title),
        "",
        "Wall: the surface fit at level {}{}; the grid's wall points lie within {:.3e} of the CAD faces (fit "
        "tolerance {:.3g}).".format(vm.WallLevelUsed, _marching_words(vm), wall_distance(grid_object),
                                    vm.Fit.Tolerance),
        "Blocks: {} tricubic B-spline blocks, {} control layers; boundary layer {:.4g} thick (reference length "
        "{:.4g}, Re {:.4g}); far field: {}, marched {}{}.".format(
            vm.BlockCount, vm.ControlLayers, vm.BoundaryLayerThicknessUsed, vm.ReferenceLengthUsed,
            vm.ReynoldsNumber, _domain_words(vm), vm.FarfieldScheme, _smoothed_layers(vm)),
        _grid_line(grid_object),
    ] + ([fans] if fans else []) + [
        "Cells with a non-positive scaled Jacobian: {}; with a face above 70 degrees of non-orthogonality: "
        "{}; with a determinant below 1e-3 (which checkMesh -allGeometry fails): {}.".format(
            quality.NonPositiveCells, quality.CellsAbove70Degrees, quality.SmallDeterminantCells),
    ]
    if case:
        lines.append("checkMesh on {}: {}".format(os.path.basename(case), verdict))
    lines += [
        "",
        quality.Table.rstrip(),
        "",
        "Files: {}; volume stage {:.1f} s.".format(
            ", ".join(os.path.basename(path) + ("/" if os.path.isdir(path) else "") for path in written), seconds),
    ]
    return lines


def body_cut(grid_object, path, title):
    """A picture of the grid in the plane through the middle of the body's bounding box, normal to
    the symmetry plane on a half model (a section at mid-span) and else to the box's longest side:
    the whole domain and the body. Returns (path, point, normal)."""
    from bvmesh import grid

    fit = grid_object.VolumeMesh.Fit
    box = _tight_box(fit.Target.Shape)
    if fit.UseSymmetryPlane:
        normal = tuple(abs(c) for c in fit.SymmetryNormal)
    else:
        lengths = (box.XLength, box.YLength, box.ZLength)
        normal = tuple(1.0 if k == lengths.index(max(lengths)) else 0.0 for k in range(3))
    across = max(range(3), key=lambda k: abs(normal[k]))  # the axis the plane is most nearly normal to
    point = (box.Center.x, box.Center.y, box.Center.z)
    in_plane = sorted(sorted(range(3), key=lambda k: abs(normal[k]))[:2])
    low = [(box.XMin, box.YMin, box.ZMin)[k] for k in in_plane]
    high = [(box.XMax, box.YMax, box.ZMax)[k] for k in in_plane]
    size = max(h - l for l, h in zip(low, high))
    centre = [0.5 * (l + h) for l, h in zip(low, high)]
    radius = grid_object.VolumeMesh.FarfieldDistanceUsed
    views = [
        ("whole domain", ((centre[0] - radius, centre[1] - radius), (centre[0] + radius, centre[1] + radius))),
        ("body", ((centre[0] - 0.65 * size, centre[1] - 0.65 * size), (centre[0] + 0.65 * size, centre[1] + 0.65 * size))),
    ]
    grid.plot_cut(api.grid_of(grid_object), point, normal, path, views,
                  title="{}: grid at {} = {:.4g}".format(title, "xyz"[across], point[across]))
    return path, point, normal


def run_volume(fit, files, title, reference_length, reynolds_number, preset="euler", target_cells=1_000_000,
               formats=DEFAULT_FORMATS, cut=None, log=print, grid_method="bspline", subdivision_steps=1,
               volume_options=None, grid_options=None):
    """The volume stage on a fitted target: volume mesh, grid (`preset` at about `target_cells`
    cells, or the control volume refined by `subdivision_steps` volumetric Catmull-Clark steps
    with grid_method 'subdivision'), quality, a cut, the grid in `formats` (checkMesh on the
    OpenFOAM case), pictures and report, into `files` (the keys 'quality', 'cut', 'volume_report'
    and one per format). cut: a function (grid object, path) -> (path, point, normal) for the cut
    picture, body_cut's by default. volume_options, grid_options: more keywords of
    api.make_volume_mesh and api.make_volume_grid (bvmesh.grid.refine's options). Returns the
    volume objects by name and checkMesh's verdict."""
    started = time.time()
    stage = time.time()
    mesh_options = {"reference_length": reference_length}
    if reynolds_number:
        mesh_options["reynolds_number"] = reynolds_number
    vm = api.make_volume_mesh(fit, **dict(mesh_options, **(volume_options or {})))
    log("volume mesh: {} blocks, {} control layers, far field {:.0f} ({:.1f} s)".format(
        vm.BlockCount, vm.ControlLayers, vm.FarfieldDistanceUsed, time.time() - stage))
    stage = time.time()
    if grid_method == "subdivision":
        grid_object = api.make_volume_grid(vm, method="subdivision", steps=subdivision_steps, show=("wall",),
                                           **(grid_options or {}))
        what = "{} subdivision step(s) of the control volume".format(subdivision_steps)
    else:
        refine_options = dict(grid_options or {})
        if not {"edge_points", "tangential_spacing", "target_cells"} & set(refine_options):
            refine_options["target_cells"] = target_cells  # the tangential counts, unless the options set them
        grid_object = api.make_volume_grid(vm, preset, show=("wall",), **refine_options)
        what = preset
    log("grid: {}, {} cells ({:.1f} s)".format(what, grid_object.CellCount, time.time() - stage))
    stage = time.time()
    quality = api.make_mesh_quality(grid_object, histogram_path=files["quality"])
    log("quality: min scaled Jacobian {:.3g}, max non-orthogonality {:.1f} ({:.1f} s)".format(
        quality.MinScaledJacobian, quality.MaxNonOrthogonality, time.time() - stage))
    fans = None
    if "knife_edge_fans" not in (volume_options or {}) and grid_method != "subdivision":
        fans = _fans_where_skew(vm, quality, log)
    stage = time.time()
    _, point, normal = (cut or (lambda g, p: body_cut(g, p, title)))(grid_object, files["cut"])
    cut_object = api.make_grid_cut(grid_object, point=point, normal=normal)
    log("cut: {} segments ({:.1f} s)".format(cut_object.SegmentCount, time.time() - stage))
    stage = time.time()
    for file_format in formats:
        source = vm if file_format in ("gismo", "blocks") else grid_object
        api.export_grid(source, files[file_format], file_format=file_format,
                        name="Export" + {"cgns": "CGNS", "openfoam": "OpenFOAM"}.get(file_format, file_format.capitalize()))
    log("files: {} ({:.1f} s)".format(", ".join(formats), time.time() - stage))
    case = files.get("openfoam") if "openfoam" in formats else None
    verdict = None
    if case:
        stage = time.time()
        verdict = check_mesh(case)
        log("checkMesh: {} ({:.1f} s)".format(verdict, time.time() - stage))
    lines = _volume_report(title, vm, grid_object, quality, [files[f] for f in formats], case, verdict,
                           time.time() - started, fans)
    with open(files["volume_report"], "w") as report:
        report.write("\n".join(lines) + "\n")
    return {"volume_mesh": vm, "grid": grid_object, "quality": quality, "cut": cut_object, "check_mesh": verdict,
            "knife_edge_fans": bool(vm.KnifeEdgeFans), "knife_edge_fans_tried": fans is not None}


# checkMesh's largest skewness of an internal face (its default maxInternalSkewness).
CHECKMESH_MAX_SKEWNESS = 4.0


def _fans_where_skew(vm, quality, log):
    """Where the grid has faces more skew than checkMesh passes, the volume mesh again with its
    knife edges cut open (knife_edge_fans): an O-grid's first cells at a sharp trailing edge are
    skew (4-15 on every FreeCAD-lofted wing measured; docs/hostile_input.md), a fan's prisms are
    not. The fans are kept when their grid passes that limit with every cell positive, else the
    O-grid is put back (a wall without knife edges gets the same blocks). vm's grid and quality
    are recomputed with it. Returns the report's sentence on it, or None where the grid passed."""
    skew = quality.MaxSkewness
    if vm.KnifeEdgeFans or skew <= CHECKMESH_MAX_SKEWNESS:
        return None
    blocks = vm.BlockCount
    stage = time.time()
    try:
        api.set_volume_options(vm, knife_edge_fans=True)
    except RuntimeError as error:  # the O-grid is back (set_volume_options undoes a failed change)
        failed = "the volume mesh with knife-edge fans failed ({}); the O-grid kept".format(error)
    else:
        if vm.BlockCount == blocks:
            failed = "the wall has no knife edge to cut open"
        elif quality.MaxSkewness > CHECKMESH_MAX_SKEWNESS or quality.NonPositiveCells > 0:
            failed = "with knife-edge fans the grid's largest skewness is {:.3g} and {} cells are not positive".format(
                quality.MaxSkewness, quality.NonPositiveCells)
        else:
            failed = None
        if failed:
            api.set_volume_options(vm, knife_edge_fans=False)
    words = ("Largest skewness {:.3g} on the O-grid, above checkMesh's {:g}: {}.".format(
        skew, CHECKMESH_MAX_SKEWNESS, failed) if failed else
        "Knife edges cut open with fans of prisms (knife_edge_fans, chosen because the O-grid's largest skewness, "
        "{:.3g}, is above checkMesh's {:g}; with the fans {:.3g}).".format(
            skew, CHECKMESH_MAX_SKEWNESS, quality.MaxSkewness))
    log("knife-edge fans: {} ({:.1f} s)".format("kept" if not failed else "not kept", time.time() - stage))
    return words


def run(cad_path, output_dir, template, name=None, title=None, template_parameters=None, half_model=False,
        reference_length=None, relative_tolerance=1e-5, max_level=5, reynolds_number=None, volume=True,
        preset="euler", target_cells=1_000_000, formats=DEFAULT_FORMATS, cut=None, log=print,
        grid_method="bspline", subdivision_steps=1, file_names=None, volume_options=None, grid_options=None):
    """Runs the whole job on the CAD file and returns a dict: 'files' (what was written, by kind),
    the fit's 'stop_reason', 'stop_detail', 'level', 'max_distance', the 'reference_length' and the
    fit's 'tolerance', and with the volume stage its objects and 'check_mesh' (unmet_goals() says
    what of these missed). file_names: a file's name by kind instead of the NAME-based
    one (e.g. {'cut': 'M6_cut_eta044.png'}). volume_options, grid_options: as run_volume takes
    them. template: a polyhedron template's name (bvmesh.polyhedra.template_names()) with its
    parameters; the fit's tolerance is relative_tolerance times the reference length (given, or on
    a half model the body's largest extent on its symmetry plane, or a wing's root chord, or the
    body's largest extent). reynolds_number: for the boundary layer's estimate (None: the volume
    stage's default). volume=False stops after the surface stage. The document and the
    surface stage's files are written even when the volume stage fails."""
    import FreeCAD

    if preset not in PRESETS:
        raise ValueError("preset must be one of {}, got {!r}".format(", ".join(PRESETS), preset))
    unknown = [f for f in formats if f not in FORMAT_ENDINGS]
    if unknown:
        raise ValueError("unknown format {!r}; known: {}".format(unknown[0], ", ".join(FORMAT_ENDINGS)))
    if volume:
        api.check_option_names(volume_options, grid_options)
    if not os.path.isfile(cad_path):
        raise ValueError("no CAD file at {}".format(cad_path))
    name = name or os.path.splitext(os.path.basename(cad_path))[0]
    title = title or name
    if os.path.basename(name) != name or name in ("", ".", ".."):
        raise ValueError("name {!r} is not a file name (the files go into the output folder)".format(name))
    try:
        os.makedirs(output_dir, exist_ok=True)
    except OSError as error:
        raise ValueError("cannot create the output folder {}: {}".format(output_dir, error.strerror)) from None
    started = time.time()
    doc = FreeCAD.newDocument(name)
    try:
        cad = api.import_cad(doc, cad_path, name=os.path.splitext(os.path.basename(cad_path))[0])
        target, what, symmetry_length, symmetry_plane = _body_target(doc, cad, half_model)
        log("target: {}".format(what))
        try:
            polyhedron = api.make_polyhedron_from_template(doc, target, template, **(template_parameters or {}))
        except load_core().InvalidInputError as error:
            if half_model or symmetry_plane is not None or "symmetry plane" not in str(error):
                raise
            # A closed half model (its symmetry-plane face in the file) under a half template.
            raise load_core().InvalidInputError(
                "{}; to leave out a half model's symmetry-plane face, run with --half-model "
                "(pipeline.run's half_model=True)".format(error)) from error
        log("polyhedron: " + polyhedron.Summary)
        # A wing's reference length is its root chord (a full wing's largest extent is its span).
        length = _reference_length(target, reference_length or symmetry_length or polyhedron.RootChord or None)
        tolerance = relative_tolerance * length
        fit = api.make_surface_fit(doc, target, polyhedron, symmetry_plane=symmetry_plane,
                                   tolerance=tolerance, max_level=max_level, check_samples_per_face=4)
        api.fit_to_tolerance(fit)
        seconds = time.time() - started
        log("fit: {} at level {}, max distance {:.3e} ({:.2e} of the reference length), RMS {:.3e}".format(
            fit.StopReason, fit.Level, fit.HistoryMax[-1], fit.HistoryMax[-1] / length, fit.HistoryRms[-1]))
        # Tangent-continuous charts: on the M6 at its converged level the normal jumps across chart
        # borders fall from 3.4 to 0.61 degrees (docs/fitting.md), within the tolerance.
        shell = api.make_bspline_shell(fit, tangent_continuity=True)
        files = {
            "document": os.path.join(output_dir, name + ".FCStd"),
            "step": os.path.join(output_dir, name + "_surface.step"),
            "plot": os.path.join(output_dir, name + "_convergence.png"),
            "report": os.path.join(output_dir, name + "_report.md"),
        }
        api.export_step(shell, files["step"])
        api.plot_convergence(fit, files["plot"], title=title)
        log("surface stage: {:.1f} s".format(time.time() - started))
        outcome = {"files": files, "stop_reason": fit.StopReason, "stop_detail": fit.StopDetail, "level": fit.Level,
                   "max_distance": fit.HistoryMax[-1], "reference_length": length, "tolerance": tolerance}
        try:
            if volume:
                files.update({kind: os.path.join(output_dir, name + ending) for kind, ending in FORMAT_ENDINGS.items()
                              if kind in formats})
                files.update({
                    "volume_report": os.path.join(output_dir, name + "_volume_report.md"),
                    "cut": os.path.join(output_dir, name + "_cut.png"),
                    "quality": os.path.join(output_dir, name + "_quality.png"),
                })
                files.update({kind: os.path.join(output_dir, file_name)
                              for kind, file_name in (file_names or {}).items()})
                outcome.update(run_volume(fit, files, title, length, reynolds_number, preset, target_cells, formats,
                                          cut, log, grid_method, subdivision_steps, volume_options, grid_options))
                _show_final_objects(doc, outcome["grid"])
            else:
                _show_final_objects(doc, shell)
        finally:  # the surface stage's results are kept when the volume stage fails
            doc.saveAs(files["document"])
            lines = _report_lines(title, what, fit, shell, length, tolerance, seconds,
                                  [f for key, f in files.items() if key == "report" or os.path.exists(f)])
            with open(files["report"], "w") as report:
                report.write("\n".join(lines) + "\n")
            for line in lines:
                log(line)
        log("{}: {:.1f} s".format(title, time.time() - started))
        return outcome
    finally:
        FreeCAD.closeDocument(doc.Name)


def unmet_goals(outcome):
    """What a finished run of run() missed, one sentence each: the fit stopped before its
    tolerance, or checkMesh found a failed check. Empty when the surface is within its tolerance
    and checkMesh says "Mesh OK." (or did not run). The files are written either way; a batch run
    learns of these from the mesh command's exit status 2."""
    unmet = []
    if outcome["stop_reason"] != "converged":
        unmet.append("the fit stopped as {}: {}".format(
            outcome["stop_reason"], outcome["stop_detail"] or "at level {}, above its tolerance {:.3g}".format(
                outcome["level"], outcome["tolerance"])))
    verdict = outcome.get("check_mesh")
    if verdict and verdict != "Mesh OK." and not verdict.startswith("checkMesh not installed"):
        # Sharp trailing edges of lofted wings: the O-grid's first cells there are skew, the fans'
        # prisms are not (docs/hostile_input.md).
        hint = ("; skew faces at a sharp trailing edge are the O-grid's first cells there, which "
                "--volume-option knife_edge_fans=true replaces by a fan of prisms"
                if "skew" in verdict and outcome.get("knife_edge_fans") is False
                and not outcome.get("knife_edge_fans_tried") else "")
        unmet.append("checkMesh on the OpenFOAM case: {}{}".format(verdict, hint))
    return unmet


def _show_final_objects(doc, final):
    """Only the last stage's object (and the cut plane) visible when the document is opened."""
    from bvmesh.features import grid_cut
    from bvmesh.features.common import VISIBLE_ON_OPEN, is_type

    shown = [obj.Name for obj in doc.Objects if obj == final or is_type(obj, grid_cut.TYPE)]
    for obj in doc.Objects:
        obj.Visibility = obj.Name in shown
    doc.Meta = dict(doc.Meta, **{VISIBLE_ON_OPEN: " ".join(shown)})

"""The main job on the bundled example: the ONERA M6 half wing (tests/data), fitted from the
half-wing template with its trailing edge as a crease and its root on the symmetry plane y = 0,
then meshed: the boundary layer and far field as B-spline blocks, evaluated on a point-matched
Euler grid, measured and written for flow solvers.

Writes into the output folder: the FreeCAD document (M6.FCStd: CAD, target, polyhedron, fit,
B-spline shell, volume mesh, grid, cut, quality, exports), the B-spline surface (M6_surface.step),
the convergence plot (M6_convergence.png) and report (M6_report.md), the grid as CGNS (M6.cgns) and
as an OpenFOAM case (M6_openfoam/), the volume report (M6_volume_report.md), the grid around the
section at 44 % of the span (M6_cut_eta044.png) and the quality histograms (M6_quality.png). Runs
headless (plain /usr/bin/python3 or freecadcmd)."""

import os
import shutil
import subprocess
import time

import numpy as np

from bvmesh import api, load_core, paths


def _root_chord(wing_shape, symmetry_face):
    return wing_shape.Faces[symmetry_face].BoundBox.XLength


def _report_lines(fit, shell, chord, tolerance, seconds, files):
    rows = api.convergence_table(fit)
    lines = [
        "# ONERA M6 half wing: surface fit",
        "",
        "Target: the wing's faces without its root face (symmetry plane y = 0); root chord {:.1f}; "
        "tolerance {:.3g} ({:.0e} root chord).".format(chord, tolerance, tolerance / chord),
        "Stop: **{}** at level {} after {:.1f} s; {} control points.{}".format(
            fit.StopReason, fit.Level, seconds, len(fit.ControlVertices),
            " " + fit.StopDetail + "." if fit.StopDetail else ""),
        "'converged' means the limit samples and the two-sided check (denser limit points to the CAD, "
        "CAD tessellation nodes to the limit surface) are both within the tolerance; a CAD node on an "
        "edge counts beyond the CAD's own tolerance there (OCCT's edge tolerance: the faces meeting at "
        "that edge may be that far apart).",
        "",
        "| level | correction | control points | max distance | RMS distance | max / chord | "
        "limit -> target | target -> limit | beyond CAD tolerance |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        def checked(value):
            return "-" if value is None else "{:.3e}".format(value)
        lines.append("| {level} | {correction} | {control_points} | {max_distance:.3e} | {rms_distance:.3e} | "
                     "{ratio:.2e} | {lt} | {tl} | {tb} |".format(ratio=row["max_distance"] / chord,
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


# Wind-tunnel case 2308 of the M6 (AGARD AR-138): Reynolds number on the mean aerodynamic chord.
REYNOLDS_NUMBER = 11.72e6
CUT_ETA = 0.44
# The M6's reference semispan (the wind-tunnel stations' eta = y / b); the CAD's rounded tip cap
# reaches 1218.5 mm.
SEMISPAN = 1196.3
TARGET_CELLS = 1_000_000


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
    """The grid around the section at CUT_ETA: the whole domain, the section, the trailing edge."""
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
    return path


def wall_distance(grid_object):
    """Largest distance of the grid's wall points from the CAD faces of its fit's target."""
    from bvmesh import grid

    target = grid_object.VolumeMesh.Fit.Target
    return float(target.Proxy.core_target(target).project(grid.wall_points(api.grid_of(grid_object)))["distances"].max())


def _smoothed_layers(vm):
    count = vm.FarfieldLayersSmoothed  # 0 unless the scheme is hyperbolic
    if count == 0:
        return ""
    return " ({} layer{} by the smoothed step where the hyperbolic one would fold)".format(
        count, "" if count == 1 else "s")


def _volume_report(vm, grid_object, quality, cgns, case, verdict, seconds):
    lines = [
        "# ONERA M6 half wing: volume mesh",
        "",
        "Wall: the surface fit at level {}{}; the grid's wall points lie within {:.3e} of the CAD faces (fit "
        "tolerance {:.3g}).".format(vm.WallLevelUsed, "" if vm.MarchingLevelUsed == vm.WallLevelUsed else (
            ", layers marched from the fit refitted to level {} and carried onto it (the automatic marching "
            "level: the highest with at most {} control points; marched from its own level the boundary layer "
            "folds at the trailing edge's tip corner; docs/volume.md)".format(vm.MarchingLevelUsed,
                                                                              vm.MarchingPointLimit)),
            wall_distance(grid_object), vm.Fit.Tolerance),
        "Blocks: {} tricubic B-spline blocks, {} control layers; boundary layer {:.4g} thick (reference length "
        "{:.4g}, Re {:.4g}); far field: sphere of radius {:.6g} ({:.1f} reference lengths), marched {}{}.".format(
            vm.BlockCount, vm.ControlLayers, vm.BoundaryLayerThicknessUsed, vm.ReferenceLengthUsed,
            vm.ReynoldsNumber, vm.FarfieldDistanceUsed, vm.FarfieldDistanceUsed / vm.ReferenceLengthUsed,
            vm.FarfieldScheme, _smoothed_layers(vm)),
        _grid_line(grid_object),
        "Cells with a non-positive scaled Jacobian: {}; with a face above 70 degrees of non-orthogonality: "
        "{}; with a determinant below 1e-3 (which checkMesh -allGeometry fails): {}.".format(
            quality.NonPositiveCells, quality.CellsAbove70Degrees, quality.SmallDeterminantCells),
        "checkMesh on {}: {}".format(os.path.basename(case), verdict),
        "",
        quality.Table.rstrip(),
        "",
        "Files: {}, {}/; volume stage {:.1f} s.".format(os.path.basename(cgns), os.path.basename(case), seconds),
    ]
    return lines


def _grid_line(grid_object):
    if grid_object.Method == "subdivision":
        return ("Grid: the fit's control mesh marched (the volume mesh's options) and refined by {} volumetric "
                "Catmull-Clark step(s), the wall on the fitted surface, no wall law; {} cells, {} points over the "
                "blocks, {} points on the wall-normal lines.".format(
                    grid_object.SubdivisionSteps, grid_object.CellCount, grid_object.PointCount,
                    grid_object.NormalPointsUsed))
    return ("Grid: preset {}, {} cells, {} points over the blocks, {} points on the wall-normal lines, first cell "
            "height {:.4g} .. {:.4g}, largest wall-normal growth {:.4g}.".format(
                grid_object.Preset, grid_object.CellCount, grid_object.PointCount, grid_object.NormalPointsUsed,
                grid_object.FirstCellHeightMin, grid_object.FirstCellHeightMax, grid_object.GrowthMax))


def run_volume(fit, chord, files, log=print, grid_method="bspline", subdivision_steps=1):
    """The volume stage of the main job on a fitted M6: volume mesh, Euler grid, cut, quality,
    CGNS and OpenFOAM files, pictures and report. grid_method 'subdivision': the grid is the
    control volume refined by `subdivision_steps` volumetric Catmull-Clark steps instead of the
    blocks evaluated. Returns the volume objects by name."""
    started = time.time()
    stage = time.time()
    vm = api.make_volume_mesh(fit, reference_length=chord, reynolds_number=REYNOLDS_NUMBER)
    log("volume mesh: {} blocks, {} control layers, far field {:.0f} ({:.1f} s)".format(
        vm.BlockCount, vm.ControlLayers, vm.FarfieldDistanceUsed, time.time() - stage))
    stage = time.time()
    if grid_method == "subdivision":
        grid_object = api.make_volume_grid(vm, method="subdivision", steps=subdivision_steps, show=("wall",))
        what = "{} subdivision step(s) of the control volume".format(subdivision_steps)
    else:
        grid_object = api.make_volume_grid(vm, "euler", target_cells=TARGET_CELLS, show=("wall",))
        what = "euler"
    log("grid: {}, {} cells ({:.1f} s)".format(what, grid_object.CellCount, time.time() - stage))
    stage = time.time()
    quality = api.make_mesh_quality(grid_object, histogram_path=files["quality"])
    log("quality: min scaled Jacobian {:.3g}, max non-orthogonality {:.1f} ({:.1f} s)".format(
        quality.MinScaledJacobian, quality.MaxNonOrthogonality, time.time() - stage))
    stage = time.time()
    cut = api.make_grid_cut(grid_object, eta=CUT_ETA, span=SEMISPAN)
    _cut_picture(grid_object, files["cut"])
    log("cut at {:.0f} % span: {} segments ({:.1f} s)".format(100 * CUT_ETA, cut.SegmentCount, time.time() - stage))
    stage = time.time()
    api.export_grid(grid_object, files["cgns"], name="ExportCGNS")
    api.export_grid(grid_object, files["openfoam"], name="ExportOpenFOAM")
    log("files: CGNS and OpenFOAM case ({:.1f} s)".format(time.time() - stage))
    stage = time.time()
    verdict = check_mesh(files["openfoam"])
    log("checkMesh: {} ({:.1f} s)".format(verdict, time.time() - stage))
    lines = _volume_report(vm, grid_object, quality, files["cgns"], files["openfoam"], verdict,
                           time.time() - started)
    with open(files["volume_report"], "w") as report:
        report.write("\n".join(lines) + "\n")
    return {"volume_mesh": vm, "grid": grid_object, "quality": quality, "cut": cut, "check_mesh": verdict}


def run(output_dir, max_level=5, relative_tolerance=1e-5, volume=True, log=print, grid_method="bspline",
        subdivision_steps=1):
    """Runs the example and returns a dict of the files written and the fit's outcome.
    relative_tolerance is relative to the root chord. volume=False stops after the surface stage.
    grid_method, subdivision_steps: as run_volume takes them."""
    import FreeCAD

    os.makedirs(output_dir, exist_ok=True)
    started = time.time()
    doc = FreeCAD.newDocument("M6")
    try:
        wing = api.import_cad(doc, paths.EXAMPLE_WING, name="AileM6_with_sharp_TE")
        _, symmetry_face, _ = load_core().remove_symmetry_face(wing.Shape.exportBrepToString())
        faces = ["Face{}".format(i + 1) for i in range(len(wing.Shape.Faces)) if i != symmetry_face]
        target = api.make_target(doc, wing, faces=faces)
        log("target: {} faces; Face{} is the symmetry-plane face".format(len(faces), symmetry_face + 1))
        polyhedron = api.make_polyhedron_from_template(doc, target, "half_wing", tip_kinks="follow")
        log("polyhedron: " + polyhedron.Summary)
        chord = _root_chord(wing.Shape, symmetry_face)
        tolerance = relative_tolerance * chord
        fit = api.make_surface_fit(doc, target, polyhedron, symmetry_plane=api.symmetry_plane_guess(target),
                                   tolerance=tolerance, max_level=max_level, check_samples_per_face=4)
        api.fit_to_tolerance(fit)
        seconds = time.time() - started
        log("fit: {} at level {}, max distance {:.3e} ({:.2e} root chord), RMS {:.3e}".format(
            fit.StopReason, fit.Level, fit.HistoryMax[-1], fit.HistoryMax[-1] / chord, fit.HistoryRms[-1]))
        # Tangent-continuous charts: at the converged level the normal jumps across chart borders
        # fall from 3.4 to 0.61 degrees (docs/fitting.md) and the charts stay within the tolerance.
        shell = api.make_bspline_shell(fit, tangent_continuity=True)
        files = {
            "document": os.path.join(output_dir, "M6.FCStd"),
            "step": os.path.join(output_dir, "M6_surface.step"),
            "plot": os.path.join(output_dir, "M6_convergence.png"),
            "report": os.path.join(output_dir, "M6_report.md"),
        }
        api.export_step(shell, files["step"])
        api.plot_convergence(fit, files["plot"], title="ONERA M6 half wing")
        log("surface stage: {:.1f} s".format(time.time() - started))
        outcome = {"files": files, "stop_reason": fit.StopReason, "level": fit.Level,
                   "max_distance": fit.HistoryMax[-1], "chord": chord}
        try:
            if volume:
                files.update({
                    "cgns": os.path.join(output_dir, "M6.cgns"),
                    "openfoam": os.path.join(output_dir, "M6_openfoam"),
                    "volume_report": os.path.join(output_dir, "M6_volume_report.md"),
                    "cut": os.path.join(output_dir, "M6_cut_eta044.png"),
                    "quality": os.path.join(output_dir, "M6_quality.png"),
                })
                outcome.update(run_volume(fit, chord, files, log, grid_method, subdivision_steps))
                _show_final_objects(doc, outcome["grid"])
            else:
                _show_final_objects(doc, shell)
        finally:  # the surface stage's results are kept when the volume stage fails
            doc.saveAs(files["document"])
            lines = _report_lines(fit, shell, chord, tolerance, seconds,
                                  [f for key, f in files.items() if key == "report" or os.path.exists(f)])
            with open(files["report"], "w") as report:
                report.write("\n".join(lines) + "\n")
            for line in lines:
                log(line)
        log("main job: {:.1f} s".format(time.time() - started))
        return outcome
    finally:
        FreeCAD.closeDocument(doc.Name)


def _show_final_objects(doc, final):
    """Only the last stage's object (and the cut plane) visible when the document is opened."""
    from bvmesh.features import grid_cut
    from bvmesh.features.common import VISIBLE_ON_OPEN, is_type

    shown = [obj.Name for obj in doc.Objects if obj == final or is_type(obj, grid_cut.TYPE)]
    for obj in doc.Objects:
        obj.Visibility = obj.Name in shown
    doc.Meta = dict(doc.Meta, **{VISIBLE_ON_OPEN: " ".join(shown)})

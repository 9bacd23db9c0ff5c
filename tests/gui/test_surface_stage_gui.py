# GUI test of the surface stage, run as a FreeCAD macro by run_gui_test.sh on the ONERA M6 half
# wing: a fit cancelled from its progress dialog leaves the document as it was; then, while
# FreeCAD's macro recorder runs, the commands are used in order as a user would (toolbar, task
# panels with their OK button, picking on the polyhedron, undo/redo); the recorded macro is then
# replayed in `freecadcmd -c` and must give the same control points; the document is saved and
# reopened and recomputes to identical results; pictures of the distance map and the convergence
# plot are saved under the build tree. Exits 0 on success, 1 on any failure.
import json
import os
import subprocess
import sys
import time

from PySide import QtCore, QtGui

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gui_harness import (check, click_toolbar, log, main_window, press_task_ok, settle, start,  # noqa: E402
                         start_macro_recording, toolbar_action, when_shown)

OUTPUT_DIR = os.environ.get("BVMESH_TEST_OUTPUT_DIR", "/tmp")
SOURCE_DIR = os.environ.get("BVMESH_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(SOURCE_DIR, "tests", "freecad"))
MACRO_NAME = "bvmesh_gui_recorded"
MACRO = os.path.join(OUTPUT_DIR, MACRO_NAME + ".FCMacro")
SAVED = os.path.join(OUTPUT_DIR, "gui_m6_surface.FCStd")
DISTANCE_PICTURE = os.path.join(OUTPUT_DIR, "gui_distance_map.png")
WINDOW_PICTURE = os.path.join(OUTPUT_DIR, "gui_distance_map_window.png")
POLYHEDRON_PICTURE = os.path.join(OUTPUT_DIR, "gui_polyhedron.png")
CONVERGENCE_PICTURE = os.path.join(OUTPUT_DIR, "gui_convergence.png")
CONVERGENCE_WINDOW_PICTURE = os.path.join(OUTPUT_DIR, "gui_convergence_window.png")
FIT_FACES = ["Face{}".format(i) for i in range(1, 12) if i != 9]  # all but the root plane





def vectors(obj):
    return [(v.x, v.y, v.z) for v in obj.ControlVertices]


def wing_fit_objects(doc, api):
    """Target, polyhedron (with creases and the tip corner) and fit of the wing, made by the API."""
    from m6_polyhedron import wing_polyhedron

    cad = api.import_cad(doc, os.path.join(SOURCE_DIR, "tests", "data", "AileM6_with_sharp_TE.stp"))
    target = api.make_target(doc, cad, faces=FIT_FACES)
    vertices, faces, creases = wing_polyhedron(cad.Shape)
    poly = api.make_polyhedron(doc, vertices, faces, creases=creases, corners=[16])
    return api.make_surface_fit(doc, target, poly, relative_tolerance=1e-5, max_level=3,
                                symmetry_plane=api.symmetry_plane_guess(target))


def cancelled_fit_leaves_document_as_it_was():
    import FreeCAD
    import FreeCADGui
    from bvmesh import api
    from bvmesh.gui import progress

    doc = FreeCAD.newDocument("CancelTest")
    fit = wing_fit_objects(doc, api)
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(fit)
    before = (list(fit.Steps), vectors(fit), list(fit.HistoryMax), [o.Name for o in doc.Objects])
    undo_before = doc.UndoCount
    seen = []

    def cancel(dialog):
        seen.append(dialog.labelText())
        dialog.findChild(QtGui.QPushButton).click()  # its only button: Cancel

    timer = when_shown(lambda: main_window().findChild(QtGui.QProgressDialog, progress.DIALOG_NAME), cancel)
    FreeCADGui.runCommand("BVMesh_FitToTolerance")
    timer.stop()
    settle()
    check(len(seen) == 1, "the fit showed its progress dialog and Cancel was pressed")
    after = (list(fit.Steps), vectors(fit), list(fit.HistoryMax), [o.Name for o in doc.Objects])
    check(after == before, "the cancelled fit left steps, control points, history and objects as they were")
    check(doc.UndoCount == undo_before, "the cancelled fit left no undo step")
    FreeCAD.closeDocument(doc.Name)


def run():
    import FreeCAD
    import FreeCADGui
    from bvmesh.features import polyhedron as polyhedron_feature
    from bvmesh.gui import plots, progress
    from m6_polyhedron import wing_polyhedron

    FreeCADGui.activateWorkbench("BVMeshWorkbench")
    settle()
    check(FreeCADGui.activeWorkbench().name() == "BVMeshWorkbench", "BVMesh is the active workbench")
    for name in ("BVMesh_PolyhedronManual", "BVMesh_DetectCreases", "BVMesh_Subdivide", "BVMesh_FitToTolerance",
                 "BVMesh_DistanceMap", "BVMesh_ConvergencePlot", "BVMesh_ExportStep"):
        action = toolbar_action(name)
        check(not action.icon().isNull() and action.toolTip(), "{} has an icon and a tooltip".format(name))

    cancelled_fit_leaves_document_as_it_was()

    start_macro_recording(OUTPUT_DIR, MACRO_NAME)
    click_toolbar("BVMesh_LoadExample")
    doc = FreeCAD.ActiveDocument
    cad = doc.getObject("CAD")
    check(cad is not None and len(cad.Shape.Faces) == 11, "the example wing was loaded")

    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(cad, FIT_FACES)
    click_toolbar("BVMesh_Target")
    target = doc.getObject("Target")
    check(target is not None and len(target.Shape.Faces) == 10, "the target holds the 10 faces besides the root")
    check(any("4 sharp" in line for line in target.Report), "the target reports the sharp edges: {}".format(
        target.Report))

    vertices, faces, _ = wing_polyhedron(cad.Shape)
    click_toolbar("BVMesh_PolyhedronManual")
    form = main_window().findChild(QtGui.QWidget, "BVMeshPolyhedron")
    check(form is not None and form.isVisible(), "the polyhedron task panel is shown")
    form.findChild(QtGui.QPlainTextEdit, "textVertices").setPlainText(
        "\n".join("{!r} {!r} {!r}".format(*v) for v in vertices))
    form.findChild(QtGui.QPlainTextEdit, "textFaces").setPlainText("\n".join(" ".join(map(str, f)) for f in faces))
    press_task_ok()
    poly = doc.getObject("ControlPolyhedron")
    check(poly is not None and len(poly.Vertices) == len(vertices) and len(poly.FaceSizes) == len(faces),
          "OK in the task panel created the polyhedron ({})".format(poly.Summary if poly else None))

    FreeCADGui.Selection.clearSelection()
    click_toolbar("BVMesh_DetectCreases")
    creases = sorted(tuple(sorted(p)) for p in polyhedron_feature.pairs(poly.Creases))
    check(creases == [(0, 8), (8, 16)], "the trailing-edge edges were detected as creases: {}".format(creases))
    colors = poly.ViewObject.LineColorArray
    mesh = polyhedron_feature.control_mesh(poly)
    crease_ids = [i for i, e in enumerate(mesh.edges) if tuple(sorted(e)) in creases]
    check(len(colors) == mesh.num_edges and colors[crease_ids[0]] != colors[(crease_ids[0] + 1) % len(colors)],
          "creases are drawn in their own colour")

    tip_te = [i for i, v in enumerate(poly.Shape.Vertexes) if (v.Point - poly.Vertices[16]).Length == 0][0]
    FreeCADGui.Selection.addSelection(poly, "Vertex{}".format(tip_te + 1))
    click_toolbar("BVMesh_MarkFeatures")
    check(list(poly.Corners) == [16], "the picked tip trailing-edge vertex is a corner")
    target.ViewObject.Transparency = 70
    view = FreeCADGui.activeDocument().activeView()
    view.viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    settle(300)
    view.saveImage(POLYHEDRON_PICTURE, 1000, 700, "White")
    check(os.path.getsize(POLYHEDRON_PICTURE) > 10000, "polyhedron picture saved to " + POLYHEDRON_PICTURE)

    FreeCADGui.Selection.clearSelection()
    click_toolbar("BVMesh_SurfaceFit")
    fit = doc.getObject("SurfaceFit")
    check(fit is not None and fit.UseSymmetryPlane and abs(fit.SymmetryNormal.y) == 1.0,
          "the fit exists and keeps the root on the symmetry plane y = 0")

    click_toolbar("BVMesh_FitParameters")
    form = main_window().findChild(QtGui.QWidget, "BVMeshFit")
    check(form is not None and form.isVisible(), "the fit parameter task panel is shown")
    form.findChild(QtGui.QSpinBox, "spinMaxLevel").setValue(3)
    form.findChild(QtGui.QDoubleSpinBox, "spinRelativeTolerance").setValue(1e-5)
    press_task_ok()
    check(fit.MaxLevel == 3 and fit.RelativeTolerance == 1e-5, "OK in the task panel set the parameters")

    start_max = fit.MaxDistance
    for name, step in (("BVMesh_Subdivide", "subdivide"), ("BVMesh_Project", "project"),
                       ("BVMesh_Approximate", "approximate"), ("BVMesh_CorrectParameters", "correct 2")):
        click_toolbar(name)
        check(fit.Steps[-1] == step and fit.isValid(), "{} added the step '{}'".format(name, step))
    check(fit.Level == 1 and fit.MaxDistance < start_max,
          "one level fitted: max distance {:.3g} -> {:.3g}".format(start_max, fit.MaxDistance))

    before_smooth = vectors(fit)
    click_toolbar("BVMesh_Smooth")
    smoothed = vectors(fit)
    check(fit.Steps[-1].startswith("smooth") and smoothed != before_smooth, "Smooth moved the control points")
    FreeCADGui.runCommand("Std_Undo")
    settle()
    check(not fit.Steps[-1].startswith("smooth") and vectors(fit) == before_smooth, "Undo took the smoothing back")
    FreeCADGui.runCommand("Std_Redo")
    settle()
    check(fit.Steps[-1].startswith("smooth") and vectors(fit) == smoothed, "Redo brought it back")

    labels, ticks = [], []
    ticker = QtCore.QTimer()
    ticker.timeout.connect(lambda: ticks.append(time.time()))
    ticker.start(100)
    watcher = when_shown(lambda: main_window().findChild(QtGui.QProgressDialog, progress.DIALOG_NAME),
                         lambda dialog: labels.append(dialog))
    # FreeCAD's own console messages share the status bar, so collect what it showed.
    messages = []
    main_window().statusBar().messageChanged.connect(messages.append)
    started = time.time()
    click_toolbar("BVMesh_FitToTolerance")
    seconds = time.time() - started
    ticker.stop()
    watcher.stop()
    main_window().statusBar().messageChanged.disconnect(messages.append)
    check(len(labels) == 1, "the fit showed its progress dialog")
    ends = [m for m in messages if m.startswith("BVMesh fit: ") and m.split(": ", 1)[1].split(" ")[0] in
            ("converged", "stagnated", "max_level", "check_failed")]
    check(len(ends) == 1, "the status bar told how the fit ended: {}".format(ends or messages[-3:]))
    check(len(ticks) >= 0.5 * seconds / 0.1, "the GUI kept processing events during the {:.1f} s fit ({} timer "
          "ticks)".format(seconds, len(ticks)))
    check(fit.Steps[-1] == "fit" and fit.Level == 3 and fit.StopReason in ("converged", "stagnated", "max_level", "check_failed"),
          "the fit ran to level {} ({})".format(fit.Level, fit.StopReason))
    check(fit.HistoryMax[-1] < 0.5 * fit.HistoryMax[0] and fit.HistoryRms[-1] < 0.1 * fit.HistoryRms[0],
          "the fit really fitted: max {:.3g} -> {:.3g}, RMS {:.3g} -> {:.3g}".format(
              fit.HistoryMax[0], fit.HistoryMax[-1], fit.HistoryRms[0], fit.HistoryRms[-1]))

    doc.saveAs(SAVED)  # pictures go beside the document
    click_toolbar("BVMesh_DistanceMap")
    dmap = doc.getObject("DistanceMap")
    check(dmap is not None and len(dmap.VertexColors) == dmap.Mesh.CountPoints > 1000,
          "the distance map colours each of its {} points".format(dmap.Mesh.CountPoints if dmap else 0))
    check(dmap.ViewObject.Coloring, "the mesh view shows the per-vertex colours")
    check(dmap in fit.ViewObject.claimChildren(), "the fit claims the distance map as its child")
    check(main_window().findChild(QtGui.QDialog, plots.IMAGE_DIALOG_NAME) is not None, "the legend is shown")

    click_toolbar("BVMesh_ConvergencePlot")
    plot = plots.default_plot_path(fit)
    check(os.path.getsize(plot) > 10000, "the convergence plot was saved as " + plot)
    os.replace(plot, CONVERGENCE_PICTURE)
    click_toolbar("BVMesh_BsplineShell")
    shell = doc.getObject("BsplineShell")
    check(shell is not None and shell.Shape.isValid() and len(shell.Shape.Faces) > 0,
          "the B-spline shell is a valid shape of {} faces".format(len(shell.Shape.Faces) if shell else 0))
    check(all(face.Surface.TypeId == "Part::GeomBSplineSurface" for face in shell.Shape.Faces),
          "made of B-spline faces only")
    FreeCADGui.runCommand("Std_MacroStopRecord")
    settle(500)
    subprocess.run(["/usr/bin/import", "-window", "root", CONVERGENCE_WINDOW_PICTURE], check=True, timeout=60)
    legend, plot_dialog = main_window().findChildren(QtGui.QDialog, plots.IMAGE_DIALOG_NAME)
    plot_dialog.close()
    legend.move(main_window().width() - legend.width() - 20, 120)

    view = FreeCADGui.activeDocument().activeView()
    for obj in doc.Objects:
        obj.ViewObject.Visibility = obj is dmap
    view.viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    settle(500)
    plots.save_distance_map_picture(dmap, DISTANCE_PICTURE)
    check(os.path.getsize(DISTANCE_PICTURE) > 10000, "distance map picture saved to " + DISTANCE_PICTURE)
    subprocess.run(["/usr/bin/import", "-window", "root", WINDOW_PICTURE], check=True, timeout=60)
    for dialog in main_window().findChildren(QtGui.QDialog, plots.IMAGE_DIALOG_NAME):
        dialog.close()

    replay_recorded_macro(fit)
    reopen_and_recompute(doc)


def replay_recorded_macro(fit):
    text = open(MACRO).read()
    for call in ("bvmesh.api.import_cad(", "bvmesh.api.make_target(", "bvmesh.api.make_polyhedron(",
                 "bvmesh.api.detect_creases(", "bvmesh.api.mark_features(", "bvmesh.api.make_surface_fit(",
                 "bvmesh.api.set_fit_parameters(", "bvmesh.api.subdivide(", "bvmesh.api.smooth(",
                 "bvmesh.api.fit_to_tolerance(", "bvmesh.api.make_distance_map("):
        check(call in text, "the recorded macro holds " + call)
    result = os.path.join(OUTPUT_DIR, "gui_macro_replay.json")
    if os.path.exists(result):
        os.remove(result)
    code = ("import json, sys; exec(compile(open({macro!r}).read(), {macro!r}, 'exec')); "
            "fit = App.ActiveDocument.getObject('SurfaceFit'); "
            "json.dump({{'vertices': [[v.x, v.y, v.z] for v in fit.ControlVertices], 'steps': list(fit.Steps)}}, "
            "open({result!r}, 'w')); sys.exit(0)").format(macro=MACRO, result=result)
    done = subprocess.run(["freecadcmd", "-c", code], capture_output=True, text=True, timeout=300)
    check(done.returncode == 0 and os.path.exists(result),
          "the macro replays in freecadcmd -c (rc {}): {}".format(done.returncode, done.stderr[-2000:]))
    replay = json.load(open(result))
    check(replay["steps"] == list(fit.Steps), "the replay made the same steps: {}".format(replay["steps"]))
    gui = vectors(fit)
    worst = max(abs(a - b) for p, q in zip(gui, replay["vertices"]) for a, b in zip(p, q))
    check(len(replay["vertices"]) == len(gui) and worst <= 1e-12,
          "the replay gives the same {} control points (max difference {:.3g})".format(len(gui), worst))


def reopen_and_recompute(doc):
    import FreeCAD

    doc.save()
    saved = {o.Name: (o.TypeId, getattr(getattr(o, "Proxy", None), "Type", None)) for o in doc.Objects}
    fit = doc.getObject("SurfaceFit")
    expected = (vectors(fit), list(fit.HistoryMax), list(fit.SampleDistances))
    dmap_distances = list(doc.getObject("DistanceMap").Distances)
    FreeCAD.closeDocument(doc.Name)
    doc = FreeCAD.openDocument(SAVED)
    restored = {o.Name: (o.TypeId, getattr(getattr(o, "Proxy", None), "Type", None)) for o in doc.Objects}
    check(restored == saved, "reopening restored every object with its proxy: {}".format(sorted(restored)))
    fit = doc.getObject("SurfaceFit")
    check((vectors(fit), list(fit.HistoryMax), list(fit.SampleDistances)) == expected, "the saved results came back")
    for obj in doc.Objects:
        obj.touch()
    doc.recompute()
    check(all(o.isValid() for o in doc.Objects), "every object recomputes after reopening")
    check((vectors(fit), list(fit.HistoryMax), list(fit.SampleDistances)) == expected,
          "the recompute after reopening gives identical control points, history and distances")
    check(list(doc.getObject("DistanceMap").Distances) == dmap_distances, "and an identical distance map")


start(run)

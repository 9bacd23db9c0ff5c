# GUI test of the volume stage, run as a FreeCAD macro by run_gui_test.sh on the ONERA M6 half
# wing. While FreeCAD's macro recorder runs, the surface commands and then the volume commands are
# used from the toolbar as a user would (task panels with OK, input and file dialogs): a volume mesh
# cancelled from its progress dialog leaves the document as it was; the volume mesh is undone and
# redone; grid, cut plane (coloured by scaled Jacobian, with its legend), quality (histograms) and
# a CGNS export follow. The recorded macro replayed in `freecadcmd -c` must give the same grid
# (identical points); the document is saved, reopened and recomputes identically; the main job's
# document opens with its grid and cut on screen; the hemisphere-cylinder's flow-domain file goes
# from target to volume mesh with its outflow plane. Screenshots go under the build tree.
# Exits 0 on success, 1 on any failure.
import json
import os
import shutil
import subprocess
import sys
import time

from PySide import QtCore, QtGui

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gui_harness import (check, click_toolbar, log, main_window, press_task_ok, settle, start,  # noqa: E402
                         start_macro_recording, toolbar_action, when_shown)

OUTPUT_DIR = os.environ.get("BVMESH_TEST_OUTPUT_DIR", "/tmp")
MACRO_NAME = "bvmesh_gui_volume_recorded"
MACRO = os.path.join(OUTPUT_DIR, MACRO_NAME + ".FCMacro")
SAVED = os.path.join(OUTPUT_DIR, "gui_m6_volume.FCStd")
CGNS = os.path.join(OUTPUT_DIR, "gui_m6.cgns")
FLOW_CASE_PARENT = os.path.join(OUTPUT_DIR, "gui_flow_case")
FLOW_CASE_PICTURE = os.path.join(OUTPUT_DIR, "gui_flow_case_properties.png")
BLOCKS_PICTURE = os.path.join(OUTPUT_DIR, "gui_volume_blocks.png")
WALL_BLOCKS_PICTURE = os.path.join(OUTPUT_DIR, "gui_volume_wall_blocks.png")
CUT_PICTURE = os.path.join(OUTPUT_DIR, "gui_volume_cut.png")
GRID_PANEL_PICTURE = os.path.join(OUTPUT_DIR, "gui_volume_grid_panel.png")
VOLUME_PANEL_PICTURE = os.path.join(OUTPUT_DIR, "gui_volume_mesh_panel.png")
CUT_WINDOW_PICTURE = os.path.join(OUTPUT_DIR, "gui_volume_cut_window.png")
MAIN_JOB_DIR = os.path.join(OUTPUT_DIR, "gui_main_job")
MAIN_JOB_PICTURE = os.path.join(OUTPUT_DIR, "gui_main_job_document.png")
STING_PICTURE = os.path.join(OUTPUT_DIR, "gui_sting_volume.png")
DATA = os.environ.get("BVMESH_TEST_DATA_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data"))
FIT_FACES = ["Face{}".format(i) for i in range(1, 12) if i != 9]  # all but the root plane
VOLUME_COMMANDS = ["BVMesh_VolumeMesh", "BVMesh_VolumeGrid", "BVMesh_GridCut", "BVMesh_MeshQuality",
                   "BVMesh_ExportGrid"]


def answer_input_dialogs(*values):
    """Answers the next QInputDialogs (a number or a list item each), in order, with OK."""
    pending = list(values)

    def answer(dialog):
        value = pending.pop(0)
        if isinstance(value, str):
            dialog.setTextValue(value)
        else:
            dialog.setDoubleValue(value)
        dialog.accept()
        if pending:
            timers.append(when_shown(find, answer))

    def find():
        return next((w for w in QtGui.QApplication.topLevelWidgets()
                     if isinstance(w, QtGui.QInputDialog) and w.isVisible()), None)

    timers = [when_shown(find, answer)]
    return timers


def answer_file_dialog(path, timeout_ms=60000):
    """Answers the next file dialog with `path`, again on every tick while it stays open (an answer
    that did not take would leave the test waiting for good)."""
    deadline = time.time() + timeout_ms / 1000.0
    timer = QtCore.QTimer()

    def poll():
        dialog = next((w for w in QtGui.QApplication.topLevelWidgets()
                       if isinstance(w, QtGui.QFileDialog) and w.isVisible()), None)
        if dialog is not None:
            # selectFile() leaves the name field alone while it has the focus (Qt's QFileDialog),
            # so the name goes into the field itself.
            edit = dialog.findChild(QtGui.QLineEdit, "fileNameEdit")
            if edit is not None:
                edit.setText(path)
            else:
                dialog.selectFile(path)
            dialog.accept()
        elif time.time() > deadline:
            timer.stop()

    timer.timeout.connect(poll)
    timer.start(200)
    return timer


def form(name):
    widget = main_window().findChild(QtGui.QWidget, name)
    check(widget is not None and widget.isVisible(), "the {} task panel is shown".format(name))
    return widget


def surface_stage(doc_holder):
    """Load the example, pick the target faces, place the half-wing template, fit to level 2."""
    import FreeCAD
    import FreeCADGui

    click_toolbar("BVMesh_LoadExample")
    doc = FreeCAD.ActiveDocument
    cad = doc.getObject("CAD")
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(cad, FIT_FACES)
    click_toolbar("BVMesh_Target")
    FreeCADGui.Selection.clearSelection()
    answer_input_dialogs("half_wing")
    click_toolbar("BVMesh_PolyhedronFromTemplate")
    check(doc.getObject("ControlPolyhedron") is not None, "the half-wing template was placed")
    click_toolbar("BVMesh_SurfaceFit")
    fit_to_tolerance(max_level=2, relative_tolerance=1e-5)
    fit = doc.getObject("SurfaceFit")
    check(fit.Level == 2 and fit.UseSymmetryPlane, "the wing was fitted to level 2 on its symmetry plane")
    doc_holder.append(doc)
    return doc, fit


def fit_to_tolerance(max_level, relative_tolerance):
    """The fit's levels and tolerance set in its parameter panel, then Fit to tolerance."""
    click_toolbar("BVMesh_FitParameters")
    panel = form("BVMeshFit")
    panel.findChild(QtGui.QSpinBox, "spinMaxLevel").setValue(max_level)
    panel.findChild(QtGui.QDoubleSpinBox, "spinRelativeTolerance").setValue(relative_tolerance)
    press_task_ok()
    click_toolbar("BVMesh_FitToTolerance")


def fill_volume_panel(farfield_scheme="smoothed"):
    from bvmesh import volume

    panel = form("BVMeshVolumeMesh")
    panel.findChild(QtGui.QDoubleSpinBox, "spinReferenceLength").setValue(810.5)
    panel.findChild(QtGui.QDoubleSpinBox, "spinReynoldsNumber").setValue(11.72e6)
    scheme = panel.findChild(QtGui.QComboBox, "comboFarfieldScheme")
    offered = [scheme.itemText(i) for i in range(scheme.count())] if scheme is not None else []
    # A new mesh starts at make_volume_mesh's defaults: the hyperbolic scheme, the point limit.
    check(offered == ["smoothed", "hyperbolic"] and scheme.currentText() == "hyperbolic",
          "the volume panel offers the far-field schemes, hyperbolic chosen: {} ({})".format(
              offered, scheme.currentText() if scheme is not None else None))
    limit = panel.findChild(QtGui.QSpinBox, "spinMarchingPointLimit")
    check(limit is not None and limit.value() == volume.MARCHING_POINT_LIMIT,
          "the volume panel offers the marching point limit at {}".format(volume.MARCHING_POINT_LIMIT))
    scheme.setCurrentIndex(offered.index(farfield_scheme))
    fans = panel.findChild(QtGui.QCheckBox, "checkKnifeEdgeFans")
    check(fans is not None and not fans.isChecked(), "the volume panel offers fans at knife edges, off")
    return panel


def cancelled_volume_mesh_leaves_document_as_it_was(doc):
    import FreeCADGui

    from bvmesh.gui import progress

    names, undo = [o.Name for o in doc.Objects], doc.UndoCount
    seen = []

    def cancel(dialog):
        seen.append(dialog.labelText())
        dialog.findChild(QtGui.QPushButton).click()

    click_toolbar("BVMesh_VolumeMesh")
    fill_volume_panel()
    timer = when_shown(lambda: main_window().findChild(QtGui.QProgressDialog, progress.WORK_DIALOG_NAME), cancel)
    press_task_ok()
    timer.stop()
    settle(1500)  # the abandoned marching finishes in the background
    check(len(seen) == 1 and "marching" in seen[0], "the volume mesh showed its progress dialog: {}".format(seen))
    check([o.Name for o in doc.Objects] == names and doc.UndoCount == undo,
          "Cancel left the objects and the undo stack as they were")
    if FreeCADGui.Control.activeDialog():
        FreeCADGui.Control.closeDialog()


def save_view(path, visible, direction="isometric", fit_to=None):
    import FreeCADGui

    doc = FreeCADGui.ActiveDocument.Document
    shown = fit_to or visible
    for obj in doc.Objects:
        obj.ViewObject.Visibility = obj in shown
    view = FreeCADGui.activeDocument().activeView()
    getattr(view, {"isometric": "viewIsometric", "front": "viewFront"}[direction])()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    for obj in doc.Objects:
        obj.ViewObject.Visibility = obj in visible
    settle(500)
    view.saveImage(path, 1000, 700, "White")
    return path


def coloured_pixels(path):
    """The share of pixels that are not the white background."""
    image = QtGui.QImage(path)
    step, total, coloured = 4, 0, 0
    for y in range(0, image.height(), step):
        for x in range(0, image.width(), step):
            total += 1
            coloured += QtGui.QColor(image.pixel(x, y)).lightness() < 235
    return coloured / max(total, 1)


def run():
    import FreeCAD
    import FreeCADGui
    from bvmesh import api
    from bvmesh.gui import plots

    FreeCADGui.activateWorkbench("BVMeshWorkbench")
    settle()
    for name in VOLUME_COMMANDS:
        action = toolbar_action(name)
        check(not action.icon().isNull() and action.toolTip(), "{} has an icon and a tooltip".format(name))

    holder = []
    start_macro_recording(OUTPUT_DIR, MACRO_NAME)
    doc, fit = surface_stage(holder)
    cancelled_volume_mesh_leaves_document_as_it_was(doc)

    click_toolbar("BVMesh_VolumeMesh")
    panel = fill_volume_panel("hyperbolic")
    settle()
    check(panel.grab().save(VOLUME_PANEL_PICTURE), "volume panel saved to " + VOLUME_PANEL_PICTURE)
    press_task_ok()
    volume = doc.getObject("VolumeMesh")
    check(volume is not None and volume.FarfieldScheme == "hyperbolic", "the far field was marched hyperbolically")
    check(not fit.ViewObject.Visibility, "the fit steps back behind the new volume mesh")
    check(volume is not None and volume.BlockCount == 24 and len(volume.Shape.Faces) > 24,
          "the volume mesh has {} blocks and shows their wall and symmetry faces".format(
              volume.BlockCount if volume else None))
    digest = volume.Digest
    colors = volume.ViewObject.DiffuseColor
    check(len(colors) == len(volume.Shape.Faces) and len(set(colors)) > 10, "the faces are coloured by block")
    FreeCADGui.runCommand("Std_Undo")
    settle()
    check(doc.getObject("VolumeMesh") is None, "Undo removed the volume mesh")
    FreeCADGui.runCommand("Std_Redo")
    settle()
    volume = doc.getObject("VolumeMesh")
    check(volume is not None and volume.Digest == digest, "Redo brought the same blocks back")
    # The blocks on the symmetry plane around the root section, seen along the span.
    save_view(BLOCKS_PICTURE, [volume], direction="front", fit_to=[doc.getObject("CAD")])
    check(coloured_pixels(BLOCKS_PICTURE) > 0.5, "block view saved to " + BLOCKS_PICTURE)

    FreeCADGui.Selection.clearSelection()
    click_toolbar("BVMesh_VolumeGrid")
    panel = form("BVMeshVolumeGrid")
    panel.findChild(QtGui.QSpinBox, "spinEdgePoints").setValue(9)
    turning = panel.findChild(QtGui.QDoubleSpinBox, "spinMaxTurningAngle")
    check(turning is not None and turning.value() == 0.0, "the grid panel offers the turning limit, off")
    jump = panel.findChild(QtGui.QDoubleSpinBox, "spinMaxSpacingJump")
    check(jump is not None and jump.value() == -1.0, "the grid panel offers the spacing jump limit, the preset's")
    even = panel.findChild(QtGui.QCheckBox, "checkEvenFarField")
    check(even is not None and even.isChecked(), "the grid panel offers the even far field, on")
    # The CAD's leading edge (Edge21, the straight line from the root to the tip) as a feature.
    FreeCADGui.Selection.addSelection(doc.getObject("CAD"), "Edge21")
    panel.findChild(QtGui.QPushButton, "buttonFeatureEdges").click()
    FreeCADGui.Selection.clearSelection()
    shown = panel.findChild(QtGui.QLabel, "labelFeatureEdges").text()
    check(shown.startswith("Edge21 ("), "the panel shows the selected feature edge: " + shown)
    panel.findChild(QtGui.QDoubleSpinBox, "spinFeatureSpacing").setValue(20.0)
    settle()
    check(panel.grab().save(GRID_PANEL_PICTURE), "grid panel saved to " + GRID_PANEL_PICTURE)
    press_task_ok()
    grid = doc.getObject("VolumeGrid")
    check(grid is not None and grid.CellCount == 24 * 8 * 8 * 48, "the Euler grid has {} cells".format(
        grid.CellCount if grid else None))
    check([(o.Name, tuple(names)) for o, names in grid.FeatureEdges] == [("CAD", ("Edge21",))]
          and grid.FeatureSpacing == 20.0, "the grid takes the leading edge as a feature at 20 mm")

    answer_input_dialogs(0.44, "scaled_jacobian")  # the span station, then the metric
    click_toolbar("BVMesh_GridCut")
    cut = doc.getObject("GridCut")
    check(cut is not None and cut.Metric == "scaled_jacobian" and cut.SegmentCount > 1000,
          "the cut at 44 % of the span shows {} grid-line segments".format(cut.SegmentCount if cut else None))
    # the span from the symmetry plane to the far end of the wall (the rounded tip, y = 1218.5)
    check(abs(cut.Point.y - 0.44 * 1218.5) < 1.0, "it is at y = {:.1f}".format(cut.Point.y))
    check(len(set(cut.ViewObject.LineColorArray)) > 5, "its lines are coloured by the metric")
    legend = main_window().findChild(QtGui.QDialog, plots.IMAGE_DIALOG_NAME)
    check(legend is not None, "the legend is shown")

    click_toolbar("BVMesh_MeshQuality")
    quality = doc.getObject("MeshQuality")
    check(quality is not None and quality.Cells == grid.CellCount and quality.NonPositiveCells == 0,
          "the quality of every cell was measured (min scaled Jacobian {:.3g})".format(quality.MinScaledJacobian))

    if os.path.exists(CGNS):
        os.remove(CGNS)
    timer = answer_file_dialog(CGNS)
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(grid)
    click_toolbar("BVMesh_ExportGrid")
    timer.stop()
    check(os.path.getsize(CGNS) > 100000, "the grid was exported to " + CGNS)
    flow_case_with_the_chosen_solver(grid)
    FreeCADGui.runCommand("Std_MacroStopRecord")
    settle()

    wing = doc.getObject("CAD")
    save_view(CUT_PICTURE, [cut], direction="front", fit_to=[wing])
    check(coloured_pixels(CUT_PICTURE) > 0.05, "cut view saved to " + CUT_PICTURE)
    api.set_volume_options(volume, show=("wall",))
    save_view(WALL_BLOCKS_PICTURE, [volume], fit_to=[wing])
    check(coloured_pixels(WALL_BLOCKS_PICTURE) > 0.05, "wall blocks view saved to " + WALL_BLOCKS_PICTURE)
    for dialog in main_window().findChildren(QtGui.QDialog, plots.IMAGE_DIALOG_NAME):
        if dialog is not legend:
            dialog.close()  # the histograms
    legend.move(main_window().width() - legend.width() - 20, 120)
    settle(300)
    subprocess.run(["/usr/bin/import", "-window", "root", CUT_WINDOW_PICTURE], check=True, timeout=60)
    for dialog in main_window().findChildren(QtGui.QDialog, plots.IMAGE_DIALOG_NAME):
        dialog.close()

    replay_recorded_macro(grid)
    doc.saveAs(SAVED)
    reopen_and_recompute(doc)
    main_job_document_shows_its_grid()
    body_running_into_its_outflow_plane()


def body_running_into_its_outflow_plane():
    """The hemisphere-cylinder's flow-domain file from the toolbar, nothing but the object
    selected: the target takes the body, the fit the domain's symmetry plane, the volume mesh the
    quarter sphere and the outflow plane, whose faces it shows with the far field."""
    import FreeCAD
    import FreeCADGui
    import Part

    doc = FreeCAD.newDocument("Sting")
    try:
        domain = doc.addObject("Part::Feature", "Domain")
        domain.Shape = Part.read(os.path.join(DATA, "hemisph-cyl.stp"))
        doc.recompute()
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(domain)
        click_toolbar("BVMesh_Target")
        FreeCADGui.Selection.clearSelection()
        target = doc.getObject("Target")
        check(target is not None and target.FlowDomain == "sphere" and len(target.Shape.Faces) == 2,
              "the target took the body of the flow domain")
        answer_input_dialogs("capsule")
        click_toolbar("BVMesh_PolyhedronFromTemplate")
        click_toolbar("BVMesh_SurfaceFit")
        fit = doc.getObject("SurfaceFit")
        check(fit is not None and fit.UseSymmetryPlane and abs(fit.SymmetryNormal.y - 1.0) < 1e-12,
              "the fit took the flow domain's symmetry plane")
        fit_to_tolerance(max_level=2, relative_tolerance=1e-4)
        click_toolbar("BVMesh_VolumeMesh")
        panel = form("BVMeshVolumeMesh")
        domain_choice = panel.findChild(QtGui.QComboBox, "comboDomain").currentText()
        check(domain_choice == "cad", "the volume panel offers the flow domain's own: {}".format(domain_choice))
        panel.findChild(QtGui.QDoubleSpinBox, "spinReferenceLength").setValue(10.0)
        panel.findChild(QtGui.QDoubleSpinBox, "spinReynoldsNumber").setValue(1e6)
        press_task_ok()
        volume = doc.getObject("VolumeMesh")
        check(volume is not None and volume.Domain == "cad" and volume.BlockCount == 4,
              "the volume mesh marched in the flow domain's quarter sphere")
        volume.ShowFarfield = True
        doc.recompute()
        in_plane = [f for f in volume.Shape.Faces
                    if abs(f.BoundBox.XMin - 10.0) < 1e-6 and abs(f.BoundBox.XMax - 10.0) < 1e-6]
        check(len(in_plane) == 3, "it shows the 3 block faces in the outflow plane x = 10 with the far field")
        save_view(STING_PICTURE, [volume], fit_to=[volume])
        check(coloured_pixels(STING_PICTURE) > 0.05, "sting view saved to " + STING_PICTURE)
    finally:
        FreeCAD.closeDocument(doc.Name)


def flow_case_with_the_chosen_solver(grid):
    """The OpenFOAM case command asks for the solver (euler grid: all three), then the parent folder."""
    import FreeCADGui

    shutil.rmtree(FLOW_CASE_PARENT, ignore_errors=True)
    os.makedirs(FLOW_CASE_PARENT)
    offered = []

    def choose(dialog):
        offered.extend(dialog.comboBoxItems())
        dialog.setTextValue("rhoCentralFoam")
        dialog.accept()

    chooser = when_shown(lambda: next((w for w in QtGui.QApplication.topLevelWidgets()
                                       if isinstance(w, QtGui.QInputDialog) and w.isVisible()), None), choose)
    timer = answer_file_dialog(FLOW_CASE_PARENT)
    click_toolbar("BVMesh_OpenFoamCase")
    timer.stop()
    chooser.stop()
    check(offered == ["rhoSimpleFoam", "rhoPimpleFoam", "rhoCentralFoam"], "the solvers offered: {}".format(offered))
    settings = os.path.join(FLOW_CASE_PARENT, grid.Name + "_case", "bvmesh_case.json")
    check(os.path.isfile(settings) and json.load(open(settings))["solver"] == "rhoCentralFoam",
          "the flow case was written for rhoCentralFoam: " + settings)
    export = grid.Document.getObject("OpenFoamCase")
    check(export is not None and export.Solver == "rhoCentralFoam" and export.getEditorMode("Mach") == [],
          "the export shows its flow case properties with the solver chosen")
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(export)  # the property editor shows its Flow case group
    settle(300)
    check(main_window().grab().save(FLOW_CASE_PICTURE), "flow case properties saved to " + FLOW_CASE_PICTURE)
    FreeCADGui.Selection.clearSelection()


def replay_recorded_macro(grid):
    text = open(MACRO).read()
    for call in ("bvmesh.api.make_surface_fit(", "bvmesh.api.fit_to_tolerance(", "bvmesh.api.make_volume_mesh(",
                 "bvmesh.api.make_volume_grid(", "bvmesh.api.make_grid_cut(", "bvmesh.api.make_mesh_quality(",
                 "bvmesh.api.export_grid(", "feature_edges=[(App.ActiveDocument.getObject('CAD'), ('Edge21',))]",
                 "farfield_scheme='hyperbolic'", "solver='rhoCentralFoam'"):
        check(call in text, "the recorded macro holds " + call)
    # The cancelled marching is not in it (replayed, it would make the VolumeMesh the later lines
    # do not mean).
    check(text.count("bvmesh.api.make_volume_mesh(") == 1, "the recorded macro holds the volume mesh made, "
          "not the cancelled one: " + str([line for line in text.splitlines() if "make_volume_mesh(" in line]))
    result = os.path.join(OUTPUT_DIR, "gui_volume_macro_replay.json")
    if os.path.exists(result):
        os.remove(result)
    code = ("import json, sys; exec(compile(open({macro!r}).read(), {macro!r}, 'exec')); "
            "g = App.ActiveDocument.getObject('VolumeGrid'); "
            "json.dump({{'digest': g.Digest, 'cells': g.CellCount}}, open({result!r}, 'w')); sys.exit(0)").format(
                macro=MACRO, result=result)
    done = subprocess.run(["freecadcmd", "-c", code], capture_output=True, text=True, timeout=300)
    check(done.returncode == 0 and os.path.exists(result),
          "the macro replays in freecadcmd -c (rc {}): {}".format(done.returncode, done.stderr[-2000:]))
    replay = json.load(open(result))
    check(replay == {"digest": grid.Digest, "cells": grid.CellCount},
          "the replay gives the same grid, point for point (digest {})".format(replay["digest"]))


def reopen_and_recompute(doc):
    import FreeCAD

    from bvmesh import api

    digests = {o.Name: o.Digest for o in doc.Objects if "Digest" in o.PropertiesList}
    points = api.grid_of(doc.getObject("VolumeGrid")).grid.points(5).tolist()
    FreeCAD.closeDocument(doc.Name)
    doc = FreeCAD.openDocument(SAVED)
    try:
        check(api.grid_of(doc.getObject("VolumeGrid")).grid.points(5).tolist() == points,
              "the reopened grid evaluates to the same points")
        for obj in doc.Objects:
            obj.touch()
        doc.recompute()
        check(all(o.isValid() for o in doc.Objects), "every object recomputes after reopening")
        check({o.Name: o.Digest for o in doc.Objects if "Digest" in o.PropertiesList} == digests,
              "with identical blocks and grid")
    finally:
        FreeCAD.closeDocument(doc.Name)


def main_job_document_shows_its_grid():
    """The main job's M6.FCStd (written headless) opens with its grid and cut on screen."""
    import FreeCAD
    import FreeCADGui

    code = ("import sys; from bvmesh import example; "
            "example.run({!r}, max_level=2, log=lambda line: None); sys.exit(0)").format(MAIN_JOB_DIR)
    done = subprocess.run(["freecadcmd", "-c", code], capture_output=True, text=True, timeout=240)
    path = os.path.join(MAIN_JOB_DIR, "M6.FCStd")
    check(done.returncode == 0 and os.path.exists(path), "the main job ran: " + done.stderr[-1000:])
    doc = FreeCAD.openDocument(path)
    try:
        shown = sorted(o.Name for o in doc.Objects if o.ViewObject.Visibility)
        check(shown == ["GridCut", "VolumeGrid"], "its final objects are shown: {}".format(shown))
        check(doc.getObject("VolumeGrid").ViewObject.Proxy is not None, "with BVMesh's view providers")
        settle(500)  # the view is fitted to them once the document is open, with no user action
        FreeCADGui.activeDocument().activeView().saveImage(MAIN_JOB_PICTURE, 1000, 700, "White")
        share = coloured_pixels(MAIN_JOB_PICTURE)
        check(share > 0.02, "the screenshot shows the grid ({:.1%} of the pixels)".format(share))
        log("main job document picture: " + MAIN_JOB_PICTURE)
    finally:
        FreeCAD.closeDocument(doc.Name)


start(run)

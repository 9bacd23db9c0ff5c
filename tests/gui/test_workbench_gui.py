# GUI test, run as a FreeCAD macro by run_gui_test.sh: activates the BVMesh workbench, checks its
# toolbar and menu, runs the example command through the toolbar action, saves a screenshot of
# the main window under the build tree and exits with 0 on success, 1 on any failure.
import os
import subprocess
import sys

from PySide import QtCore, QtGui

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gui_harness import check, log, settle, start  # noqa: E402

OUTPUT_DIR = os.environ.get("BVMESH_TEST_OUTPUT_DIR", "/tmp")
SCREENSHOT = os.path.join(OUTPUT_DIR, "gui_workbench.png")
VIEW_IMAGE = os.path.join(OUTPUT_DIR, "gui_workbench_view.png")
EXPECTED_COMMANDS = ["BVMesh_LoadExample", "BVMesh_ImportCad", "BVMesh_ShapeReport", "BVMesh_Target"]





def run():
    import FreeCAD
    import FreeCADGui

    check("BVMeshWorkbench" in FreeCADGui.listWorkbenches(), "BVMesh is in the workbench list")
    FreeCADGui.activateWorkbench("BVMeshWorkbench")
    settle()
    check(FreeCADGui.activeWorkbench().name() == "BVMeshWorkbench", "BVMesh is the active workbench")

    main_window = FreeCADGui.getMainWindow()
    toolbars = []
    for _ in range(50):  # the toolbars are shown a moment after activation
        toolbars = [bar for bar in main_window.findChildren(QtGui.QToolBar)
                    if bar.windowTitle() == "BVMesh CAD" and bar.isVisible()]
        if toolbars:
            break
        settle(100)
    check(len(toolbars) == 1 and toolbars[0].isVisible(), "the BVMesh CAD toolbar is shown (toolbars: {})".format(
        [bar.windowTitle() for bar in main_window.findChildren(QtGui.QToolBar) if bar.isVisible()]))
    actions = [action.objectName() for action in toolbars[0].actions()]
    check(actions == EXPECTED_COMMANDS, "the toolbar holds {} (found {})".format(EXPECTED_COMMANDS, actions))
    menus = [action.text() for action in main_window.menuBar().actions()]
    check("&BVMesh" in menus, "the BVMesh menu is in the menu bar (found {})".format(menus))

    toolbars[0].actions()[0].trigger()  # the Load Example button, as a user would click it
    settle(1000)
    doc = FreeCAD.ActiveDocument
    check(doc is not None and len(doc.Objects) == 1, "the example was added to a new document")
    check(len(doc.Objects[0].Shape.Faces) == 11, "the example wing has 11 faces")
    FreeCADGui.Selection.addSelection(doc.Objects[0])
    FreeCADGui.runCommand("BVMesh_ShapeReport")
    doc.undo()
    check(len(doc.Objects) == 0, "undo removes the imported wing")
    doc.redo()
    check(len(doc.Objects) == 1, "redo brings it back")

    check_preference_page()
    check_headless_document_gets_view_providers()

    FreeCADGui.SendMsgToActiveView("ViewFit")
    FreeCADGui.activeDocument().activeView().viewIsometric()
    settle(1000)
    # Qt's grab() leaves the OpenGL 3D view blank: take the X screen as a person sees it when
    # ImageMagick is there, else the widget grab; the 3D view alone is also rendered offscreen.
    if os.path.exists("/usr/bin/import"):
        subprocess.run(["/usr/bin/import", "-window", "root", SCREENSHOT], check=True, timeout=60)
    else:
        main_window.grab().save(SCREENSHOT)
    check(os.path.getsize(SCREENSHOT) > 0, "screenshot saved to " + SCREENSHOT)
    FreeCADGui.activeDocument().activeView().saveImage(VIEW_IMAGE, 800, 600, "White")
    check(os.path.getsize(VIEW_IMAGE) > 0, "3D view saved to " + VIEW_IMAGE)


def check_headless_document_gets_view_providers():
    """A document written without the GUI (as by the main job) opens with BVMesh's view providers."""
    import FreeCAD

    path = os.path.join(OUTPUT_DIR, "headless_polyhedron.FCStd")
    code = ("import FreeCAD, bvmesh.api as api; doc = FreeCAD.newDocument('Headless'); "
            "api.make_polyhedron(doc, [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [[0, 1, 2, 3]], "
            "creases=[[0, 1]]); doc.saveAs({!r})".format(path))
    done = subprocess.run(["freecadcmd", "-c", code], capture_output=True, text=True, timeout=120)
    check(done.returncode == 0 and os.path.exists(path), "a document was written headless: " + done.stderr[-300:])
    doc = FreeCAD.openDocument(path)
    try:
        proxy = doc.getObject("ControlPolyhedron").ViewObject.Proxy
        check(type(proxy).__name__ == "ViewProvider" and proxy.getIcon().endswith(".svg"),
              "its polyhedron got BVMesh's view provider in the GUI ({})".format(type(proxy).__name__))
    finally:
        FreeCAD.closeDocument(doc.Name)


def check_preference_page():
    """The BVMesh page of FreeCAD's preferences shows and stores BVMesh's parameters."""
    import FreeCADGui

    from bvmesh import preferences

    group = preferences.group()
    group.SetFloat("RelativeTolerance", 2.5e-5)
    seen = {}

    def edit():
        dialog = QtGui.QApplication.activeModalWidget()
        if dialog is None:
            QtCore.QTimer.singleShot(100, edit)
            return
        spin = dialog.findChild(QtGui.QDoubleSpinBox, "prefRelativeTolerance")
        seen["shown"] = None if spin is None else spin.value()
        if spin is not None:
            spin.setValue(3e-5)
            seen["threads"] = dialog.findChild(QtGui.QSpinBox, "prefThreads") is not None
            seen["color"] = dialog.findChild(QtGui.QPushButton, "prefCreaseColor") is not None
        for box in dialog.findChildren(QtGui.QDialogButtonBox):
            if box.button(QtGui.QDialogButtonBox.Ok) is not None:
                box.button(QtGui.QDialogButtonBox.Ok).click()
                return
        dialog.reject()

    QtCore.QTimer.singleShot(300, edit)
    FreeCADGui.runCommand("Std_DlgPreferences")
    try:
        check(seen.get("shown") == 2.5e-5, "the BVMesh preference page shows the stored tolerance ({})".format(seen))
        check(seen.get("threads") and seen.get("color"), "it offers threads and colours")
        check(preferences.relative_tolerance() == 3e-5, "OK stored the edited tolerance")
    finally:
        group.RemFloat("RelativeTolerance")


start(run)

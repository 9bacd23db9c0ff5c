"""Toolbar and menu commands. Each one runs the public API through FreeCADGui.doCommand inside a
transaction, so the Python console shows the call, a recorded macro replays it headless, and
Undo takes it back."""

import FreeCAD
import FreeCADGui

import bvmesh
from bvmesh import paths

_core_error = None


def core_available():
    global _core_error
    try:
        bvmesh.load_core()
        return True
    except ImportError as error:
        _core_error = str(error)
        return False


def core_error():
    return _core_error


def _selected_shape_object():
    selection = FreeCADGui.Selection.getSelection()
    if len(selection) == 1 and hasattr(selection[0], "Shape") and not selection[0].Shape.isNull():
        return selection[0]
    return None


def run_in_transaction(title, lines):
    """Runs `lines` of Python through doCommand inside one undo transaction of the active
    document; on an error the transaction is aborted, so the document is left as it was, and
    the error goes to the Report view."""
    doc = FreeCAD.ActiveDocument
    doc.openTransaction(title)
    try:
        FreeCADGui.addModule("bvmesh.api")
        for line in lines:
            FreeCADGui.doCommand(line)
    except Exception as error:  # any failure of the command must leave the document intact
        doc.abortTransaction()
        FreeCAD.Console.PrintError("BVMesh: {} failed: {}\n".format(title, error))
        return False
    doc.commitTransaction()
    return True


class ImportCad:
    """Adds a STEP / IGES / BREP file to the document as the CAD target."""

    def GetResources(self):
        return {
            "Pixmap": paths.icon("BVMesh_ImportCad"),
            "MenuText": "Import CAD geometry",
            "ToolTip": "Read a STEP, IGES or BREP file with the BVMesh core and add it as a Part object",
        }

    def IsActive(self):
        return True

    def Activated(self):
        from PySide import QtGui

        path, _ = QtGui.QFileDialog.getOpenFileName(
            FreeCADGui.getMainWindow(), "Import CAD geometry", paths.EXAMPLE_DATA_DIR,
            "CAD files (*.step *.stp *.iges *.igs *.brep *.brp)",
        )
        if path:
            _import_into_active_document(path)


class LoadExample:
    """Adds the bundled example, the ONERA M6 half wing, to the document."""

    def GetResources(self):
        return {
            "Pixmap": paths.icon("BVMesh_LoadExample"),
            "MenuText": "Load the ONERA M6 example",
            "ToolTip": "Add the ONERA M6 half wing (STEP, 11 faces, sharp trailing edge) to the document",
        }

    def IsActive(self):
        return True

    def Activated(self):
        _import_into_active_document(paths.EXAMPLE_WING)


def _import_into_active_document(path):
    if FreeCAD.ActiveDocument is None:
        FreeCADGui.doCommand("App.newDocument()")
    if run_in_transaction("Import CAD geometry",
                          ["bvmesh.api.import_cad(App.ActiveDocument, {!r})".format(path)]):
        FreeCADGui.SendMsgToActiveView("ViewFit")


class ShapeReport:
    """Reports faces, surface types and feature edges of the selected shape."""

    def GetResources(self):
        return {
            "Pixmap": paths.icon("BVMesh_ShapeReport"),
            "MenuText": "CAD report",
            "ToolTip": "Report the faces, surface types, bounding box and sharp / free edges of the "
                       "selected shape in the Report view",
        }

    def IsActive(self):
        return _selected_shape_object() is not None

    def Activated(self):
        target = _selected_shape_object()
        FreeCADGui.addModule("bvmesh.api")
        FreeCADGui.doCommand(
            "bvmesh.api.print_shape_report(App.ActiveDocument.getObject({!r}))".format(target.Name)
        )


# (name, command, needs the compiled core)
_COMMANDS = (
    ("BVMesh_LoadExample", LoadExample, True),
    ("BVMesh_ImportCad", ImportCad, True),
    ("BVMesh_ShapeReport", ShapeReport, True),
)


def register_commands():
    """Registers the commands that can work and returns their names, in toolbar order."""
    have_core = core_available()
    names = []
    for name, command, needs_core in _COMMANDS:
        if needs_core and not have_core:
            continue
        FreeCADGui.addCommand(name, command())
        names.append(name)
    return names

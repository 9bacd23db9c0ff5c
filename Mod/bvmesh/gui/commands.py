"""Toolbar and menu commands. Each one runs the public API inside a transaction and, once it
succeeded, puts the call through FreeCADGui.doCommand, so the Python console shows it, a recorded
macro replays it headless, and Undo takes it back. A failing or cancelled command aborts its
transaction: the document stays as it was and the macro does not hold it."""

import types

import __main__
import FreeCAD
import FreeCADGui

import bvmesh
from bvmesh import extensions, paths, preferences
from bvmesh.features import bspline_shell, grid_cut, polyhedron, surface_fit, target, volume_grid, volume_mesh
from bvmesh.features.common import WorkCancelled, is_type

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


def _is_cad_object(obj):
    """An object with a shape that is not one of BVMesh's own."""
    return (hasattr(obj, "Shape") and not obj.Shape.isNull()
            and getattr(getattr(obj, "Proxy", None), "Type", None) is None)


def _object_ref(obj):
    return "App.ActiveDocument.getObject({!r})".format(obj.Name)


def find_object(type_name):
    """The selected BVMesh object of this type, else the only one in the active document."""
    for obj in FreeCADGui.Selection.getSelection():
        if is_type(obj, type_name):
            return obj
        # a distance map or shell stands for its fit, a grid's cut, quality or export for the grid, ...
        for link in ("Fit", "VolumeMesh", "Grid", "Source"):
            if is_type(getattr(obj, link, None), type_name):
                return getattr(obj, link)
    doc = FreeCAD.ActiveDocument
    if doc is None:
        return None
    found = [o for o in doc.Objects if is_type(o, type_name)]
    return found[0] if len(found) == 1 else None


def run_in_transaction(title, lines):
    """Runs `lines` (bvmesh.api calls) inside one undo transaction of the active document, where
    doCommand runs its lines (__main__, with App and Gui), and records them in the macro once they
    all succeeded. On an error or a Cancel the transaction is aborted, so the document is left as it
    was, the error goes to the Report view, and nothing is recorded: a macro recorded through a
    cancelled marching used to replay it to the end and create an object the later lines did not
    mean, and a failed line stopped the replay."""
    doc = FreeCAD.ActiveDocument
    doc.openTransaction(title)
    try:
        exec("import bvmesh.api", __main__.__dict__)
        for line in lines:
            exec(line, __main__.__dict__)
    except Exception as error:  # any failure of the command must leave the document intact
        doc.abortTransaction()
        if any(kind.__name__ in str(error) for kind in (surface_fit.FitCancelled, WorkCancelled)):
            FreeCAD.Console.PrintWarning("BVMesh: {} cancelled; the document is as it was\n".format(title))
        else:
            FreeCAD.Console.PrintError("BVMesh: {} failed: {}\n".format(title, error))
        return False
    _record(lines)
    doc.commitTransaction()
    return True


class _CallsDone:
    """bvmesh.api as _record's lines see it: every call has already been made."""

    def __getattr__(self, name):
        return lambda *args, **kwargs: None


def _record(lines):
    """Puts lines that have run into the macro and the Python console. FreeCAD 0.20's doCommand is
    the only way to record a line and it runs the line too, so while it records them `bvmesh` in
    __main__ stands for a package whose API calls do nothing (their arguments are evaluated as
    before)."""
    # Not addModule: it records the import only the first time in a session, so a macro recorded
    # later would lack it. The macro recorder keeps one copy in the macro's header.
    FreeCADGui.doCommand("import bvmesh.api")
    package = __main__.__dict__.get("bvmesh")
    __main__.__dict__["bvmesh"] = types.SimpleNamespace(api=_CallsDone())
    try:
        for line in lines:
            FreeCADGui.doCommand(line)
    finally:
        __main__.__dict__["bvmesh"] = package


def _resources(icon, menu, tooltip):
    return {"Pixmap": paths.icon(icon), "MenuText": menu, "ToolTip": tooltip}


# -- CAD ------------------------------------------------------------------------------------------


class ImportCad:
    """Adds a STEP / IGES / BREP file to the document as the CAD target."""

    def GetResources(self):
        return _resources("BVMesh_ImportCad", "Import CAD geometry",
                          "Read a STEP, IGES or BREP file with the BVMesh core and add it as a Part object")

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
        return _resources("BVMesh_LoadExample", "Load the ONERA M6 example",
                          "Add the ONERA M6 half wing (STEP, 11 faces, sharp trailing edge) to the document")

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
        return _resources("BVMesh_ShapeReport", "CAD report",
                          "Report the faces, surface types, bounding box and sharp / free edges of the "
                          "selected shape in the Report view")

    def IsActive(self):
        return _selected_shape_object() is not None

    def Activated(self):
        obj = _selected_shape_object()
        FreeCADGui.doCommand("import bvmesh.api")
        FreeCADGui.doCommand("bvmesh.api.print_shape_report({})".format(_object_ref(obj)))


class MakeTarget:
    def GetResources(self):
        return _resources("BVMesh_Target", "Target from selection",
                          "Make the selected CAD object the fitting target; with faces selected, only "
                          "those faces are fitted (leave out e.g. a root face on the symmetry plane)")

    def IsActive(self):
        selection = FreeCADGui.Selection.getSelectionEx()
        return len(selection) == 1 and _is_cad_object(selection[0].Object)

    def Activated(self):
        selection = FreeCADGui.Selection.getSelectionEx()[0]
        faces = [name for name in selection.SubElementNames if name.startswith("Face")]
        line = "bvmesh.api.make_target(App.ActiveDocument, {}{})".format(
            _object_ref(selection.Object), ", faces={!r}".format(faces) if faces else "")
        run_in_transaction("BVMesh target", [line])


# -- polyhedron -----------------------------------------------------------------------------------


class PolyhedronManual:
    def GetResources(self):
        return _resources("BVMesh_PolyhedronManual", "Control polyhedron (typed)",
                          "Create a control polyhedron from typed vertex, face, crease and corner lists")

    def IsActive(self):
        return FreeCAD.ActiveDocument is not None and not FreeCADGui.Control.activeDialog()

    def Activated(self):
        from bvmesh.gui import task_panels

        FreeCADGui.Control.showDialog(task_panels.PolyhedronPanel(None))


def _polyhedron_source():
    selection = FreeCADGui.Selection.getSelection()
    if len(selection) != 1 or getattr(getattr(selection[0], "Proxy", None), "Type", None) is not None:
        return None
    obj = selection[0]
    if obj.isDerivedFrom("Mesh::Feature"):
        return obj
    if _is_cad_object(obj) and obj.Shape.Faces and all(
            f.Surface.TypeId == "Part::GeomPlane" for f in obj.Shape.Faces):
        return obj
    return None


class PolyhedronFromSelection:
    def GetResources(self):
        return _resources("BVMesh_PolyhedronFromMesh", "Control polyhedron from mesh / shape",
                          "Create a control polyhedron from the selected Mesh object, or from the selected "
                          "Part shape made of planar polygon faces")

    def IsActive(self):
        return _polyhedron_source() is not None

    def Activated(self):
        source = _polyhedron_source()
        function = "make_polyhedron_from_mesh" if source.isDerivedFrom("Mesh::Feature") else "make_polyhedron_from_shape"
        run_in_transaction("BVMesh polyhedron", ["bvmesh.api.{}(App.ActiveDocument, {})".format(
            function, _object_ref(source))])


class PolyhedronFromTemplate:
    def GetResources(self):
        available, reason = extensions.templates_available()
        tooltip = "Create a control polyhedron by placing a template on the target, with its feature map"
        if not available:
            tooltip += " (unavailable: {})".format(reason)
        return _resources("BVMesh_PolyhedronFromTemplate", "Control polyhedron from template", tooltip)

    def IsActive(self):
        return extensions.templates_available()[0] and find_object(target.TYPE) is not None

    def Activated(self):
        from PySide import QtGui

        names = extensions.template_names()
        name, ok = QtGui.QInputDialog.getItem(FreeCADGui.getMainWindow(), "Template", "Template:", names, 0, False)
        if ok:
            run_in_transaction("BVMesh polyhedron from template", [
                "bvmesh.api.make_polyhedron_from_template(App.ActiveDocument, {}, {!r})".format(
                    _object_ref(find_object(target.TYPE)), str(name))])


def picked_features():
    """(polyhedron, crease pairs, corner ids) of the edges / vertices picked on a polyhedron."""
    for selection in FreeCADGui.Selection.getSelectionEx():
        obj = selection.Object
        if not is_type(obj, polyhedron.TYPE) or not selection.SubElementNames:
            continue
        mesh = polyhedron.control_mesh(obj)
        edges = mesh.edges
        creases, corners = [], []
        for name in selection.SubElementNames:
            if name.startswith("Edge"):
                creases.append([int(v) for v in edges[polyhedron.edge_of_element(obj, name)]])
            elif name.startswith("Vertex"):
                corners.append(polyhedron.vertex_of_element(obj, name))
        if creases or corners:
            return obj, creases, corners
    return None, [], []


class MarkFeatures:
    def GetResources(self):
        return _resources("BVMesh_MarkFeatures", "Mark creases and corners",
                          "Mark the selected edges of a control polyhedron as creases and the selected "
                          "vertices as corners; when all of them are marked already, clear them")

    def IsActive(self):
        return picked_features()[0] is not None

    def Activated(self):
        obj, creases, corners = picked_features()
        marked = {tuple(sorted(p)) for p in polyhedron.pairs(obj.Creases)}
        unmark = all(tuple(sorted(p)) in marked for p in creases) and all(c in obj.Corners for c in corners)
        line = "bvmesh.api.mark_features({}, creases={!r}, corners={!r}{})".format(
            _object_ref(obj), creases, corners, ", unmark=True" if unmark else "")
        if run_in_transaction("BVMesh creases and corners", [line]):
            FreeCADGui.Selection.clearSelection()


class DetectCreases:
    def GetResources(self):
        return _resources("BVMesh_DetectCreases", "Detect creases",
                          "Mark the polyhedron's edges that run along sharp edges of the target as creases")

    def IsActive(self):
        return find_object(polyhedron.TYPE) is not None and find_object(target.TYPE) is not None

    def Activated(self):
        run_in_transaction("BVMesh detect creases", ["bvmesh.api.detect_creases({}, {})".format(
            _object_ref(find_object(polyhedron.TYPE)), _object_ref(find_object(target.TYPE)))])


# -- fitting --------------------------------------------------------------------------------------


class MakeSurfaceFit:
    def GetResources(self):
        return _resources("BVMesh_SurfaceFit", "Surface fit",
                          "Create the surface fit of the control polyhedron to the target (parameters from "
                          "the preferences; a left-out planar target face, or the symmetry plane of the flow "
                          "domain the target took its body from, becomes the symmetry plane)")

    def IsActive(self):
        return find_object(polyhedron.TYPE) is not None and find_object(target.TYPE) is not None

    def Activated(self):
        from bvmesh import api

        target_obj = find_object(target.TYPE)
        parameters = "relative_tolerance={!r}, max_level={!r}".format(
            preferences.relative_tolerance(), preferences.max_level())
        plane = api.symmetry_plane_guess(target_obj)
        if plane is not None:
            parameters += ", symmetry_plane={!r}".format(plane)
        run_in_transaction("BVMesh surface fit", ["bvmesh.api.make_surface_fit(App.ActiveDocument, {}, {}, {})".format(
            _object_ref(target_obj), _object_ref(find_object(polyhedron.TYPE)), parameters)])


class FitParameters:
    def GetResources(self):
        return _resources("BVMesh_FitParameters", "Fit parameters",
                          "Edit tolerance, levels, solver, weights and smoothing of the surface fit")

    def IsActive(self):
        return find_object(surface_fit.TYPE) is not None and not FreeCADGui.Control.activeDialog()

    def Activated(self):
        from bvmesh.gui import task_panels

        FreeCADGui.Control.showDialog(task_panels.FitPanel(find_object(surface_fit.TYPE)))


class FitStep:
    """One step of the iteration on the surface fit (subdivide, project, ...)."""

    def __init__(self, function, icon, menu, tooltip):
        self.function, self.icon, self.menu, self.tooltip = function, icon, menu, tooltip

    def GetResources(self):
        return _resources(self.icon, self.menu, self.tooltip)

    def IsActive(self):
        return find_object(surface_fit.TYPE) is not None

    def Activated(self):
        fit = find_object(surface_fit.TYPE)
        run_in_transaction("BVMesh " + self.menu.lower(), ["bvmesh.api.{}({})".format(self.function, _object_ref(fit))])


class FitToTolerance(FitStep):
    def __init__(self):
        super().__init__("fit_to_tolerance", "BVMesh_FitToTolerance", "Fit to tolerance",
                         "Subdivide, project, approximate and correct level after level until the "
                         "tolerance (progress in the status bar; Cancel restores the document)")

    def Activated(self):
        from bvmesh.gui import progress

        with surface_fit.fit_runner(progress.GuiFitRunner()):
            super().Activated()


class DistanceMap:
    def GetResources(self):
        return _resources("BVMesh_DistanceMap", "Distance map",
                          "Show the limit surface coloured by its distance to the target, with a legend")

    def IsActive(self):
        fit = find_object(surface_fit.TYPE)
        return fit is not None and len(fit.ControlVertices) > 0

    def Activated(self):
        from bvmesh.gui import plots

        fit = find_object(surface_fit.TYPE)
        if run_in_transaction("BVMesh distance map", ["bvmesh.api.make_distance_map({})".format(_object_ref(fit))]):
            dmap = FreeCAD.ActiveDocument.Objects[-1]
            fit.ViewObject.Visibility = False
            plots.show_legend(dmap)


class ConvergencePlot:
    def GetResources(self):
        return _resources("BVMesh_ConvergencePlot", "Convergence plot",
                          "Plot max and RMS distance per pass (log scale) and save it as PNG")

    def IsActive(self):
        fit = find_object(surface_fit.TYPE)
        return fit is not None and len(fit.HistoryMax) > 0

    def Activated(self):
        from bvmesh.gui import plots

        fit = find_object(surface_fit.TYPE)
        path = plots.default_plot_path(fit)
        FreeCADGui.doCommand("import bvmesh.api")
        FreeCADGui.doCommand("bvmesh.api.plot_convergence({}, {!r})".format(_object_ref(fit), path))
        plots.show_image("Convergence of " + fit.Label, path)


class BsplineShell:
    def GetResources(self):
        available, reason = extensions.shell_available()
        tooltip = "Convert the fitted limit surface into a sewn shell of B-spline faces"
        if not available:
            tooltip += " (unavailable: {})".format(reason)
        return _resources("BVMesh_BsplineShell", "B-spline shell", tooltip)

    def IsActive(self):
        fit = find_object(surface_fit.TYPE)
        return extensions.shell_available()[0] and fit is not None and len(fit.ControlVertices) > 0

    def Activated(self):
        run_in_transaction("BVMesh B-spline shell", ["bvmesh.api.make_bspline_shell({})".format(
            _object_ref(find_object(surface_fit.TYPE)))])


class ExportStep:
    def GetResources(self):
        return _resources("BVMesh_ExportStep", "Export surface (STEP)",
                          "Write the selected B-spline shell to a STEP file")

    def IsActive(self):
        shell = find_object(bspline_shell.TYPE)
        return shell is not None and not shell.Shape.isNull()

    def Activated(self):
        from PySide import QtGui

        shell = find_object(bspline_shell.TYPE)
        path, _ = QtGui.QFileDialog.getSaveFileName(FreeCADGui.getMainWindow(), "Export surface", "",
                                                    "STEP (*.step *.stp)")
        if path:
            FreeCADGui.doCommand("import bvmesh.api")
            FreeCADGui.doCommand("bvmesh.api.export_step({}, {!r})".format(_object_ref(shell), path))


# -- volume ---------------------------------------------------------------------------------------


class MakeVolumeMesh:
    def GetResources(self):
        return _resources("BVMesh_VolumeMesh", "Volume mesh",
                          "Grow the boundary layer and march the far field from the fitted wall into tricubic "
                          "B-spline blocks (options in a task panel; Cancel restores the document)")

    def IsActive(self):
        fit = find_object(surface_fit.TYPE)
        return fit is not None and len(fit.ControlVertices) > 0 and not FreeCADGui.Control.activeDialog()

    def Activated(self):
        from bvmesh.gui import task_panels

        FreeCADGui.Control.showDialog(task_panels.VolumeMeshPanel(None, find_object(surface_fit.TYPE)))


class MakeVolumeGrid:
    def GetResources(self):
        return _resources("BVMesh_VolumeGrid", "Volume grid",
                          "Evaluate the B-spline blocks on a stretched, point-matched grid (euler or rans preset)")

    def IsActive(self):
        return find_object(volume_mesh.TYPE) is not None and not FreeCADGui.Control.activeDialog()

    def Activated(self):
        from bvmesh.gui import task_panels

        FreeCADGui.Control.showDialog(task_panels.VolumeGridPanel(None, find_object(volume_mesh.TYPE)))


class GridCut:
    def GetResources(self):
        return _resources("BVMesh_GridCut", "Cut plane",
                          "Show the grid lines around the section at a span station, coloured by block or by a "
                          "quality metric")

    def IsActive(self):
        return find_object(volume_grid.TYPE) is not None

    def Activated(self):
        from PySide import QtGui

        from bvmesh.gui import plots

        window = FreeCADGui.getMainWindow()
        eta, ok = QtGui.QInputDialog.getDouble(window, "Cut plane", "Span fraction (0 at the symmetry plane):",
                                               0.44, 0.0, 1.0, 3)
        if not ok:
            return
        metric, ok = QtGui.QInputDialog.getItem(window, "Cut plane", "Colour by:", grid_cut.METRICS, 0, False)
        if not ok:
            return
        grid = find_object(volume_grid.TYPE)
        line = "bvmesh.api.make_grid_cut({}, eta={!r}, metric={!r})".format(_object_ref(grid), eta, str(metric))
        if run_in_transaction("BVMesh cut plane", [line]):
            cut = FreeCAD.ActiveDocument.Objects[-1]
            if cut.Metric != "block":
                plots.show_cut_legend(cut)


class MeshQuality:
    def GetResources(self):
        return _resources("BVMesh_MeshQuality", "Mesh quality",
                          "Measure the grid's cells (scaled Jacobian, non-orthogonality, skewness, aspect and "
                          "growth ratio, wall angle, first cell height): table in the Report view, histograms")

    def IsActive(self):
        return find_object(volume_grid.TYPE) is not None

    def Activated(self):
        import os

        from bvmesh.gui import plots, progress

        grid = find_object(volume_grid.TYPE)
        path = os.path.join(plots.output_dir(), "{}_{}_quality.png".format(grid.Document.Name, grid.Name))
        line = "bvmesh.api.make_mesh_quality({}, histogram_path={!r})".format(_object_ref(grid), path)
        with progress.work_runner_in_gui("Mesh quality"):
            done = run_in_transaction("BVMesh mesh quality", [line])
        if done:
            quality = FreeCAD.ActiveDocument.Objects[-1]
            FreeCAD.Console.PrintMessage("BVMesh: quality of {} ({} cells, {} non-positive)\n{}".format(
                grid.Label, quality.Cells, quality.NonPositiveCells, quality.Table))
            plots.show_image("Quality of " + grid.Label, path)


EXPORT_FILTERS = ("CGNS (*.cgns)", "OpenFOAM case (a new directory) (*)", "Plot3D (*.xyz *.p3d *.x)",
                  "VTK multiblock (*.vtm)", "G+Smo B-spline blocks (*.xml)", "BVMesh block file (*.blocks)")


class ExportGrid:
    def GetResources(self):
        return _resources("BVMesh_Export", "Export volume grid",
                          "Write the grid as CGNS, an OpenFOAM case, Plot3D or VTK, or the B-spline blocks as "
                          "G+Smo XML or a block file (the format from the file ending)")

    def IsActive(self):
        return find_object(volume_grid.TYPE) is not None

    def Activated(self):
        from PySide import QtGui

        from bvmesh.gui import plots, progress

        grid = find_object(volume_grid.TYPE)
        path, _ = QtGui.QFileDialog.getSaveFileName(FreeCADGui.getMainWindow(), "Export volume grid",
                                                    plots.output_dir(), ";;".join(EXPORT_FILTERS))
        if not path:
            return
        with progress.work_runner_in_gui("Export"):
            run_in_transaction("BVMesh export", ["bvmesh.api.export_grid({}, {!r})".format(_object_ref(grid), path)])


class OpenFoamCase:
    def GetResources(self):
        return _resources("BVMesh_Export", "OpenFOAM flow case",
                          "Write a complete OpenFOAM case on the grid with the solver you choose (compressible; "
                          "free stream and force references: the ONERA M6 wind-tunnel case, changed in the "
                          "export's Flow case properties); run it with bvmesh.openfoam_run.run_case")

    def IsActive(self):
        return find_object(volume_grid.TYPE) is not None

    def Activated(self):
        import os

        from PySide import QtGui

        from bvmesh import openfoam_case
        from bvmesh.gui import plots, progress

        grid = find_object(volume_grid.TYPE)
        window = FreeCADGui.getMainWindow()
        solvers = [s for s in openfoam_case.SOLVERS
                   if grid.Preset != "rans" or s not in openfoam_case.EULER_ONLY_SOLVERS]
        solver, ok = QtGui.QInputDialog.getItem(window, "OpenFOAM case", "Solver:", solvers,
                                                solvers.index(openfoam_case.DEFAULT_SOLVER), False)
        if not ok:
            return
        path = QtGui.QFileDialog.getExistingDirectory(window, "OpenFOAM case: parent folder", plots.output_dir())
        if not path:
            return
        case = os.path.join(path, "{}_case".format(grid.Name))
        with progress.work_runner_in_gui("OpenFOAM case"):
            run_in_transaction("BVMesh OpenFOAM case", ["bvmesh.api.export_grid({}, {!r}, file_format='openfoam_case', "
                                                        "name='OpenFoamCase', solver={!r})".format(
                                                            _object_ref(grid), case, solver)])


STEP_COMMANDS = (
    ("BVMesh_Subdivide", FitStep("subdivide", "BVMesh_Subdivide", "Subdivide",
                                 "Step 1: one Catmull-Clark subdivision of the fitted control mesh")),
    ("BVMesh_Project", FitStep("project", "BVMesh_Project", "Project",
                               "Step 3: project the limit samples onto the target (sample distances)")),
    ("BVMesh_Approximate", FitStep("approximate", "BVMesh_Approximate", "Approximate",
                                   "Step 4: least-squares control points for the projections")),
    ("BVMesh_CorrectParameters", FitStep("correct_parameters", "BVMesh_CorrectParameters", "Parameter correction",
                                         "Steps 2-4 again at the same level (CorrectionPasses times)")),
    ("BVMesh_Smooth", FitStep("smooth", "BVMesh_Smooth", "Smooth",
                              "Taubin smoothing of the control mesh, crease- and boundary-aware")),
    ("BVMesh_FitToTolerance", FitToTolerance()),
)

# (toolbar group, [(name, command)]); every command needs the compiled core except the first group's.
GROUPS = (
    ("BVMesh CAD", [("BVMesh_LoadExample", LoadExample()), ("BVMesh_ImportCad", ImportCad()),
                    ("BVMesh_ShapeReport", ShapeReport()), ("BVMesh_Target", MakeTarget())]),
    ("BVMesh polyhedron", [("BVMesh_PolyhedronManual", PolyhedronManual()),
                           ("BVMesh_PolyhedronFromMesh", PolyhedronFromSelection()),
                           ("BVMesh_PolyhedronFromTemplate", PolyhedronFromTemplate()),
                           ("BVMesh_MarkFeatures", MarkFeatures()), ("BVMesh_DetectCreases", DetectCreases())]),
    ("BVMesh fit", [("BVMesh_SurfaceFit", MakeSurfaceFit()), ("BVMesh_FitParameters", FitParameters())]
     + list(STEP_COMMANDS)),
    ("BVMesh results", [("BVMesh_DistanceMap", DistanceMap()), ("BVMesh_ConvergencePlot", ConvergencePlot()),
                        ("BVMesh_BsplineShell", BsplineShell()), ("BVMesh_ExportStep", ExportStep())]),
    ("BVMesh volume", [("BVMesh_VolumeMesh", MakeVolumeMesh()), ("BVMesh_VolumeGrid", MakeVolumeGrid()),
                       ("BVMesh_GridCut", GridCut()), ("BVMesh_MeshQuality", MeshQuality()),
                       ("BVMesh_ExportGrid", ExportGrid()), ("BVMesh_OpenFoamCase", OpenFoamCase())]),
)


def _add_command(name, command):
    # FreeCAD writes "import <file name of addCommand's caller>" into macros recorded while the
    # command runs; calling it from code compiled under the name "bvmesh" makes that line
    # "import bvmesh", which also works where the macro is replayed.
    exec(compile("FreeCADGui.addCommand(name, command)", "bvmesh", "exec"),
         {"FreeCADGui": FreeCADGui, "name": name, "command": command})


def register_commands():
    """Registers the commands (when the compiled core loads) and returns [(group, [names])]."""
    if not core_available():
        return []
    groups = []
    for group, commands in GROUPS:
        for name, command in commands:
            _add_command(name, command)
        groups.append((group, [name for name, _ in commands]))
    return groups

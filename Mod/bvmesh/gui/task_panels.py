"""Task panels (FreeCAD's combo-view dialogs) for polyhedron creation and fit parameters. Their
accept() runs the same API call a command would, in one transaction (commands.run_in_transaction)."""

import os

import FreeCAD
import FreeCADGui

from bvmesh import paths, volume
from bvmesh.features import polyhedron, surface_fit, volume_grid, volume_mesh
from bvmesh.features.common import is_type
from bvmesh.gui.commands import _object_ref, run_in_transaction

UI_DIR = os.path.join(paths.RESOURCES_DIR, "ui")


def load_form(name):
    """The form of resources/ui/<name>.ui, its named widgets also as attributes.

    PySide's own loader, not FreeCADGui.PySideUic.loadUi: that one hands back wrappers PySide does
    not track, so when the task dialog deletes a closed form its wrappers stay registered, and a
    new form allocated at the same address came back as the old, deleted widget (measured: 'Internal
    C++ object already deleted' in the second panel, now and then)."""
    from PySide import QtCore, QtGui, QtUiTools

    file = QtCore.QFile(os.path.join(UI_DIR, name + ".ui"))
    if not file.open(QtCore.QFile.ReadOnly):
        raise OSError("cannot read the form {}".format(file.fileName()))
    try:
        form = QtUiTools.QUiLoader().load(file)
    finally:
        file.close()
    for child in form.findChildren(QtGui.QWidget):
        if child.objectName():
            setattr(form, child.objectName(), child)
    return form


def panel_for(obj):
    if is_type(obj, polyhedron.TYPE):
        return PolyhedronPanel(obj)
    if is_type(obj, surface_fit.TYPE):
        return FitPanel(obj)
    if is_type(obj, volume_mesh.TYPE):
        return VolumeMeshPanel(obj)
    if is_type(obj, volume_grid.TYPE):
        return VolumeGridPanel(obj)
    return None


def _numbers(text, kind, what):
    try:
        return [kind(word) for word in text.replace(",", " ").split()]
    except ValueError as error:
        raise ValueError("{}: {}".format(what, error)) from None


def parse_polyhedron(vertices_text, faces_text, creases_text, corners_text):
    """(vertices, faces, creases, corners) from the panel's texts; ValueError naming the line."""
    vertices, faces, creases = [], [], []
    for n, line in enumerate(vertices_text.splitlines()):
        if line.strip():
            values = _numbers(line, float, "vertex line {}".format(n + 1))
            if len(values) != 3:
                raise ValueError("vertex line {} must hold x y z, got '{}'".format(n + 1, line.strip()))
            vertices.append(values)
    for n, line in enumerate(faces_text.splitlines()):
        if line.strip():
            faces.append(_numbers(line, int, "face line {}".format(n + 1)))
    for n, line in enumerate(creases_text.splitlines()):
        if line.strip():
            pair = _numbers(line, int, "crease line {}".format(n + 1))
            if len(pair) != 2:
                raise ValueError("crease line {} must hold two vertex ids, got '{}'".format(n + 1, line.strip()))
            creases.append(pair)
    return vertices, faces, creases, _numbers(corners_text, int, "corners")


class _Panel:
    """What every BVMesh task panel does on Cancel: close, leaving the document as it was."""

    def reject(self):
        FreeCADGui.Control.closeDialog()
        return True


class PolyhedronPanel(_Panel):
    """Creates a polyhedron (obj None) or edits the data of `obj`."""

    def __init__(self, obj):
        self.obj = obj
        self.form = load_form("polyhedron")
        if obj is not None:
            self.form.textVertices.setPlainText("\n".join("{!r} {!r} {!r}".format(v.x, v.y, v.z) for v in obj.Vertices))
            faces = polyhedron.unflatten_faces(obj.FaceSizes, obj.FaceIndices)
            self.form.textFaces.setPlainText("\n".join(" ".join(map(str, f)) for f in faces))
            self.form.textCreases.setPlainText("\n".join("{} {}".format(*p) for p in polyhedron.pairs(obj.Creases)))
            self.form.lineCorners.setText(" ".join(map(str, obj.Corners)))

    def getStandardButtons(self):
        from PySide import QtGui

        return int(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)

    def accept(self):
        try:
            vertices, faces, creases, corners = parse_polyhedron(
                self.form.textVertices.toPlainText(), self.form.textFaces.toPlainText(),
                self.form.textCreases.toPlainText(), self.form.lineCorners.text())
        except ValueError as error:
            self.form.labelStatus.setText(str(error))
            return False
        if self.obj is None:
            line = "bvmesh.api.make_polyhedron(App.ActiveDocument, {!r}, {!r}, creases={!r}, corners={!r})".format(
                vertices, faces, creases, corners)
        else:
            line = "bvmesh.api.set_polyhedron({}, {!r}, {!r}, creases={!r}, corners={!r})".format(
                _object_ref(self.obj), vertices, faces, creases, corners)
        if not run_in_transaction("BVMesh polyhedron", [line]):
            self.form.labelStatus.setText("The polyhedron was not accepted: see the Report view.")
            return False
        FreeCADGui.Control.closeDialog()
        return True


def _vector_text(v):
    return "{!r} {!r} {!r}".format(v.x, v.y, v.z)


class FitPanel(_Panel):
    """Edits the parameters of a SurfaceFit; accept() sets the changed ones."""

    SPINS = (
        ("spinTolerance", "tolerance", "Tolerance"),
        ("spinRelativeTolerance", "relative_tolerance", "RelativeTolerance"),
        ("spinMaxLevel", "max_level", "MaxLevel"),
        ("spinMaxCorrections", "max_corrections", "MaxCorrections"),
        ("spinStagnation", "stagnation_ratio", "StagnationRatio"),
        ("spinCorrectionPasses", "correction_passes", "CorrectionPasses"),
        ("spinSmoothIterations", "smooth_iterations", "SmoothIterations"),
        ("spinSmoothLambda", "smooth_lambda", "SmoothLambda"),
        ("spinSmoothMu", "smooth_mu", "SmoothMu"),
    )
    WEIGHTS = ("smooth", "crease", "boundary", "corner")

    def __init__(self, fit):
        self.fit = fit
        self.form = load_form("fit")
        f = self.form
        for widget, _, prop in self.SPINS:
            getattr(f, widget).setValue(getattr(fit, prop))
        f.comboSolver.addItems(surface_fit.SOLVERS)
        f.comboSolver.setCurrentIndex(surface_fit.SOLVERS.index(fit.Solver))
        for kind in self.WEIGHTS:
            getattr(f, "spinWeight" + kind.capitalize()).setValue(getattr(fit, "Weight" + kind.capitalize()))
        f.checkSymmetry.setChecked(fit.UseSymmetryPlane)
        f.lineSymmetryPoint.setText(_vector_text(fit.SymmetryPoint))
        f.lineSymmetryNormal.setText(_vector_text(fit.SymmetryNormal))

    def getStandardButtons(self):
        from PySide import QtGui

        return int(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)

    def changed_parameters(self):
        """The parameters whose value in the form differs from the object's."""
        f, fit = self.form, self.fit
        changed = {}
        for widget, key, prop in self.SPINS:
            value = getattr(f, widget).value()
            if value != getattr(fit, prop):
                changed[key] = value
        if f.comboSolver.currentText() != fit.Solver:
            changed["solver"] = f.comboSolver.currentText()
        weights = {}
        for kind in self.WEIGHTS:
            value = getattr(f, "spinWeight" + kind.capitalize()).value()
            if value != getattr(fit, "Weight" + kind.capitalize()):
                weights[kind] = value
        if weights:
            changed["weights"] = weights
        point = tuple(_numbers(f.lineSymmetryPoint.text(), float, "plane point"))
        normal = tuple(_numbers(f.lineSymmetryNormal.text(), float, "plane normal"))
        if len(point) != 3 or len(normal) != 3:
            raise ValueError("the plane point and normal need three numbers each")
        current = ((fit.SymmetryPoint.x, fit.SymmetryPoint.y, fit.SymmetryPoint.z),
                   (fit.SymmetryNormal.x, fit.SymmetryNormal.y, fit.SymmetryNormal.z))
        if not f.checkSymmetry.isChecked():
            if fit.UseSymmetryPlane:
                changed["symmetry_plane"] = None
        elif not fit.UseSymmetryPlane or (point, normal) != current:
            changed["symmetry_plane"] = (point, normal)
        return changed

    def accept(self):
        try:
            changed = self.changed_parameters()
        except ValueError as error:
            FreeCAD.Console.PrintError("BVMesh: {}\n".format(error))
            return False
        if changed:
            arguments = ", ".join("{}={!r}".format(k, v) for k, v in changed.items())
            if not run_in_transaction("BVMesh fit parameters", ["bvmesh.api.set_fit_parameters({}, {})".format(
                    _object_ref(self.fit), arguments)]):
                return False
        FreeCADGui.Control.closeDialog()
        return True


class _OptionsPanel(_Panel):
    """A panel over a feature's OPTIONS and DISPLAY tables (widgets spin<Property>,
    check<Property>): creates the object (obj None, from `source`) or changes the options of `obj`
    through the API, in one transaction, the work in a worker thread with progress and Cancel."""

    form_name = title = create_function = set_function = None
    options = display = ()
    extra_spins = ()  # (property, keyword, default of a new object) outside OPTIONS
    combos = ()       # (property, keyword, choices)
    combo_defaults = {}  # property: the choice a new object starts with (else the first)
    switches = ()     # (property, keyword, default, description): check<Property>

    def __init__(self, obj, source=None):
        self.obj, self.source = obj, source
        self.form = load_form(self.form_name)
        for prop, keyword, choices in self.combos:
            widget = self.widget("combo", prop)
            widget.addItems(choices)
            widget.setCurrentIndex(choices.index(self.current(prop, self.combo_defaults.get(prop, choices[0]))))
        for prop, _, _, default, _ in self.options:
            self.widget("spin", prop, default).setValue(self.current(prop, default))
        for prop, _, default in self.extra_spins:
            self.widget("spin", prop, default).setValue(self.current(prop, default))
        for prop, _, default in self.display:
            self.widget("check", prop).setChecked(self.current(prop, default))
        for prop, _, default, _ in self.switches:
            self.widget("check", prop).setChecked(self.current(prop, default))

    def widget(self, kind, prop, default=None):
        """The form's widget for a property, looked up with its class (an attribute lookup can
        come back as a plain QWidget)."""
        from PySide import QtGui

        classes = {"combo": QtGui.QComboBox, "check": QtGui.QCheckBox,
                   "spin": QtGui.QSpinBox if isinstance(default, int) else QtGui.QDoubleSpinBox}
        found = self.form.findChild(classes[kind], kind + prop)
        if found is None:
            raise LookupError("the {} form has no {}{}".format(self.form_name, kind, prop))
        return found

    def current(self, prop, default):
        return default if self.obj is None else getattr(self.obj, prop)

    def getStandardButtons(self):
        from PySide import QtGui

        return int(QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel)

    def changed(self):
        """API keywords whose value in the form differs from the object's (or the defaults)."""
        changed = {}
        for prop, keyword, choices in self.combos:
            value = self.widget("combo", prop).currentText()
            if self.obj is None or value != getattr(self.obj, prop):
                changed[keyword] = value
        for prop, keyword, _, default, _ in self.options:
            value = self.widget("spin", prop, default).value()
            if value != self.current(prop, default):
                changed[keyword] = value
        for prop, keyword, default in self.extra_spins:
            value = self.widget("spin", prop, default).value()
            if value != self.current(prop, default):
                changed[keyword] = value
        for prop, keyword, default, _ in self.switches:
            value = self.widget("check", prop).isChecked()
            if value != self.current(prop, default):
                changed[keyword] = value
        shown = tuple(condition for prop, condition, _ in self.display if self.widget("check", prop).isChecked())
        if shown != tuple(condition for prop, condition, default in self.display if self.current(prop, default)):
            changed["show"] = shown
        return changed

    def argument(self, keyword, value):
        """The keyword argument as the macro line writes it."""
        return ", {}={!r}".format(keyword, value)

    def accept(self):
        from bvmesh.gui import progress

        changed = self.changed()
        arguments = "".join(self.argument(k, v) for k, v in changed.items())
        if self.obj is None:
            line = "bvmesh.api.{}({}{})".format(self.create_function, _object_ref(self.source), arguments)
        elif changed:
            line = "bvmesh.api.{}({}{})".format(self.set_function, _object_ref(self.obj), arguments)
        else:
            FreeCADGui.Control.closeDialog()
            return True
        with progress.work_runner_in_gui(self.title):
            done = run_in_transaction("BVMesh " + self.title.lower(), [line])
        if not done:
            self.form.labelStatus.setText("Not done: see the Report view.")
            return False
        if self.obj is None and self.source is not None and self.source.ViewObject is not None:
            self.source.ViewObject.Visibility = False  # the new stage's object is what to look at now
        FreeCADGui.Control.closeDialog()
        return True


class VolumeMeshPanel(_OptionsPanel):
    form_name, title = "volume_mesh", "Volume mesh"
    create_function, set_function = "make_volume_mesh", "set_volume_options"
    options, display = volume_mesh.OPTIONS, volume_mesh.DISPLAY
    switches = volume_mesh.SWITCHES
    extra_spins = (("WallLevel", "wall_level", -1), ("MarchingLevel", "marching_level", -1),
                   ("MarchingPointLimit", "marching_point_limit", volume.MARCHING_POINT_LIMIT))
    combos = (("Domain", "domain", volume_mesh.DOMAINS),
              ("FarfieldScheme", "farfield_scheme", volume_mesh.FARFIELD_SCHEMES))
    combo_defaults = {"FarfieldScheme": volume_mesh.NEW_MESH_FARFIELD_SCHEME}  # as make_volume_mesh

    def __init__(self, obj, source=None):
        super().__init__(obj, source)
        # A new volume mesh on a flow domain's body takes that domain, as make_volume_mesh does.
        target = getattr(source, "Target", None)
        if obj is None and getattr(target, "FlowDomain", ""):
            self.widget("combo", "Domain").setCurrentIndex(volume_mesh.DOMAINS.index("cad"))


class VolumeGridPanel(_OptionsPanel):
    form_name, title = "volume_grid", "Volume grid"
    create_function, set_function = "make_volume_grid", "set_grid_options"
    options, display = volume_grid.OPTIONS + volume_grid.SUBDIVISION_OPTIONS, volume_grid.DISPLAY
    switches = volume_grid.SWITCHES
    combos = (("Method", "method", volume_grid.METHODS), ("Preset", "preset", volume_grid.PRESETS),
              ("Distribution", "distribution", volume_grid.DISTRIBUTIONS))

    def __init__(self, obj, source=None):
        from PySide import QtGui

        super().__init__(obj, source)
        # Feature edges as (object, (edge names, ...)), taken from the selection by the button.
        self.feature_edges = self.saved_feature_edges()
        self.widget("spin", "FeatureSpacing", 0.0).setValue(self.current("FeatureSpacing", 0.0))
        self.form.findChild(QtGui.QPushButton, "buttonFeatureEdges").clicked.connect(self.take_selected_edges)
        self.show_feature_edges()

    def saved_feature_edges(self):
        """The grid's FeatureEdges as (object, (edge names, ...)); none for a new grid."""
        return [(o, tuple(names)) for o, names in (self.obj.FeatureEdges if self.obj is not None else [])]

    def take_selected_edges(self):
        edges = []
        for selection in FreeCADGui.Selection.getSelectionEx():
            names = tuple(name for name in selection.SubElementNames if name.startswith("Edge"))
            if names:
                edges.append((selection.Object, names))
        self.feature_edges = edges
        self.show_feature_edges()

    def show_feature_edges(self):
        from PySide import QtGui

        text = "; ".join("{} ({})".format(", ".join(names), o.Label) for o, names in self.feature_edges)
        self.form.findChild(QtGui.QLabel, "labelFeatureEdges").setText(text or "none")

    def changed(self):
        changed = super().changed()
        if self.feature_edges != self.saved_feature_edges():
            changed["feature_edges"] = self.feature_edges
        spacing = self.widget("spin", "FeatureSpacing", 0.0).value()
        if spacing != self.current("FeatureSpacing", 0.0):
            changed["feature_spacing"] = spacing
        return changed

    def argument(self, keyword, value):
        if keyword != "feature_edges":
            return super().argument(keyword, value)
        edges = ", ".join("({}, {!r})".format(_object_ref(o), names) for o, names in value)
        return ", feature_edges=[{}]".format(edges)

"""View providers of BVMesh's objects: icons, crease colours on wireframes, per-vertex colours
of the distance map, task panels on double-click. Attached by bvmesh.api when FreeCAD.GuiUp."""

import colorsys

from bvmesh import paths, preferences
from bvmesh.features import (bspline_shell, distance_map, grid_cut, grid_export, mesh_quality, polyhedron,
                             surface_fit, target, volume_grid, volume_mesh)

# proxy Type -> icon name
_KINDS = {
    target.TYPE: "BVMesh_Target",
    polyhedron.TYPE: "BVMesh_PolyhedronManual",
    surface_fit.TYPE: "BVMesh_SurfaceFit",
    distance_map.TYPE: "BVMesh_DistanceMap",
    bspline_shell.TYPE: "BVMesh_BsplineShell",
    volume_mesh.TYPE: "BVMesh_VolumeMesh",
    volume_grid.TYPE: "BVMesh_VolumeGrid",
    grid_cut.TYPE: "BVMesh_GridCut",
    mesh_quality.TYPE: "BVMesh_MeshQuality",
    grid_export.TYPE: "BVMesh_Export",
}


def attach(obj):
    """Gives `obj` (a BVMesh object) its view provider."""
    ViewProvider(obj.ViewObject, _KINDS[obj.Proxy.Type])
    if obj.Proxy.Type == distance_map.TYPE:
        obj.ViewObject.Lighting = "Two side"  # both sides of the surface show their colours


_fits_pending = set()


def fit_view_once(doc):
    """Fits the 3D view of a document written headless to what it shows, once after it opened
    (its camera is in the GUI's view state, which a headless writer has not written): every object
    restored asks, the first request of the opening is carried out."""
    name = doc.Name
    if name in _fits_pending:
        return
    _fits_pending.add(name)

    def fit():
        import FreeCAD
        import FreeCADGui

        _fits_pending.discard(name)
        if name not in FreeCAD.listDocuments():
            return  # closed before the view came up
        gui_document = FreeCADGui.getDocument(name)
        if gui_document is not None and gui_document.activeView() is not None:
            gui_document.activeView().viewIsometric()
            gui_document.activeView().fitAll()

    from PySide import QtCore

    QtCore.QTimer.singleShot(0, fit)


def block_colors(blocks):
    """A distinct, light colour per block number (golden-ratio hues), for faces and cut lines."""
    return [colorsys.hsv_to_rgb((0.61803398875 * b) % 1.0, 0.45, 0.95) for b in blocks]


def cut_line_colors(cut):
    """Per-segment colours of a GridCut: by block, or along the distance map's ramp from the
    cut's smallest to its largest value."""
    values = list(cut.SegmentValues)
    if cut.Metric == "block":
        return [tuple(c) for c in block_colors(int(v) for v in values)]
    span = cut.ValueMax - cut.ValueMin
    shifted = [v - cut.ValueMin for v in values]
    return [tuple(map(float, c)) for c in distance_map.ramp_colors(shifted, span if span > 0 else 1.0)]


def crease_edge_colors(edges, crease_pairs):
    """Per-edge colours of a wireframe (one line per mesh edge): creases in the crease colour."""
    creases = {tuple(sorted(pair)) for pair in crease_pairs}
    edge_color, crease_color = preferences.edge_color(), preferences.crease_color()
    return [crease_color if tuple(sorted(map(int, e))) in creases else edge_color for e in edges]


class ViewProvider:
    def __init__(self, vobj, icon):
        self.icon = icon
        self.Object = vobj.Object
        vobj.Proxy = self

    def attach(self, vobj):
        self.Object = vobj.Object

    def getIcon(self):
        return paths.icon(self.icon)

    def __getstate__(self):
        return self.icon

    def __setstate__(self, state):
        self.icon = state

    dumps = __getstate__
    loads = __setstate__

    def claimChildren(self):
        obj = self.Object
        links = {surface_fit.TYPE: ("Fit",), volume_mesh.TYPE: ("VolumeMesh",),
                 volume_grid.TYPE: ("Grid", "Source")}.get(obj.Proxy.Type, ())
        return [o for o in obj.InList if any(getattr(o, link, None) == obj for link in links)]

    def updateData(self, obj, prop):
        kind = obj.Proxy.Type
        if prop == "Shape" and kind in (polyhedron.TYPE, surface_fit.TYPE):
            self._color_creases(obj)
        elif prop == "FaceBlocks" and kind == volume_mesh.TYPE:
            self._color_blocks(obj)
        elif prop == "SegmentValues" and kind == grid_cut.TYPE:
            vobj = obj.ViewObject
            if vobj is not None and len(obj.SegmentValues) == len(obj.Shape.Edges):
                vobj.LineColorArray = cut_line_colors(obj)
                vobj.LineWidth = 1.0
        elif prop == "VertexColors" and kind == distance_map.TYPE:
            vobj = obj.ViewObject
            if vobj is not None and "Coloring" in vobj.PropertiesList and len(obj.VertexColors):
                vobj.Coloring = False  # re-read the colour list
                vobj.Coloring = True

    def _color_blocks(self, obj):
        vobj = obj.ViewObject
        if vobj is None or len(obj.FaceBlocks) != len(obj.Shape.Faces):
            return
        vobj.DiffuseColor = block_colors(obj.FaceBlocks)
        vobj.LineColor = (0.1, 0.15, 0.25)  # the face borders are the block edges
        vobj.LineWidth = 2.0

    def _color_creases(self, obj):
        vobj = obj.ViewObject
        if vobj is None or obj.Shape.isNull():
            return
        try:
            if obj.Proxy.Type == polyhedron.TYPE:
                mesh = polyhedron.control_mesh(obj)
            else:
                mesh = surface_fit.result_mesh(obj)
        except ValueError:  # properties still being restored
            return
        vobj.LineColorArray = crease_edge_colors(mesh.edges, mesh.creases)
        vobj.LineWidth = 3.0
        vobj.PointSize = 5.0

    def doubleClicked(self, vobj):
        return self.setEdit(vobj, 0)

    def setEdit(self, vobj, mode=0):
        import FreeCADGui

        from bvmesh.gui import task_panels

        panel = task_panels.panel_for(vobj.Object)
        if panel is None:
            return False
        FreeCADGui.Control.showDialog(panel)
        return True

    def unsetEdit(self, vobj, mode=0):
        import FreeCADGui

        FreeCADGui.Control.closeDialog()
        return True

"""View providers of BVMesh's objects: icons, crease colours on wireframes, per-vertex colours
of the distance map, task panels on double-click. Attached by bvmesh.api when FreeCAD.GuiUp."""

from bvmesh import paths, preferences
from bvmesh.features import bspline_shell, distance_map, polyhedron, surface_fit, target

# proxy Type -> icon name
_KINDS = {
    target.TYPE: "BVMesh_Target",
    polyhedron.TYPE: "BVMesh_PolyhedronManual",
    surface_fit.TYPE: "BVMesh_SurfaceFit",
    distance_map.TYPE: "BVMesh_DistanceMap",
    bspline_shell.TYPE: "BVMesh_BsplineShell",
}


def attach(obj):
    """Gives `obj` (a BVMesh object) its view provider."""
    ViewProvider(obj.ViewObject, _KINDS[obj.Proxy.Type])
    if obj.Proxy.Type == distance_map.TYPE:
        obj.ViewObject.Lighting = "Two side"  # both sides of the surface show their colours


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
        if obj.Proxy.Type == surface_fit.TYPE:
            return [o for o in obj.InList if getattr(o, "Fit", None) == obj]
        return []

    def updateData(self, obj, prop):
        kind = obj.Proxy.Type
        if prop == "Shape" and kind in (polyhedron.TYPE, surface_fit.TYPE):
            self._color_creases(obj)
        elif prop == "VertexColors" and kind == distance_map.TYPE:
            vobj = obj.ViewObject
            if vobj is not None and "Coloring" in vobj.PropertiesList and len(obj.VertexColors):
                vobj.Coloring = False  # re-read the colour list
                vobj.Coloring = True

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

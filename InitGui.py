# BVMesh workbench, GUI part: FreeCAD runs this file when the GUI starts (after Init.py).
# Only the workbench class lives here; commands are imported when the workbench is activated,
# so a missing compiled core never stops FreeCAD from starting.
import FreeCAD
import FreeCADGui


class BVMeshWorkbench(FreeCADGui.Workbench):
    import bvmesh.paths as _paths

    MenuText = "BVMesh"
    ToolTip = "Block-structured B-spline surface and volume meshes for CFD from CAD geometry"
    Icon = _paths.icon("BVMesh_Workbench")

    def Initialize(self):
        from bvmesh.gui import workbench

        workbench.initialize(self)

    def Activated(self):
        pass

    def Deactivated(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


FreeCADGui.addWorkbench(BVMeshWorkbench())


def _add_preference_page():
    import os

    import bvmesh.paths

    FreeCADGui.addPreferencePage(os.path.join(bvmesh.paths.RESOURCES_DIR, "ui", "preferences.ui"), "BVMesh")


_add_preference_page()


# View providers are restored with documents too (see Init.py).
import bvmesh.gui.view_providers  # noqa: E402,F401

"""Toolbar and menu of the BVMesh workbench."""

import FreeCAD

from bvmesh.gui import commands

TOOLBAR = "BVMesh"
MENU = "&BVMesh"


def initialize(workbench):
    """Registers the commands and puts those that can work on the toolbar and the menu. Without
    the compiled core only the commands that do not need it are offered, and the Report view
    says why."""
    available = commands.register_commands()
    if not commands.core_available():
        FreeCAD.Console.PrintError(
            "BVMesh: the compiled core is missing, so the meshing commands are disabled: {}\n".format(
                commands.core_error()
            )
        )
    workbench.appendToolbar(TOOLBAR, available)
    workbench.appendMenu(MENU, available)

"""Toolbars and menu of the BVMesh workbench."""

import FreeCAD

from bvmesh import extensions
from bvmesh.gui import commands

MENU = "&BVMesh"


def initialize(workbench):
    """Registers the commands and puts them on one toolbar per stage and in the menu. Without
    the compiled core no command is offered, and the Report view says why; commands whose later
    stage is missing stay disabled, and the Report view and their tooltips say why."""
    groups = commands.register_commands()
    if not commands.core_available():
        FreeCAD.Console.PrintError(
            "BVMesh: the compiled core is missing, so the meshing commands are disabled: {}\n".format(
                commands.core_error()
            )
        )
        return
    for available, reason in (extensions.templates_available(), extensions.shell_available()):
        if not available:
            FreeCAD.Console.PrintLog("BVMesh: {}\n".format(reason))
    for group, names in groups:
        workbench.appendToolbar(group, names)
        workbench.appendMenu(MENU, names + ["Separator"])

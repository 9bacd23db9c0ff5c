"""BVMesh's FreeCAD GUI: commands, view providers and task panels. Only this package imports
FreeCADGui."""

# BVMesh workbench, headless part: FreeCAD runs this file at start-up, also in freecadcmd.
# It puts BVMesh's Python package (Mod/bvmesh below the workbench folder) on sys.path.
# FreeCAD executes this file without __file__, but it has already put the workbench folder on
# sys.path: find it there.
import os as _os
import sys as _sys

for _entry in list(_sys.path):
    _package_root = _os.path.normpath(_os.path.join(_entry, "Mod"))
    if _os.path.isfile(_os.path.join(_package_root, "bvmesh", "__init__.py")) and _os.path.isfile(
        _os.path.join(_entry, "InitGui.py")
    ):
        if _package_root not in _sys.path:
            _sys.path.append(_package_root)
        break

# FreeCAD (Debian's 0.20.2) restores a document's Python objects only from modules that are
# loaded already or live in an installed workbench: load BVMesh's feature modules now, so .FCStd
# files with BVMesh objects open wherever the package was found.
try:
    import bvmesh.features.bspline_shell  # noqa: F401
    import bvmesh.features.distance_map  # noqa: F401
    import bvmesh.features.polyhedron  # noqa: F401
    import bvmesh.features.surface_fit  # noqa: F401
    import bvmesh.features.target  # noqa: F401
except ImportError as _error:
    import FreeCAD as _FreeCAD

    _FreeCAD.Console.PrintError("BVMesh: its document objects cannot be loaded: {}\n".format(_error))

"""BVMesh: block-structured B-spline volume meshes from CAD geometry.

The compiled core lives in ``bvmesh._core`` (built by CMake into this folder). Its public names are
re-exported here and loaded on first use, so ``import bvmesh`` always works (FreeCAD's workbench
list, ``bvmesh.paths``) and a missing build is reported with the way to fix it when the core is
actually needed.
"""

import importlib

__version__ = "0.1.0"

# Public names of the compiled core, re-exported by this package.
_CORE_NAMES = (
    "InvalidInputError",
    "TopologyError",
    "SolverError",
    "CancelledError",
    "ControlMesh",
    "LimitEvaluator",
    "LimitSamples",
    "SampleElement",
    "SampleFeature",
    "SubdivisionOptions",
    "read_control_mesh",
    "write_control_mesh",
    "Target",
    "ProjectionStatus",
    "SurfaceFitter",
    "limit_surface_to_bsplines",
    "BlockMesh",
    "VolumeMesh",
    "generate_volume_mesh",
    "read_block_mesh",
    "StructuredGrid",
    "RefinedGrid",
    "refine_blocks",
    "grid_quality",
    "write_openfoam",
    "write_cgns",
    "write_plot3d",
    "read_plot3d",
    "write_vtk",
    "write_gismo",
)


def load_core():
    """Returns the compiled module, or raises ImportError that says how to build it."""
    try:
        return importlib.import_module("bvmesh._core")
    except ImportError as error:
        raise ImportError(
            "BVMesh's compiled module bvmesh._core could not be loaded ({}). Build it with "
            "'bash scripts/setup.sh build' in the BVMesh checkout (see README.md).".format(error)
        ) from error


def __getattr__(name):
    if name in _CORE_NAMES:
        return getattr(load_core(), name)
    raise AttributeError("module 'bvmesh' has no attribute '{}'".format(name))


def __dir__():
    return sorted(list(globals()) + list(_CORE_NAMES))

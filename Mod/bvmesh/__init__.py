"""BVMesh: block-structured B-spline volume meshes from CAD geometry.

The compiled core lives in ``bvmesh._core`` (built by CMake into this folder); this package
re-exports its public classes and adds the FreeCAD-facing API in :mod:`bvmesh.api`.
"""

try:
    from . import _core
except ImportError as error:  # the C++ module has not been built, or was built for another Python
    raise ImportError(
        "BVMesh's compiled module bvmesh._core could not be loaded ({}). Build it with "
        "'bash scripts/setup.sh build' from the BVMesh checkout (see README.md).".format(error)
    ) from error

from ._core import CancelledError, InvalidInputError, SolverError, TopologyError
from ._core import (ControlMesh, LimitEvaluator, LimitSamples, SampleElement, SampleFeature,
                    SubdivisionOptions, read_control_mesh, write_control_mesh)

__version__ = "0.1.0"

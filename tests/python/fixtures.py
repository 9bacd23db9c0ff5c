"""What several Python test modules share: the cube inscribed in the unit sphere (the thesis'
starting polyhedron for the sphere fits), the unit sphere's fitted volume mesh, and checkMesh."""

import os
import subprocess

import numpy as np

import FreeCAD  # noqa: F401  -- Part needs it loaded first
import Part

import bvmesh
import bvmesh.volume

A = 1.0 / np.sqrt(3.0)
CUBE_VERTICES = A * np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                              [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
CUBE_FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
OPENFOAM = dict(os.environ, WM_PROJECT_DIR="/usr/share/openfoam")


def sphere_target():
    """The unit sphere as a target."""
    return bvmesh.Target.from_brep(Part.makeSphere(1.0).exportBrepToString())


def sphere_volume(max_level):
    """(target, fitter, volume mesh): the unit sphere fitted from the cube to `max_level`, with a
    0.05 boundary layer and the far field at 20."""
    target = sphere_target()
    fitter = bvmesh.SurfaceFitter(target, bvmesh.ControlMesh(CUBE_VERTICES, CUBE_FACES), max_level=max_level,
                                  tolerance=1e-9)
    fitter.run()
    volume = bvmesh.volume.offset_and_farfield(fitter, boundary_layer_thickness=0.05, farfield_distance=20.0,
                                               reference_length=1.0)
    return target, fitter, volume


def check_mesh(case, timeout=600):
    """checkMesh's output; it exits 0 whatever it finds, so callers parse it."""
    result = subprocess.run(["checkMesh", "-allGeometry", "-allTopology", "-case", case], env=OPENFOAM,
                            capture_output=True, text=True, timeout=timeout)
    return result.stdout + result.stderr


def failed_checks(output):
    """The lines of checkMesh's output that report a failed check."""
    return [line.strip() for line in output.splitlines() if line.strip().startswith("***")]

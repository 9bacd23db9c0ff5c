"""What several Python test modules share: the cube inscribed in the unit sphere (the thesis'
starting polyhedron for the sphere fits), the unit sphere's fitted volume mesh, checkMesh, the
normal jump between B-spline charts along their shared smooth borders, and a wing section as a
FreeCAD user draws it."""

import math
import os
import subprocess

import numpy as np
from scipy.interpolate import BSpline

import FreeCAD  # Part needs it loaded first
import Part

import bvmesh
import bvmesh.volume

A = 1.0 / np.sqrt(3.0)
CUBE_VERTICES = A * np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                              [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
CUBE_FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
OPENFOAM = dict(os.environ, WM_PROJECT_DIR="/usr/share/openfoam")


def naca0012_section(leading_edge, y, chord):
    """A NACA 0012 section in the plane of span station y, as a FreeCAD user draws it for a loft:
    an interpolated upper and lower curve meeting at a sharp trailing edge."""
    xs = [0.5 * (1 + math.cos(math.pi * i / 40)) for i in range(41)]  # 1 .. 0
    half = [0.6 * (0.2969 * math.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4) for x in xs]
    upper, lower = Part.BSplineCurve(), Part.BSplineCurve()
    upper.interpolate([FreeCAD.Vector(leading_edge + chord * x, y, chord * h) for x, h in zip(xs, half)])
    lower.interpolate([FreeCAD.Vector(leading_edge + chord * x, y, -chord * h) for x, h in zip(xs, half)])
    return Part.Wire([upper.toShape(), lower.toShape()])


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


def smooth_border_normal_jumps(result, per_edge=16):
    """(angles in degrees, points): the angle between the two charts' normals at per_edge points
    per edge along every shared smooth segment of a limit_surface_to_bsplines result, evaluated
    from the charts' poles and knots."""
    angles, points = [], []
    for segment in result["segments"]:
        if len(segment["uses"]) != 2 or segment["kind"] == "crease":
            continue
        y = np.linspace(0.0, len(segment["vertices"]) - 1, per_edge * (len(segment["vertices"]) - 1) + 1)
        normals = []
        for chart_id, side, first, reversed_ in segment["uses"]:
            chart = result["charts"][chart_id]
            position = first - y if reversed_ else first + y
            s = {"u_min": 0.0 * y, "u_max": 0.0 * y + chart["u_cells"]}.get(side, position)
            t = {"v_min": 0.0 * y, "v_max": 0.0 * y + chart["v_cells"]}.get(side, position)
            basis = []
            for knots, multiplicities, x in ((chart["u_knots"], chart["u_multiplicities"], s),
                                             (chart["v_knots"], chart["v_multiplicities"], t)):
                full = np.repeat(knots, multiplicities)
                spline = BSpline(full, np.eye(len(full) - 4), 3)
                basis.append((spline(x), spline.derivative()(x)))
            (bu, dbu), (bv, dbv) = basis
            du = np.einsum("ki,kj,ijx->kx", dbu, bv, chart["poles"])
            dv = np.einsum("ki,kj,ijx->kx", bu, dbv, chart["poles"])
            normals.append(np.cross(du, dv))
            if len(normals) == 1:
                points.append(np.einsum("ki,kj,ijx->kx", bu, bv, chart["poles"]))
        sine = np.linalg.norm(np.cross(normals[0], normals[1]), axis=1)
        angles.append(np.degrees(np.arctan2(sine, np.einsum("kx,kx->k", normals[0], normals[1]))))
    return np.concatenate(angles), np.concatenate(points)


def check_mesh(case, timeout=600):
    """checkMesh's output; it exits 0 whatever it finds, so callers parse it."""
    result = subprocess.run(["checkMesh", "-allGeometry", "-allTopology", "-case", case], env=OPENFOAM,
                            capture_output=True, text=True, timeout=timeout)
    return result.stdout + result.stderr


def failed_checks(output):
    """The lines of checkMesh's output that report a failed check."""
    return [line.strip() for line in output.splitlines() if line.strip().startswith("***")]

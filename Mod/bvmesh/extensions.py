"""The two places where BVMesh's later stages plug into the workbench, one function each:

- place_template(target, name, **parameters): a template control polyhedron placed on a target.
  Expects bvmesh.polyhedra.place(name: str, target: bvmesh.Target, parameters: dict) -> dict with
  "mesh" (bvmesh.ControlMesh), "feature_map" (dict for bvmesh.SurfaceFitter) and "planform"
  (a wing's, or None), and bvmesh.polyhedra.template_names() -> list of str.
- limit_surface_to_shell(mesh): the limit surface of a control mesh as a sewn B-spline shell and
  what the conversion measured, from bvmesh._core.limit_surface_to_bsplines(control_mesh) -> dict
  whose "brep" entry is the sewn shell (or solid) as BREP text.

Each has an *_available() -> (bool, reason) so commands can be disabled and say why, instead
of producing anything in place of the real result."""

import importlib


def _polyhedra():
    try:
        return importlib.import_module("bvmesh.polyhedra"), None
    except ImportError as error:
        return None, "templates need bvmesh.polyhedra, which is not installed ({})".format(error)


def templates_available():
    module, reason = _polyhedra()
    if module is None:
        return False, reason
    if not hasattr(module, "place"):
        return False, "bvmesh.polyhedra has no place()"
    return True, ""


def template_names():
    module, reason = _polyhedra()
    if module is None:
        raise RuntimeError(reason)
    return list(module.template_names())


def place_template(target, name, **parameters):
    """Template `name` placed on a bvmesh.Target: a dict with "mesh" (bvmesh.ControlMesh),
    "feature_map" and "planform" (a wing's, or None), as bvmesh.polyhedra.place gives it."""
    available, reason = templates_available()
    if not available:
        raise RuntimeError(reason)
    module, _ = _polyhedra()
    return module.place(name, target, parameters)


def shell_available():
    from bvmesh import load_core

    try:
        core = load_core()
    except ImportError as error:
        return False, str(error)
    if not hasattr(core, "limit_surface_to_bsplines"):
        return False, "this build of the core has no limit_surface_to_bsplines (B-spline conversion)"
    return True, ""


def limit_surface_to_shell(mesh, tangent_continuity=False):
    """(Part.Shape, report) for the limit surface of a bvmesh.ControlMesh: the shell of B-spline
    faces and what the conversion measured: max_distance (largest distance of the faces from the
    limit surface at the check points, to first order) and max_kink_degrees (largest normal jump
    between neighbouring faces along smooth borders). tangent_continuity: neighbouring faces share
    their tangent planes along smooth borders (bvmesh.limit_surface_to_bsplines)."""
    from bvmesh import load_core
    from bvmesh.adapters.shapes import brep_to_shape

    available, reason = shell_available()
    if not available:
        raise RuntimeError(reason)
    result = load_core().limit_surface_to_bsplines(mesh, tangent_continuity=bool(tangent_continuity))
    if not result["valid"]:
        raise RuntimeError("the sewn B-spline shell is not a valid shape ({} free edges, max edge tolerance {:.3g})"
                           .format(result["free_edges"], result["max_edge_tolerance"]))
    report = {"max_distance": result["max_distance"], "max_kink_degrees": result["max_kink_degrees"]}
    return brep_to_shape(result["brep"]), report

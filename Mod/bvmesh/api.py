"""BVMesh's headless API for FreeCAD: works in freecadcmd, in the GUI's Python console and in
plain /usr/bin/python3 with FreeCAD's library on sys.path. GUI commands call these functions
through FreeCADGui.doCommand, so a recorded macro replays them without the GUI."""

import numpy as np

from bvmesh import load_core
from bvmesh.adapters.shapes import as_shape, brep_to_shape, shape_to_brep


def shape_report(shape_or_object, sharp_angle_degrees=30.0):
    """What a CAD shape holds, as a dict: face count and surface types, bounding box, and edges
    classified as sharp / smooth / free / seam / non-manifold / degenerate with their dihedral
    angles. Face i is FreeCAD's Face<i+1>, edge j its Edge<j+1>."""
    shape = as_shape(shape_or_object)
    return load_core().summarize_brep(shape_to_brep(shape), float(sharp_angle_degrees))


def format_shape_report(report):
    """The report of shape_report as readable lines."""
    counts = report["edge_counts"]
    types = {}
    for name in report["surface_types"]:
        types[name] = types.get(name, 0) + 1
    low, high = report["bounds"]
    lines = [
        "{} faces ({}), {} edges, {} vertices, {} solid(s)".format(
            report["faces"],
            ", ".join("{} {}".format(n, t) for t, n in sorted(types.items())),
            len(report["edges"]),
            report["vertices"],
            report["solids"],
        ),
        "edges: {sharp} sharp, {smooth} smooth, {free} free, {seam} seam, "
        "{nm} non-manifold, {degenerate} degenerate".format(nm=counts["non-manifold"], **counts),
        "bounding box: ({:.6g}, {:.6g}, {:.6g}) .. ({:.6g}, {:.6g}, {:.6g})".format(*low, *high),
    ]
    sharp = [
        "Edge{} ({:.1f} deg)".format(j + 1, edge["max_dihedral_degrees"])
        for j, edge in enumerate(report["edges"])
        if edge["kind"] == "sharp"
    ]
    if sharp:
        lines.append("sharp edges: " + ", ".join(sharp))
    return lines


def make_bspline_face(poles, u_knots, v_knots, u_multiplicities, v_multiplicities,
                      u_degree=3, v_degree=3, weights=None):
    """A Part.Face on the B-spline surface with the given poles (n_u x n_v x 3), knots and
    multiplicities, built and checked by the core."""
    poles = np.asarray(poles, dtype=float)
    brep = load_core().bspline_face_brep(
        poles, int(u_degree), int(v_degree), list(u_knots), list(v_knots),
        list(u_multiplicities), list(v_multiplicities), weights,
    )
    shape = brep_to_shape(brep)
    return shape.Faces[0]


def import_cad(doc, path, name=None):
    """Reads a STEP / IGES / BREP file with the core and adds it to `doc` as a Part::Feature,
    which is returned. Nothing is added when the file cannot be read."""
    import os

    from bvmesh.adapters.shapes import read_shape_file

    shape = read_shape_file(path)
    label = name or os.path.splitext(os.path.basename(os.fspath(path)))[0]
    feature = doc.addObject("Part::Feature", "CAD")
    feature.Label = label
    feature.Shape = shape
    doc.recompute()
    return feature


def print_shape_report(shape_or_object, sharp_angle_degrees=30.0):
    """Writes shape_report's summary to FreeCAD's console (the Report view in the GUI) and
    returns the report."""
    import FreeCAD

    report = shape_report(shape_or_object, sharp_angle_degrees)
    name = getattr(shape_or_object, "Label", "shape")
    FreeCAD.Console.PrintMessage("BVMesh report for {}:\n".format(name))
    for line in format_shape_report(report):
        FreeCAD.Console.PrintMessage("  {}\n".format(line))
    return report

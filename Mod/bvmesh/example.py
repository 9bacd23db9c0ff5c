"""The main job on the bundled example: the ONERA M6 half wing (tests/data), fitted from the
half-wing template with its trailing edge as a crease and its root on the symmetry plane y = 0.

Writes into the output folder: the FreeCAD document (M6.FCStd: CAD, target, polyhedron, fit,
B-spline shell), the B-spline surface (M6_surface.step), the convergence plot (M6_convergence.png)
and a convergence report (M6_report.md). Runs headless (plain /usr/bin/python3 or freecadcmd)."""

import os
import time

from bvmesh import api, load_core, paths


def _root_chord(wing_shape, symmetry_face):
    return wing_shape.Faces[symmetry_face].BoundBox.XLength


def _report_lines(fit, shell, chord, tolerance, seconds, files):
    rows = api.convergence_table(fit)
    lines = [
        "# ONERA M6 half wing: surface fit",
        "",
        "Target: the wing's faces without its root face (symmetry plane y = 0); root chord {:.1f}; "
        "tolerance {:.3g} ({:.0e} root chord).".format(chord, tolerance, tolerance / chord),
        "Stop: **{}** at level {} after {:.1f} s; {} control points.".format(
            fit.StopReason, fit.Level, seconds, len(fit.ControlVertices)),
        "",
        "| level | correction | control points | max distance | RMS distance | max / chord | "
        "limit -> target | target -> limit |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        def checked(value):
            return "-" if value is None else "{:.3e}".format(value)
        lines.append("| {level} | {correction} | {control_points} | {max_distance:.3e} | {rms_distance:.3e} | "
                     "{ratio:.2e} | {lt} | {tl} |".format(ratio=row["max_distance"] / chord,
                                                       lt=checked(row["limit_to_target"]),
                                                       tl=checked(row["target_to_limit"]), **row))
    solid = shell.Shape
    lines += [
        "",
        "B-spline surface: {} faces, valid: {}, closed shells: {}, free edges: {}.".format(
            len(solid.Faces), solid.isValid(), sum(1 for s in solid.Shells if s.isClosed()),
            len([e for e in solid.Edges if len(solid.ancestorsOfType(e, type(solid.Faces[0]))) == 1])),
        "",
        "Files: " + ", ".join(os.path.basename(f) for f in files),
    ]
    return lines


def run(output_dir, max_level=5, relative_tolerance=1e-5, log=print):
    """Runs the example and returns a dict of the files written and the fit's outcome.
    relative_tolerance is relative to the root chord."""
    import FreeCAD

    os.makedirs(output_dir, exist_ok=True)
    started = time.time()
    doc = FreeCAD.newDocument("M6")
    try:
        wing = api.import_cad(doc, paths.EXAMPLE_WING, name="AileM6_with_sharp_TE")
        _, symmetry_face, _ = load_core().remove_symmetry_face(wing.Shape.exportBrepToString())
        faces = ["Face{}".format(i + 1) for i in range(len(wing.Shape.Faces)) if i != symmetry_face]
        target = api.make_target(doc, wing, faces=faces)
        log("target: {} faces; Face{} is the symmetry-plane face".format(len(faces), symmetry_face + 1))
        polyhedron = api.make_polyhedron_from_template(doc, target, "half_wing")
        log("polyhedron: " + polyhedron.Summary)
        chord = _root_chord(wing.Shape, symmetry_face)
        tolerance = relative_tolerance * chord
        fit = api.make_surface_fit(doc, target, polyhedron, symmetry_plane=api.symmetry_plane_guess(target),
                                   tolerance=tolerance, max_level=max_level, check_samples_per_face=4)
        api.fit_to_tolerance(fit)
        seconds = time.time() - started
        log("fit: {} at level {}, max distance {:.3e} ({:.2e} root chord), RMS {:.3e}".format(
            fit.StopReason, fit.Level, fit.HistoryMax[-1], fit.HistoryMax[-1] / chord, fit.HistoryRms[-1]))
        shell = api.make_bspline_shell(fit)
        files = {
            "document": os.path.join(output_dir, "M6.FCStd"),
            "step": os.path.join(output_dir, "M6_surface.step"),
            "plot": os.path.join(output_dir, "M6_convergence.png"),
            "report": os.path.join(output_dir, "M6_report.md"),
        }
        api.export_step(shell, files["step"])
        api.plot_convergence(fit, files["plot"], title="ONERA M6 half wing")
        doc.saveAs(files["document"])
        lines = _report_lines(fit, shell, chord, tolerance, seconds, files.values())
        with open(files["report"], "w") as report:
            report.write("\n".join(lines) + "\n")
        for line in lines:
            log(line)
        return {"files": files, "stop_reason": fit.StopReason, "level": fit.Level,
                "max_distance": fit.HistoryMax[-1], "chord": chord}
    finally:
        FreeCAD.closeDocument(doc.Name)

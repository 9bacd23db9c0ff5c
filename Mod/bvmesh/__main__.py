"""Command line: /usr/bin/python3 -m bvmesh COMMAND (with <checkout>/Mod and FreeCAD's library
on PYTHONPATH; scripts/setup.sh sets that up).

  info FILE       what a STEP / IGES / BREP file holds (faces, surface types, feature edges)
  example         the main job: the ONERA M6 half wing fitted from the half-wing template and
                  meshed; writes the FreeCAD document, the B-spline surface (STEP), the Euler
                  grid (CGNS, OpenFOAM case), pictures and reports into --output (default:
                  bvmesh-example); --surface-only stops after the surface
  mesh CAD --template NAME
                  the same job on any STEP / IGES / BREP file, for batch runs
                  (bvmesh.pipeline): the body (a flow domain's, the shape without its
                  symmetry-plane face with --half-model, or the whole shape) fitted from the
                  template, its volume mesh and a grid (--preset euler or rans, about
                  --target-cells cells) in --formats, with reports and the FreeCAD document
                  in --output
  openfoam-case CASE
                  a steady compressible OpenFOAM case (bvmesh.openfoam_case): the mesh from
                  --mesh (an OpenFOAM case directory with patches wall, farfield or a box's
                  inlet / outlet / side, and symmetry on a half model, in
                  --length-unit metres per unit) or the bundled M6 grid built here; --run runs
                  the solver, --report DIR writes the Cp comparison and convergence report
                  (--no-experiment: without the M6 comparison, for other bodies);
                  --continue --iterations N goes on with a case run before up to step N
  grid-convergence REPORT REPORT REPORT
                  Richardson extrapolation, observed order and grid convergence index of CL,
                  CD and CM over three runs of one grid family (bvmesh.grid_convergence), from
                  their --report folders

Exit status: 0 done; 1 bad input or a failed step (the message says which); 2 (example, mesh)
every file written, but the fit stopped above its tolerance or checkMesh failed a check: a
warning line says which.
"""

import argparse
import os
import sys

FREECAD_LIB = "/usr/lib/freecad-python3/lib"


def _info(path, sharp_angle_degrees, sew=True, sew_tolerance=0.0):
    from bvmesh import api

    report = api.shape_report(path, sharp_angle_degrees, sew=sew, sew_tolerance=sew_tolerance)
    print(path)
    for line in api.format_shape_report(report):
        print("  " + line)
    return report


def _openfoam_case(args):
    from bvmesh import openfoam_case, openfoam_run

    if args.no_experiment and not args.report:
        raise ValueError("--no-experiment shapes the report: it needs --report DIR")
    if args.continue_run:
        if args.mesh:
            raise ValueError("--continue goes on with the case as it is: it takes no --mesh")
        case = os.path.abspath(args.case)
        step = openfoam_run.continue_case(case, args.iterations)
        print("continuing {} from step {} to {}".format(case, step, args.iterations))
        _run_and_report(case, args)
        return
    if args.mesh:
        source = args.mesh
    else:
        print("building the M6 {} grid (level {}, {})".format(args.model, args.level, "{} edge points".format(
            args.edge_points) if args.edge_points is not None else "about {} cells".format(args.target_cells or 300000)))
        source = openfoam_case.m6_grid(args.model, level=args.level, edge_points=args.edge_points,
                                       normal_points=args.normal_points, target_cells=args.target_cells,
                                       leading_edge_spacing=args.leading_edge_spacing,
                                       reynolds_number=args.reynolds or 11.72e6, y_plus=args.y_plus,
                                       knife_edge_fans=args.knife_edge_fans)
        print("  {} cells".format(source.grid.cell_count))
    case = openfoam_case.write_case(
        source, args.case, mach=args.mach, alpha_degrees=args.alpha, pressure=args.pressure,
        temperature=args.temperature, reynolds_number=args.reynolds, model=args.model,
        length_unit=args.length_unit, iterations=args.iterations, write_interval=args.write_interval,
        solver=args.solver, max_courant=args.max_courant, initial_solution=args.initial_solution,
        reference_length=args.reference_length, reference_area=args.reference_area,
        moment_point=tuple(args.moment_point), semispan=args.semispan)
    print("case written: {}".format(case))
    if args.run:
        _run_and_report(case, args)


def _parameter_value(text):
    """An option's value from the command line: a number where it reads as one, true / false, a
    tuple of numbers for comma-separated ones, else the text."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    if "," in text:
        try:
            return tuple(float(part) for part in text.split(","))
        except ValueError:
            pass
    return text


def _key_values(items, what):
    """{key: value} of the KEY=VALUE items of an option given on the command line."""
    values = {}
    for item in items:
        key, equals, value = item.partition("=")
        if not equals or not key:
            raise ValueError("a {} is KEY=VALUE, got {!r}".format(what, item))
        values[key] = _parameter_value(value)
    return values


def _mesh(args):
    from bvmesh import pipeline

    parameters = _key_values(args.template_parameter, "template parameter")
    volume_options = _key_values(args.volume_option, "volume option")
    grid_options = _key_values(args.grid_option, "grid option")
    if args.reynolds is None and args.preset == "rans":
        raise ValueError("the rans preset needs --reynolds (its first cell comes from a y+ of 1)")
    formats = [f.strip() for f in args.formats.split(",") if f.strip()]
    _info(args.cad, 30.0)
    return pipeline.run(args.cad, args.output, args.template, name=args.name, template_parameters=parameters,
                        half_model=args.half_model, reference_length=args.reference_length,
                        relative_tolerance=args.tolerance, max_level=args.max_level, reynolds_number=args.reynolds,
                        volume=not args.surface_only, preset=args.preset, target_cells=args.target_cells,
                        formats=formats, volume_options=volume_options, grid_options=grid_options)


def _run_and_report(case, args):
    from bvmesh import openfoam_case, openfoam_post, openfoam_run

    result = openfoam_run.run_case(case, cores=args.cores, timeout=args.timeout)
    print("{}: {} iterations in {:.0f} s{}, CL {:.4f}, CD {:.5f}".format(
        openfoam_case.read_settings(case)["solver"], result["iterations"], result["wall_time"],
        ", stopped " + result["stopped"] if result["stopped"] else "",
        result["coefficients"]["Cl"][-1], result["coefficients"]["Cd"][-1]))
    if args.report:
        if args.no_experiment:
            summary = openfoam_post.write_report(case, args.report, experiment_path=None,
                                                 title=os.path.basename(os.path.normpath(case)))
        else:
            summary = openfoam_post.write_report(case, args.report)
        stations = summary["stations"]
        print("report: {}{}".format(os.path.join(args.report, "report.md"), " (RMS dCp per station: {})".format(
            ", ".join("{:.3f}".format(s["rms"]) for s in stations)) if stations else ""))


def main(argv=None):
    from bvmesh import openfoam_case  # the flow case's defaults (plain Python, no numpy)

    parser = argparse.ArgumentParser(prog="bvmesh", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = parser.add_subparsers(dest="command", required=True)
    info = commands.add_parser("info", help="report what a CAD file holds")
    info.add_argument("file")
    info.add_argument("--sharp-angle", type=float, default=30.0,
                      help="dihedral angle in degrees from which an edge is sharp (default 30)")
    info.add_argument("--sew-tolerance", type=float, default=0.0,
                      help="sew faces whose edges lie this close (model units; default 0: automatic, "
                           "from the file's tolerances and the model size)")
    info.add_argument("--no-sew", action="store_true", help="report the faces as written, unsewn")
    example = commands.add_parser("example", help="run the main job on the bundled ONERA M6 wing")
    example.add_argument("--output", default="bvmesh-example", help="folder for the results")
    example.add_argument("--max-level", type=int, default=5, help="subdivision levels at most (default 5)")
    example.add_argument("--surface-only", action="store_true", help="stop after the surface stage")
    example.add_argument("--grid-method", choices=("bspline", "subdivision"), default="bspline",
                         help="bspline: the blocks evaluated on the Euler grid (default); subdivision: the fit's "
                              "control mesh marched and refined by volumetric Catmull-Clark")
    example.add_argument("--subdivision-steps", type=int, default=1, help="with --grid-method subdivision (default 1)")
    mesh = commands.add_parser("mesh", help="fit and mesh the body of a CAD file (a batch run of the whole job)")
    mesh.add_argument("cad", help="STEP, IGES or BREP file")
    mesh.add_argument("--template", required=True, help="polyhedron template: one of bvmesh.polyhedra.template_names() "
                                                        "(box, capsule, cylinder, fuselage, half_wing, nacelle, sphere, "
                                                        "wing, wing_fuselage)")
    mesh.add_argument("--template-parameter", action="append", default=[], metavar="KEY=VALUE",
                      help="a template parameter (docs/templates.md), e.g. tip_kinks=follow; repeatable")
    mesh.add_argument("--half-model", action="store_true",
                      help="the shape is a half model closed by its symmetry-plane face (e.g. a half wing's root): "
                           "that face is left out and its plane is the symmetry plane")
    mesh.add_argument("--output", default="bvmesh-mesh", help="folder for the results (default bvmesh-mesh)")
    mesh.add_argument("--name", help="the files' base name (default: the CAD file's)")
    mesh.add_argument("--reference-length", type=float,
                      help="model units (default: on a half model the body's largest extent on its symmetry plane, "
                           "a wing's root chord, else the body's largest extent)")
    mesh.add_argument("--tolerance", type=float, default=1e-5,
                      help="the fit's tolerance relative to the reference length (default 1e-5)")
    mesh.add_argument("--max-level", type=int, default=5, help="subdivision levels at most (default 5)")
    mesh.add_argument("--reynolds", type=float, help="Reynolds number on the reference length (the boundary layer's "
                                                     "thickness and the rans preset's first cell)")
    mesh.add_argument("--preset", choices=("euler", "rans"), default="euler", help="grid preset (default euler)")
    mesh.add_argument("--target-cells", type=int, default=1_000_000, help="about this many cells (default 1000000)")
    mesh.add_argument("--formats", default="cgns,openfoam",
                      help="comma-separated: cgns, openfoam, plot3d, vtk, gismo, blocks (default cgns,openfoam)")
    mesh.add_argument("--volume-option", action="append", default=[], metavar="KEY=VALUE",
                      help="an option of the volume mesh (bvmesh.api.make_volume_mesh: domain=box, "
                           "flow_direction=1,0,0.1, farfield_distance=..., boundary_layer_thickness=..., "
                           "knife_edge_fans=true, ...); repeatable")
    mesh.add_argument("--grid-option", action="append", default=[], metavar="KEY=VALUE",
                      help="an option of the grid (bvmesh.grid.refine: normal_points=65, y_plus=30, "
                           "distribution=tanh, ...); repeatable")
    mesh.add_argument("--surface-only", action="store_true", help="stop after the surface stage")
    cfd = commands.add_parser("openfoam-case", help="write (and run) an OpenFOAM case on a BVMesh grid")
    cfd.add_argument("case", help="case directory to write")
    cfd.add_argument("--mesh", help="OpenFOAM case directory whose constant/polyMesh is used "
                                    "(default: build the bundled M6 grid)")
    cfd.add_argument("--length-unit", type=float, default=0.001,
                     help="metres per grid unit (default 0.001: the grid is in mm)")
    cfd.add_argument("--model", choices=openfoam_case.MODELS, default="euler")
    cfd.add_argument("--solver", choices=openfoam_case.SOLVERS, default=openfoam_case.DEFAULT_SOLVER,
                     help="rhoPimpleFoam with local time stepping (default), rhoSimpleFoam, or rhoCentralFoam "
                          "(density-based, explicit with local time stepping; euler only)")
    cfd.add_argument("--mach", type=float, default=openfoam_case.M6_MACH)
    cfd.add_argument("--alpha", type=float, default=openfoam_case.M6_ALPHA_DEGREES, help="angle of attack in degrees")
    cfd.add_argument("--temperature", type=float, default=openfoam_case.M6_TEMPERATURE,
                     help="free-stream temperature in K")
    cfd.add_argument("--pressure", type=float, help="free-stream pressure in Pa (default: from --reynolds, else 1e5)")
    cfd.add_argument("--reynolds", type=float,
                     help="Reynolds number on the reference length (default the M6's mean aerodynamic chord)")
    cfd.add_argument("--reference-length", type=float, default=openfoam_case.M6_REFERENCE_LENGTH,
                     help="force coefficients' reference length in m, and the Reynolds number's (default the "
                          "M6's mean aerodynamic chord, {} m)".format(openfoam_case.M6_REFERENCE_LENGTH))
    cfd.add_argument("--reference-area", type=float, default=openfoam_case.M6_REFERENCE_AREA,
                     help="force coefficients' reference area in m^2 (default the M6 half wing's, {} m^2)".format(
                         openfoam_case.M6_REFERENCE_AREA))
    cfd.add_argument("--moment-point", type=float, nargs=3, metavar=("X", "Y", "Z"),
                     default=openfoam_case.M6_MOMENT_POINT,
                     help="point in m the moment coefficient is taken about (default the M6's quarter chord of "
                          "the mean aerodynamic chord)")
    cfd.add_argument("--semispan", type=float, default=openfoam_case.M6_SEMISPAN,
                     help="half span in m, for the report's span stations (default the M6's, {} m)".format(
                         openfoam_case.M6_SEMISPAN))
    cfd.add_argument("--iterations", type=int, default=openfoam_case.DEFAULT_ITERATIONS)
    cfd.add_argument("--write-interval", type=int, help="iterations between writes (default: --iterations)")
    cfd.add_argument("--max-courant", type=float,
                     help="local time stepping Courant number (default 2; rans 0.5; rhoCentralFoam 0.2)")
    cfd.add_argument("--initial-solution", help="a case written and run before (an euler solution of the same "
                                                "wing): its latest fields mapped onto this grid as the start")
    cfd.add_argument("--level", type=int, default=2, help="M6 grid: subdivision level of the fit (default 2)")
    cfd.add_argument("--target-cells", type=int,
                     help="M6 grid: about this many cells, spaced as the wall needs (default 300000)")
    cfd.add_argument("--edge-points", type=int, help="M6 grid: points on every block edge instead (no target cells)")
    cfd.add_argument("--normal-points", type=int, help="M6 grid: wall-normal points (default: the preset's)")
    cfd.add_argument("--y-plus", type=float, help="M6 rans grid: the first cell's flat-plate y+ (default 1)")
    cfd.add_argument("--leading-edge-spacing", type=float, default=2.0,
                     help="M6 grid: wall spacing in mm away from the leading edge (default 2; 0: none)")
    cfd.add_argument("--knife-edge-fans", action="store_true",
                     help="M6 grid: the sharp trailing edge cut open with a fan of prisms round it")
    cfd.add_argument("--run", action="store_true", help="run the solver (nice -n 19)")
    cfd.add_argument("--continue", dest="continue_run", action="store_true",
                     help="go on with CASE, written and run before (stopped by --timeout, or at its end), from its "
                          "latest written step to --iterations steps in all, and run it; nothing is written anew")
    cfd.add_argument("--cores", type=int, default=1, help="cores for the solver (default 1)")
    cfd.add_argument("--timeout", type=float, help="stop the solver after this many seconds, keeping its last write")
    cfd.add_argument("--report", help="with --run: folder for the Cp plots, convergence plot and report.md")
    cfd.add_argument("--no-experiment", action="store_true",
                     help="with --report: a body other than the ONERA M6; the report leaves out the comparison "
                          "with the M6 wind-tunnel pressures (convergence, forces and upper-surface Cp only)")
    convergence = commands.add_parser(
        "grid-convergence", help="Richardson extrapolation and grid convergence index of CL, CD and CM over three "
                                 "runs of one grid family")
    convergence.add_argument("reports", nargs=3, metavar="REPORT",
                             help="a run's report folder (openfoam-case --report), one per grid")
    args = parser.parse_args(argv)

    if FREECAD_LIB not in sys.path:
        sys.path.append(FREECAD_LIB)
    from bvmesh import InvalidInputError, SolverError, paths

    outcome = None
    try:
        if args.command == "info":
            _info(args.file, args.sharp_angle, not args.no_sew, args.sew_tolerance)
        elif args.command == "openfoam-case":
            _openfoam_case(args)
        elif args.command == "mesh":
            outcome = _mesh(args)
        elif args.command == "grid-convergence":
            from bvmesh import grid_convergence

            print("\n".join(grid_convergence.table(grid_convergence.study_reports(args.reports))))
        else:
            from bvmesh import example as main_job

            _info(paths.EXAMPLE_WING, 30.0)
            outcome = main_job.run(args.output, max_level=args.max_level, volume=not args.surface_only,
                                   grid_method=args.grid_method, subdivision_steps=args.subdivision_steps)
    except (InvalidInputError, SolverError, ValueError, RuntimeError, OSError) as error:
        print("bvmesh: {}".format(error), file=sys.stderr)
        return 1
    if outcome is not None:
        from bvmesh import pipeline

        unmet = pipeline.unmet_goals(outcome)
        for goal in unmet:
            print("bvmesh: warning: {}".format(goal), file=sys.stderr)
        if unmet:
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())

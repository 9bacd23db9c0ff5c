"""Command line: /usr/bin/python3 -m bvmesh COMMAND (with <checkout>/Mod and FreeCAD's library
on PYTHONPATH; scripts/setup.sh sets that up).

  info FILE       what a STEP / IGES / BREP file holds (faces, surface types, feature edges)
  example         the main job: the ONERA M6 half wing fitted from the half-wing template and
                  meshed; writes the FreeCAD document, the B-spline surface (STEP), the Euler
                  grid (CGNS, OpenFOAM case), pictures and reports into --output (default:
                  bvmesh-example); --surface-only stops after the surface
"""

import argparse
import sys

FREECAD_LIB = "/usr/lib/freecad-python3/lib"


def _info(path, sharp_angle_degrees, sew=True, sew_tolerance=0.0):
    from bvmesh import api

    report = api.shape_report(path, sharp_angle_degrees, sew=sew, sew_tolerance=sew_tolerance)
    print(path)
    for line in api.format_shape_report(report):
        print("  " + line)
    return report


def main(argv=None):
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
    args = parser.parse_args(argv)

    if FREECAD_LIB not in sys.path:
        sys.path.append(FREECAD_LIB)
    from bvmesh import InvalidInputError, SolverError, paths

    try:
        if args.command == "info":
            _info(args.file, args.sharp_angle, not args.no_sew, args.sew_tolerance)
        else:
            from bvmesh import example as main_job

            _info(paths.EXAMPLE_WING, 30.0)
            main_job.run(args.output, max_level=args.max_level, volume=not args.surface_only)
    except (InvalidInputError, SolverError, ValueError, RuntimeError) as error:
        print("bvmesh: {}".format(error), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Command line: /usr/bin/python3 -m bvmesh COMMAND (with <checkout>/Mod and FreeCAD's library
on PYTHONPATH; scripts/setup.sh sets that up).

  info FILE       what a STEP / IGES / BREP file holds (faces, surface types, feature edges)
  example         the main job on the bundled example, the ONERA M6 half wing
"""

import argparse
import sys

FREECAD_LIB = "/usr/lib/freecad-python3/lib"


def _info(path, sharp_angle_degrees):
    from bvmesh import api

    report = api.shape_report(path, sharp_angle_degrees)
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
    commands.add_parser("example", help="run the main job on the bundled ONERA M6 wing")
    args = parser.parse_args(argv)

    if FREECAD_LIB not in sys.path:
        sys.path.append(FREECAD_LIB)
    from bvmesh import InvalidInputError, SolverError, paths

    try:
        if args.command == "info":
            _info(args.file, args.sharp_angle)
        else:
            _info(paths.EXAMPLE_WING, 30.0)
    except (InvalidInputError, SolverError, ValueError) as error:
        print("bvmesh: {}".format(error), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

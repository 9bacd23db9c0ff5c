"""Replays the CAD fuzz targets' findings through the isolated reader, the way the workbench reads
outside files: every crash-, timeout- and oom- input of build-fuzz/artifacts/{step,iges,brep} goes
to bvmesh.Target.from_file (as a .stp / .igs file) or bvmesh.Target.from_brep (BREP text, as
bytes). Each must come back as an error (or a target) within the reader's limits while this
process stays alive; prints one line per input and a summary by outcome.

    PYTHONPATH=Mod:/usr/lib/freecad-python3/lib /usr/bin/python3 fuzz/replay_isolated.py [build-fuzz]
"""

import collections
import os
import shutil
import sys
import tempfile
import time

import bvmesh

EXTENSIONS = {"step": ".stp", "iges": ".igs", "brep": None}


def replay(target, path, folder):
    start = time.time()
    try:
        if EXTENSIONS[target] is None:
            with open(path, "rb") as source:
                bvmesh.Target.from_brep(source.read())
        else:
            copy = os.path.join(folder, "input" + EXTENSIONS[target])
            shutil.copyfile(path, copy)
            bvmesh.Target.from_file(copy)
        outcome = "read"
    except bvmesh.InvalidInputError as error:
        outcome = "InvalidInputError: " + str(error).replace("\n", " ")
    except Exception as error:  # noqa: BLE001 -- any other error is reported as such
        outcome = "{}: {}".format(type(error).__name__, str(error).replace("\n", " "))
    return outcome, time.time() - start


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "build-fuzz")
    summary = collections.Counter()
    slowest = 0.0
    with tempfile.TemporaryDirectory() as folder:
        for target in EXTENSIONS:
            artifacts = os.path.join(build, "artifacts", target)
            for name in sorted(os.listdir(artifacts)) if os.path.isdir(artifacts) else []:
                outcome, seconds = replay(target, os.path.join(artifacts, name), folder)
                slowest = max(slowest, seconds)
                print("{} {} {:.2f} s: {}".format(target, name, seconds, outcome[:200]))
                # The kind of outcome without the file name: "... crashed OpenCASCADE's reader (Segmentation fault)".
                kind = outcome.split(":")[0]
                for reason in ("crashed", "time limit", "memory", "corrupt", "Unresolved", "no shape"):
                    if reason in outcome:
                        kind += " (" + reason + ")"
                        break
                summary[(target, name.split("-")[0], kind)] += 1
    for (target, finding, kind), count in sorted(summary.items()):
        print("{:5} {:8} {:4d} x {}".format(target, finding, count, kind))
    print("slowest {:.1f} s; this process is alive".format(slowest))


if __name__ == "__main__":
    main()

"""Running a case written by bvmesh.openfoam_case with OpenFOAM (v1912): the start before the
first step (mapFields, applyBoundaryLayer), then the solver's stages under nice, on one core or
decomposed along the span (decomposePar, mpirun, reconstructPar). The tools exit 0 on some
failures, so their logs are read.

    import bvmesh.openfoam_run as ofr
    result = ofr.run_case(case, cores=2, timeout=3600)
    print(result["iterations"], result["residuals"]["p"][-1])

Pure Python (no FreeCAD).
"""

import glob
import json
import os
import re
import shutil
import signal
import subprocess
import time

from .openfoam_case import SETTINGS_FILE, _time_folders, _write, read_settings

OPENFOAM_DIR = "/usr/share/openfoam"


def openfoam_environment():
    """The environment every OpenFOAM tool needs (WM_PROJECT_DIR); ValueError when it is missing."""
    if not os.path.isfile(os.path.join(OPENFOAM_DIR, "etc", "controlDict")) or shutil.which("rhoSimpleFoam") is None:
        raise ValueError("OpenFOAM is missing: no {}/etc/controlDict or no rhoSimpleFoam on PATH "
                         "(apt-get install openfoam)".format(OPENFOAM_DIR))
    return dict(os.environ, WM_PROJECT_DIR=OPENFOAM_DIR)


START_MARK = ".bvmesh_start"  # in 0/: the start is done (write_case writes 0/ again)


def start_case(case, nice=19):
    """The case's start before its first solver step (write_case's initial_solution and
    wall_damped_start): the initial solution's latest fields mapped onto the grid (mapFields,
    log.mapFields), then U damped near the wall (applyBoundaryLayer, log.applyBoundaryLayer).
    Writes 0/ in ascii, once: a case with a time step written or started before is left as it
    is. Returns the steps done (a list of tool names). The tools exit 0 on some failures, so their
    logs are read: a FOAM FATAL, a non-zero exit or a missing 'Writing U' / 'interpolating U'
    raises RuntimeError naming the log."""
    settings = read_settings(case)
    start = settings.get("start") or {}
    source, thickness = start.get("initial_solution"), start.get("boundary_layer_thickness")
    mark = os.path.join(case, "0", START_MARK)
    if not (source or thickness) or os.path.exists(mark) or _time_folders(case):
        return []
    environment = openfoam_environment()
    command = ["nice", "-n", str(nice)] if nice else []

    def tool(arguments, expected):
        _run_tool(case, arguments, os.path.join(case, "log." + arguments[0]), command, environment, expected=expected)

    control = os.path.join(case, "system", "controlDict")
    done = []
    _set_entries(control, True, writeFormat="ascii")
    try:
        if source:
            tool(["mapFields", source, "-consistent", "-sourceTime", "latestTime", "-mapMethod",
                  "cellPointInterpolate"], "interpolating U")
            # The source's other fields (rho, Ma, rDeltaT of its run) would be read as this
            # case's start: only the case's own fields stay.
            for name in os.listdir(os.path.join(case, "0")):
                path = os.path.join(case, "0", name)
                if os.path.isfile(path) and name not in settings["fields"]:
                    os.remove(path)
            done.append("mapFields")
        if thickness:
            tool(["applyBoundaryLayer", "-ybl", repr(float(thickness))], "Writing U")
            # Its flux is that of the undamped U: the solver makes its own from rho U.
            if os.path.exists(os.path.join(case, "0", "phi")):
                os.remove(os.path.join(case, "0", "phi"))
            done.append("applyBoundaryLayer")
    finally:
        _set_entries(control, True, writeFormat="binary")
    with open(mark, "w") as file:
        json.dump(done, file)
    return done


def _write_decompose(case, cores):
    # Debian's v1912 has no scotch or metis (their stubs stop decomposePar); `simple` splits the
    # cells sorted along y, the span, into equal parts.
    _write(case, "system", "decomposeParDict", """numberOfSubdomains {0};

method          simple;

simpleCoeffs
{{
    n               (1 {0} 1);
    delta           0.001;
}}
""".format(cores))


def _set_entries(path, top_level, **entries):
    """Sets `key value;` entries of an OpenFOAM dictionary in place: only unindented ones with
    top_level (function objects have their own writeInterval), else the one entry of that name
    at any depth."""
    with open(path) as file:
        text = file.read()
    for key, value in entries.items():
        indent = "" if top_level else r"[ \t]*"
        text, count = re.subn(r"(?m)^({}{}[ \t]+)[^;\n]*;".format(indent, re.escape(key)),
                              lambda match: "{}{};".format(match.group(1), value), text)
        if count != 1:
            raise ValueError("{}: expected one entry {}, found {}".format(path, key, count))
    with open(path, "w") as file:
        file.write(text)


def _stop(process):
    """SIGTERM to the process group, SIGKILL if it is still there after 30 s."""
    for sent, wait in ((signal.SIGTERM, 30), (signal.SIGKILL, None)):
        try:
            os.killpg(process.pid, sent)
        except ProcessLookupError:
            return
        try:
            process.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            pass


def _run_tool(case, arguments, log_path, prefix, environment, limit=None, mode="w", expected=None):
    """Runs an OpenFOAM tool (`prefix` + `arguments` + -case) with its output in log_path; returns
    (the log's text, whether it was stopped at `limit` seconds: the last written time step stays
    usable). OpenFOAM's tools exit 0 on some failures, so the log is read: a non-zero exit, a FOAM
    FATAL or, when given, a missing `expected` line raises RuntimeError naming the log."""
    timed_out = False
    with open(log_path, mode) as out:
        # A session of its own, so that a stop reaches mpirun's ranks too, not only mpirun.
        process = subprocess.Popen(prefix + arguments + ["-case", case], stdout=out, stderr=subprocess.STDOUT,
                                   env=environment, start_new_session=True)
        try:
            code = process.wait(timeout=limit)
        except subprocess.TimeoutExpired:
            _stop(process)
            timed_out, code = True, 0
        except BaseException:
            _stop(process)
            raise
    with open(log_path, errors="replace") as file:
        text = file.read()
    missing = expected is not None and expected not in text
    if code != 0 or "FOAM FATAL" in text or missing:
        tail = "\n".join(text.strip().splitlines()[-25:])
        raise RuntimeError("{} failed (exit {}{}), see {}:\n{}".format(
            arguments[0], code, ", {!r} missing".format(expected) if missing else "", log_path, tail))
    return text, timed_out


def _drop_unfinished_write(folder, log_text):
    """After a solver stopped at its time limit: removes `folder`'s latest time folder when the
    solver's log shows that step unfinished (no ExecutionTime line after its "Time = " line). The
    stop can land while the solver writes it, and a half-written field (a binary block cut short)
    made the next run fail to read it; the write before it is whole."""
    written = _time_folders(folder)
    if not written:
        return
    at = log_text.rfind("\nTime = {}\n".format(written[-1]))
    if at >= 0 and "ExecutionTime" not in log_text[at:]:
        shutil.rmtree(os.path.join(folder, written[-1]))


def latest_step(case):
    """The latest step the case has written (0 before its first write)."""
    written = _time_folders(case)
    return int(round(float(written[-1]))) if written else 0


def _stages_to(settings, iterations):
    """The case's stages run to `iterations` steps: each ends there at the latest, the last one
    exactly there; those beyond are left out."""
    stages = []
    for number, stage in enumerate(settings["stages"]):
        last = number == len(settings["stages"]) - 1
        stages.append(dict(stage, end=iterations if last else min(stage["end"], iterations)))
        if stages[-1]["end"] == iterations:
            break
    return stages


def continue_case(case, iterations):
    """Sets a case that has run before (to its end, or stopped by run_case's timeout) to go on from
    its latest written step to `iterations` steps in all; run_case then runs what is left through
    the case's stages, appending to the solver's log; fields, schemes and the other settings stay.
    Returns the step it goes on from. ValueError when the case has written no step (run_case runs
    it from its start), when `iterations` is not beyond the latest step, or when the write
    interval of the stage it ends in does not divide it (OpenFOAM writes only at write times)."""
    settings = read_settings(case)
    latest = latest_step(case)
    if latest == 0:
        raise ValueError("{} has written no step yet: run it (run_case) instead of continuing it".format(case))
    if not (isinstance(iterations, int) and iterations > latest):
        raise ValueError("{} has run to step {}: to continue it, give more iterations than that, got {!r}".format(
            case, latest, iterations))
    interval = _stages_to(settings, iterations)[-1]["write_interval"]
    if iterations % interval:
        raise ValueError("the case writes every {} steps there: iterations must be a multiple of that, got {}".format(
            interval, iterations))
    settings["iterations"] = iterations
    with open(os.path.join(case, SETTINGS_FILE), "w") as file:
        json.dump(settings, file, indent=2)
    return latest


def run_case(case, cores=1, nice=19, timeout=None, log_name=None):
    """Runs the case's solver (under `nice`, on `cores` cores: decomposePar / mpirun / reconstructPar
    above 1), after the case's start (start_case) on a case not run before, and returns
    {iterations, wall_time, log, residuals, coefficients, cores, stopped}. A case that has written
    steps before goes on from its latest one through the stages left (continue_case sets how far),
    its log appended to; one with none left is a ValueError.
    timeout (s) stops the solver and keeps what it wrote (stopped says so).
    OpenFOAM tools can exit 0 after a failure, so the log is read: a FOAM FATAL, a non-zero exit,
    no residuals or a non-finite one raise RuntimeError naming the log."""
    from . import openfoam_post

    environment = openfoam_environment()
    settings = read_settings(case)
    solver = settings["solver"]
    if not (isinstance(cores, int) and cores >= 1):
        raise ValueError("cores must be a positive integer, got {!r}".format(cores))
    if timeout is not None and not (isinstance(timeout, (int, float)) and timeout > 0):
        raise ValueError("timeout must be a number of seconds > 0 (or None: no limit), got {!r}".format(timeout))
    log = os.path.join(case, log_name or "log.{}".format(solver))
    command = ["nice", "-n", str(nice)] if nice else []

    stopped = []

    def tool(arguments, log_path, limit=None, mode="w"):
        text, timed_out = _run_tool(case, arguments, log_path, command, environment, limit, mode)
        if timed_out:
            stopped.append("after {:.0f} s".format(timeout))
            for folder in [case] + sorted(glob.glob(os.path.join(case, "processor[0-9]*"))):
                _drop_unfinished_write(folder, text)
        return text

    if cores > 1 and hasattr(os, "geteuid") and os.geteuid() == 0:
        # Open MPI refuses root unless told twice.
        environment.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    latest = latest_step(case)
    stages = [stage for stage in _stages_to(settings, settings["iterations"]) if stage["end"] > latest]
    if not stages:
        raise ValueError("{} has run to step {}, the end of its last stage: continue_case sets it to go on".format(
            case, latest))
    start = time.monotonic()
    start_case(case, nice)
    for number, stage in enumerate(stages):
        if stopped:
            break
        _set_entries(os.path.join(case, "system", "controlDict"), True,
                     endTime=stage["end"], writeInterval=stage["write_interval"])
        if solver == "rhoPimpleFoam":
            _set_entries(os.path.join(case, "system", "fvSolution"), False, maxCo=stage["max_courant"])
        elif solver == "rhoCentralFoam":
            _set_entries(os.path.join(case, "system", "controlDict"), True, maxCo=stage["max_courant"])
        limit = None if timeout is None else max(1.0, timeout - (time.monotonic() - start))
        mode = "w" if number == 0 and latest == 0 else "a"
        if cores > 1:
            _write_decompose(case, cores)
            tool(["decomposePar", "-force", "-latestTime"], os.path.join(case, "log.decomposePar"))
            tool(["mpirun", "--oversubscribe", "-np", str(cores), solver, "-parallel"], log, limit, mode)
            tool(["reconstructPar", "-latestTime"], os.path.join(case, "log.reconstructPar"))
        else:
            tool([solver], log, limit, mode)
    wall_time = time.monotonic() - start
    residuals = openfoam_post.read_residuals(case)
    if not residuals or not len(residuals["iteration"]):
        raise RuntimeError("no residuals recorded by {}, see {}".format(solver, log))
    import numpy as np

    for name, values in residuals.items():
        if not np.all(np.isfinite(values)):
            raise RuntimeError("non-finite {} residual after iteration {}, see {}".format(
                name, int(residuals["iteration"][np.argmin(np.isfinite(values))]), log))
    return dict(iterations=int(residuals["iteration"][-1]), wall_time=wall_time, log=log, residuals=residuals,
                coefficients=openfoam_post.read_force_coefficients(case), cores=cores,
                stopped=stopped[0] if stopped else None)

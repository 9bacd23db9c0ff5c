"""A steady compressible OpenFOAM (v1912) case on a BVMesh grid: mesh, boundary conditions,
thermophysics, function objects (residuals, force coefficients, wall pressure) and the case's
settings; the schemes and solver controls come from bvmesh.openfoam_schemes, and
bvmesh.openfoam_run runs the case.

    import bvmesh.openfoam_case as ofc, bvmesh.openfoam_run as ofr
    case = ofc.write_case(refined, "m6_euler", model="euler", iterations=3000)
    result = ofr.run_case(case)           # nice -n 19, one core
    print(result["iterations"], result["residuals"]["p"][-1])

Pure Python (no FreeCAD); the grid goes through bvmesh.grid.write_openfoam, or an existing case
directory's constant/polyMesh is copied. Patches: wall, the outer ones (farfield, or a box's or
cylinder's inlet, outlet and side) and symmetry on a half model.
Units: the grid is in model units (length_unit metres each, 0.001 for mm); the case is in SI.
The defaults are the ONERA M6 at the AGARD AR-138 test 2308 (see docs/cfd.md).
"""

import json
import math
import os
import re
import shutil

from . import openfoam_schemes

GAS_CONSTANT = 8314.47 / 28.9644  # J/(kg K), dry air
GAMMA = 1.4
SUTHERLAND_AS, SUTHERLAND_TS = 1.458e-6, 110.4

# ONERA M6 (Schmitt & Charpin, AGARD AR-138): mean aerodynamic chord, half-wing area, and the
# quarter chord of the mean aerodynamic chord (leading edge swept 30 deg, taper 0.562,
# semispan 1.1963 m: MAC at y = b/3 (1 + 2 taper)/(1 + taper) = 0.5423 m, its leading edge
# at x = 0.3131 m).
M6_REFERENCE_LENGTH = 0.64607
M6_REFERENCE_AREA = 0.7532
M6_MOMENT_POINT = (0.47459, 0.0, 0.0)
M6_SEMISPAN = 1.1963
# The wind-tunnel case compared with (test 2308): the defaults of write_case and the workbench.
M6_MACH, M6_ALPHA_DEGREES, M6_TEMPERATURE = 0.8395, 3.06, 255.56
DEFAULT_ITERATIONS = 2000
DEFAULT_SOLVER = "rhoPimpleFoam"

PATCHES = {"wall": "wall", "symmetry": "symmetryPlane", "farfield": "patch", "inlet": "patch", "outlet": "patch",
           "side": "patch"}
# The outer boundary's patches (a sphere's far field, a box's or cylinder's inlet, outlet and
# sides): all get the free-stream conditions, which let the flow in or out by its own direction.
OUTER_PATCHES = ("farfield", "inlet", "outlet", "side")
MODELS = ("euler", "rans")
SOLVERS = ("rhoSimpleFoam", "rhoPimpleFoam", "rhoCentralFoam")
EULER_ONLY_SOLVERS = ("rhoCentralFoam",)  # written without viscous terms or a turbulence model
# Local time stepping's Courant number when none is given (docs/cfd.md: rhoPimpleFoam converges at
# 2 and stalls at 5; rhoCentralFoam, explicit, diverged at 0.5 on a 59 k-cell M6 grid and runs at
# 0.2). rhoSimpleFoam has no time step; its entry is only recorded in the case's settings.
DEFAULT_COURANT = {"rhoPimpleFoam": 2.0, "rhoCentralFoam": 0.2, "rhoSimpleFoam": 2.0}
# A rans case's rhoPimpleFoam Courant number after the start-up (docs/cfd.md, RANS): on a 59 k-cell
# M6 rans grid at y+ 30, 2 put p on pressureControl's bounds from its first steps at 2 and diverged,
# 0.5 ran 400 steps inside them.
DEFAULT_RANS_COURANT = 0.5
SETTINGS_FILE = "bvmesh_case.json"
# Written first into a case folder: a write that fails before its settings file still leaves a
# folder that the next write_case may clear.
OWNER_MARK = ".bvmesh_case"

HEADER = """/*--------------------------------*- C++ -*----------------------------------*\\
  Written by BVMesh (openfoam_case.py)
\\*---------------------------------------------------------------------------*/
FoamFile
{{
    version     2.0;
    format      ascii;
    class       {cls};
    location    "{location}";
    object      {name};
}}

"""


def flat_plate_boundary_layer_thickness(reynolds_number, length):
    """The turbulent flat-plate boundary-layer thickness 0.37 L Re^-0.2 at L: the core's estimate,
    the one a volume mesh takes for its boundary layer when none is given."""
    from . import load_core

    return load_core().flat_plate_boundary_layer_thickness(float(reynolds_number), float(length))


def sutherland_viscosity(temperature):
    return SUTHERLAND_AS * temperature ** 1.5 / (temperature + SUTHERLAND_TS)


def freestream(mach, alpha_degrees, temperature, pressure=None, reynolds_number=None, reference_length=1.0):
    """The free stream as a dict (p, T, rho, speed, velocity, viscosity, mach, alpha_degrees).
    Without a pressure, it is the one that gives reynolds_number on reference_length (metres) with
    Sutherland's viscosity; without either, 1e5 Pa. Flow in x-z, lift along +z."""
    if not (isinstance(mach, (int, float)) and math.isfinite(mach) and mach > 0.0):
        raise ValueError("mach must be a finite number > 0, got {!r}".format(mach))
    if not (isinstance(temperature, (int, float)) and math.isfinite(temperature) and temperature > 0.0):
        raise ValueError("temperature must be > 0 K, got {!r}".format(temperature))
    if not (isinstance(alpha_degrees, (int, float)) and math.isfinite(alpha_degrees) and abs(alpha_degrees) < 90.0):
        raise ValueError("alpha_degrees must be finite and within (-90, 90), got {!r}".format(alpha_degrees))
    if reynolds_number is not None and not (reynolds_number > 0.0 and math.isfinite(reynolds_number)):
        raise ValueError("reynolds_number must be > 0 (or None), got {!r}".format(reynolds_number))
    speed = mach * math.sqrt(GAMMA * GAS_CONSTANT * temperature)
    viscosity = sutherland_viscosity(temperature)
    if pressure is None:
        if reynolds_number is not None:
            density = reynolds_number * viscosity / (speed * reference_length)
            pressure = density * GAS_CONSTANT * temperature
        else:
            pressure = 1e5
    if not (isinstance(pressure, (int, float)) and math.isfinite(pressure) and pressure > 0.0):
        raise ValueError("pressure must be > 0 Pa, got {!r}".format(pressure))
    density = pressure / (GAS_CONSTANT * temperature)
    alpha = math.radians(alpha_degrees)
    return dict(p=pressure, T=temperature, rho=density, speed=speed, mach=mach, alpha_degrees=alpha_degrees,
                velocity=(speed * math.cos(alpha), 0.0, speed * math.sin(alpha)), viscosity=viscosity,
                reynolds_number=density * speed * reference_length / viscosity)


def _vector(v):
    return "({:.12g} {:.12g} {:.12g})".format(*v)


def _write(case, location, name, body, cls="dictionary"):
    folder = os.path.join(case, location)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "w") as file:
        file.write(HEADER.format(cls=cls, location=location, name=name) + body)


def read_boundary(case):
    """The patches of constant/polyMesh/boundary: {name: {type, nFaces, startFace}} in file order."""
    path = os.path.join(case, "constant", "polyMesh", "boundary")
    try:
        with open(path) as file:
            text = file.read()
    except OSError as error:
        raise ValueError("cannot read the patches of {}: {}".format(path, error)) from None
    text = re.sub(r"/\*.*?\*/|//[^\n]*", "", text, flags=re.S)
    text = text[text.index("}", text.index("FoamFile")) + 1:] if "FoamFile" in text else text
    patches = {}
    for name, body in re.findall(r"(\w+)\s*\{([^{}]*)\}", text):
        entries = dict(re.findall(r"(\w+)\s+([^;]+);", body))
        patches[name] = dict(type=entries.get("type"), nFaces=int(entries.get("nFaces", 0)),
                             startFace=int(entries.get("startFace", 0)))
    return patches


def check_patches(case):
    """The mesh's patches, checked: a wall, at least one outer patch, BVMesh's patch types; a
    symmetry plane when the model is a half model."""
    patches = read_boundary(case)
    if "wall" not in patches or not any(name in patches for name in OUTER_PATCHES):
        raise ValueError("the mesh of {} needs a patch 'wall' and an outer patch ({}); it has: {}".format(
            case, ", ".join(OUTER_PATCHES), ", ".join(patches) or "none"))
    for name, entry in patches.items():
        if name not in PATCHES:
            raise ValueError("the mesh of {} has a patch '{}' that BVMesh cases do not know (known: {})".format(
                case, name, ", ".join(PATCHES)))
        if entry["type"] != PATCHES[name]:
            raise ValueError("patch '{}' of {} is of type {}, expected {}".format(
                name, case, entry["type"], PATCHES[name]))
    return patches


def scale_points(case, factor):
    """Multiplies constant/polyMesh/points by factor (ascii points as BVMesh writes them)."""
    path = os.path.join(case, "constant", "polyMesh", "points")
    with open(path) as file:
        text = file.read()
    start = text.index("(", text.index("}", text.index("FoamFile")))
    count = int(text[:start].split()[-1])
    body = text[start + 1:text.rindex(")")]
    values = re.findall(r"\(([^()]*)\)", body)
    if len(values) != count:
        raise ValueError("{}: {} points announced, {} read".format(path, count, len(values)))
    lines = []
    for value in values:
        x, y, z = (float(c) * factor for c in value.split())
        lines.append("({!r} {!r} {!r})".format(x, y, z))
    with open(path, "w") as file:
        file.write(text[:start] + "(\n" + "\n".join(lines) + "\n)\n")


def _boundary_field(entries, patches):
    """The boundaryField of the patches the mesh has: the 'farfield' entry for every outer patch,
    the 'symmetry' entry only for a half model."""
    expanded = []
    for name, items in entries:
        if name == "farfield":
            expanded += [(outer, items) for outer in OUTER_PATCHES if outer in patches]
        elif name in patches:
            expanded.append((name, items))
    return "boundaryField\n{\n" + "".join(
        "    {}\n    {{\n{}    }}\n".format(name, "".join("        {:<16}{};\n".format(k, v) for k, v in items))
        for name, items in expanded) + "}\n"


def _fields(case, flow, model, patches):
    p, T, U = flow["p"], flow["T"], _vector(flow["velocity"])
    symmetry = ("symmetry", [("type", "symmetryPlane")])
    wall_u = [("type", "slip")] if model == "euler" else [("type", "noSlip")]
    files = {
        "p": ("volScalarField", "[1 -1 -2 0 0 0 0]", "{!r}".format(p), [
            ("wall", [("type", "zeroGradient")]), symmetry,
            # Riemann-free far field: fixed value where the flow comes in, extrapolated where it leaves.
            ("farfield", [("type", "freestreamPressure"), ("freestreamValue", "uniform {!r}".format(p)),
                          ("supersonic", "false"), ("value", "uniform {!r}".format(p))])]),
        "U": ("volVectorField", "[0 1 -1 0 0 0 0]", U, [
            ("wall", wall_u), symmetry,
            ("farfield", [("type", "freestreamVelocity"), ("freestreamValue", "uniform " + U),
                          ("value", "uniform " + U)])]),
        "T": ("volScalarField", "[0 0 0 1 0 0 0]", "{!r}".format(T), [
            ("wall", [("type", "zeroGradient")]), symmetry,
            ("farfield", [("type", "inletOutlet"), ("inletValue", "uniform {!r}".format(T)),
                          ("value", "uniform {!r}".format(T))])]),
    }
    if model == "rans":
        nu = flow["viscosity"] / flow["rho"]
        nu_tilda = 3.0 * nu  # fully turbulent free stream (Spalart & Allmaras' recommendation 3-5 nu)
        chi3 = 27.0
        nut = nu_tilda * chi3 / (chi3 + 7.1 ** 3)
        files["nuTilda"] = ("volScalarField", "[0 2 -1 0 0 0 0]", "{!r}".format(nu_tilda), [
            ("wall", [("type", "fixedValue"), ("value", "uniform 0")]), symmetry,
            ("farfield", [("type", "inletOutlet"), ("inletValue", "uniform {!r}".format(nu_tilda)),
                          ("value", "uniform {!r}".format(nu_tilda))])])
        # Spalding's law covers y+ ~ 1 (low-Re) and log-layer wall cells alike.
        files["nut"] = ("volScalarField", "[0 2 -1 0 0 0 0]", "{!r}".format(nut), [
            ("wall", [("type", "nutUSpaldingWallFunction"), ("value", "uniform 0")]), symmetry,
            ("farfield", [("type", "freestream"), ("freestreamValue", "uniform {!r}".format(nut)),
                          ("value", "uniform {!r}".format(nut))])])
        files["alphat"] = ("volScalarField", "[1 -1 -1 0 0 0 0]", "0", [
            ("wall", [("type", "compressible::alphatWallFunction"), ("Prt", "0.85"), ("value", "uniform 0")]),
            symmetry, ("farfield", [("type", "calculated"), ("value", "uniform 0")])])
    for name, (cls, dimensions, internal, boundary) in files.items():
        _write(case, "0", name, "dimensions      {};\n\ninternalField   uniform {};\n\n{}".format(
            dimensions, internal, _boundary_field(boundary, patches)), cls=cls)
    return sorted(files)


def _constant(case, flow, model):
    cp = GAMMA / (GAMMA - 1.0) * GAS_CONSTANT
    if model == "euler":
        transport = "const", "        mu          0;\n        Pr          0.72;\n"
    else:
        transport = "sutherland", "        As          {!r};\n        Ts          {!r};\n".format(
            SUTHERLAND_AS, SUTHERLAND_TS)
    _write(case, "constant", "thermophysicalProperties", """thermoType
{{
    type            hePsiThermo;
    mixture         pureMixture;
    transport       {transport};
    thermo          hConst;
    equationOfState perfectGas;
    specie          specie;
    energy          sensibleInternalEnergy;
}}

mixture
{{
    specie
    {{
        molWeight   28.9644;
    }}
    thermodynamics
    {{
        Cp          {cp!r};
        Hf          0;
    }}
    transport
    {{
{coefficients}    }}
}}
""".format(transport=transport[0], cp=cp, coefficients=transport[1]))
    if model == "euler":
        turbulence = "simulationType  laminar;\n"
    else:
        turbulence = ("simulationType  RAS;\n\nRAS\n{\n    RASModel        SpalartAllmaras;\n"
                      "    turbulence      on;\n    printCoeffs     off;\n}\n")
    _write(case, "constant", "turbulenceProperties", turbulence)


def _residual_function_objects(solver, fields):
    """The residual history's function objects. The pressure-based solvers report their linear
    solvers' initial residuals; rhoCentralFoam's explicit update has no linear solve (its diagonal
    'solvers' report 0), so its residual is the mean over the cells of |d(rho, rho U, rho E)/dt|:
    with local time stepping that is the steady equations' flux imbalance per unit volume."""
    if solver != "rhoCentralFoam":
        solved = [f for f in ("p", "U", "e", "nuTilda") if f in fields or f == "e"]
        return """    residuals
    {{
        type            solverInfo;
        libs            ("libutilityFunctionObjects.so");
        fields          ({});
        writeControl    timeStep;
        writeInterval   1;
    }}
""".format(" ".join(solved))
    return """    conservedRates
    {
        type            ddt2;
        libs            ("libfieldFunctionObjects.so");
        fields          (rho rhoU rhoE);
        mag             true;
        result          mag(ddt(@@));
        executeControl  timeStep;
        writeControl    none;
        log             false;
    }
    residuals
    {
        type            volFieldValue;
        libs            ("libfieldFunctionObjects.so");
        fields          (mag(ddt(rho)) mag(ddt(rhoU)) mag(ddt(rhoE)));
        operation       average;
        regionType      all;
        writeFields     false;
        writeControl    timeStep;
        writeInterval   1;
        log             false;
    }
"""


def _system(case, flow, model, solver, iterations, write_interval, reference, fields, max_courant):
    lift = (-math.sin(math.radians(flow["alpha_degrees"])), 0.0, math.cos(math.radians(flow["alpha_degrees"])))
    drag = (math.cos(math.radians(flow["alpha_degrees"])), 0.0, math.sin(math.radians(flow["alpha_degrees"])))
    _write(case, "system", "controlDict", """application     {solver};
startFrom       latestTime;
startTime       0;
stopAt          endTime;
endTime         {iterations};
deltaT          1;
writeControl    timeStep;
writeInterval   {write_interval};
purgeWrite      2;
writeFormat     binary;
writePrecision  12;
writeCompression off;
timeFormat      general;
timePrecision   8;
runTimeModifiable false;
{central_time_control}
functions
{{
{residuals}    forceCoeffs
    {{
        type            forceCoeffs;
        libs            ("libforces.so");
        patches         (wall);
        rho             rho;
        rhoInf          {rho!r};
        pRef            {p!r};
        magUInf         {speed!r};
        lRef            {lref!r};
        Aref            {aref!r};
        CofR            {cofr};
        liftDir         {lift};
        dragDir         {drag};
        pitchAxis       (0 1 0);
        writeControl    timeStep;
        writeInterval   1;
        log             false;
    }}
    wallPressure
    {{
        type            surfaces;
        libs            ("libsampling.so");
        writeControl    writeTime;
        surfaceFormat   vtk;
        formatOptions
        {{
            vtk {{ legacy true; format ascii; }}
        }}
        interpolationScheme cellPoint;
        fields          (p);
        surfaces
        (
            wall
            {{
                type        patch;
                patches     (wall);
                interpolate true;
            }}
        );
    }}
    MachNo
    {{
        type            MachNo;
        libs            ("libfieldFunctionObjects.so");
        writeControl    writeTime;
    }}
}}
""".format(solver=solver, iterations=iterations, write_interval=write_interval,
           residuals=_residual_function_objects(solver, fields),
           # rhoCentralFoam reads its local time step's Courant number here (rhoPimpleFoam: fvSolution's
           # PIMPLE); smoothing 1 for the reason given there.
           central_time_control="adjustTimeStep  no;\nmaxCo           {!r};\nmaxDeltaT       1;\n"
                                "rDeltaTSmoothingCoeff 1;\n".format(max_courant) if solver == "rhoCentralFoam" else "",
           rho=flow["rho"], p=flow["p"], speed=flow["speed"], lref=reference["length"], aref=reference["area"],
           cofr=_vector(reference["moment_point"]), lift=_vector(lift), drag=_vector(drag)))

    if solver == "rhoCentralFoam":
        dictionaries = openfoam_schemes.central_schemes()
    else:
        dictionaries = openfoam_schemes.pressure_based_schemes(solver == "rhoPimpleFoam", max_courant, model)
    for name, body in dictionaries.items():
        _write(case, "system", name, body)
    fv_options = os.path.join(case, "system", "fvOptions")
    if model == "rans":
        # The RANS start on a y+ ~ 1 grid drove T negative at step 2 without this guard. Not for
        # euler: there it would clip the tip's trailing-edge corner (925 K on the level-2 grid,
        # docs/cfd.md) and hide the defect.
        _write(case, "system", "fvOptions", """limitT
{{
    type            limitTemperature;
    selectionMode   all;
    min             {:.6g};
    max             {:.6g};
}}
""".format(0.3 * flow["T"], 3.0 * flow["T"]))
    elif os.path.exists(fv_options):
        os.remove(fv_options)


# Fields a solver run writes into each of its time folders (any one marks a folder as one).
_TIME_FOLDER_MARKS = ("p", "U", "T", "rho", "phi", "uniform")


def _is_time_folder(path):
    return os.path.isdir(path) and any(
        os.path.exists(os.path.join(path, mark)) or os.path.exists(os.path.join(path, mark + ".gz"))
        for mark in _TIME_FOLDER_MARKS)


def _clear_earlier_case(case):
    """Clears what an earlier write_case and its solver runs wrote into `case` (0/, system/,
    postProcessing/, the time folders) before the case is written again. A folder without the
    case's settings file may hold an OpenFOAM mesh alone (constant/, and system/ from
    bvmesh.grid.write_openfoam, whose files are then overwritten by name); anything else in a
    folder, or a number-named folder that is no time folder, is refused: nothing is deleted that
    write_case did not write (a user's folders beside their mesh, their document)."""
    entries = os.listdir(case)
    ours = any(os.path.isfile(os.path.join(case, name)) for name in (SETTINGS_FILE, OWNER_MARK))
    if ours:
        numbered = [e for e in entries if re.fullmatch(r"[0-9.e+-]+", e) and os.path.isdir(os.path.join(case, e))]
        foreign = [e for e in numbered if e != "0" and not _is_time_folder(os.path.join(case, e))]
    else:
        numbered = []
        foreign = [e for e in entries if e not in ("constant", "system")]
    if foreign:
        shown = ", ".join(sorted(foreign)[:5]) + (" ..." if len(foreign) > 5 else "")
        raise ValueError("{} holds {}, which write_case did not write: write the case into an empty or new folder "
                         "(nothing was deleted)".format(case, shown))
    open(os.path.join(case, OWNER_MARK), "w").close()
    if not ours:
        return
    for stale in ["0", "system", "postProcessing"] + numbered:
        shutil.rmtree(os.path.join(case, stale), ignore_errors=True)


def _time_folders(case):
    """The case's written time folders other than 0, in time order."""
    found = []
    for name in os.listdir(case):
        try:
            value = float(name)
        except ValueError:
            continue
        if name != "0" and value > 0.0 and _is_time_folder(os.path.join(case, name)):
            found.append((value, name))
    return [name for _, name in sorted(found)]


def _check_initial_solution(path):
    source = os.path.abspath(os.fspath(path))
    if not os.path.isfile(os.path.join(source, SETTINGS_FILE)):
        raise ValueError("initial_solution {} is not a case written by write_case (no {})".format(source, SETTINGS_FILE))
    written = _time_folders(source)
    if not written or not os.path.exists(os.path.join(source, written[-1], "U")):
        raise ValueError("initial_solution {} has no solution written (no time folder after 0 with U): run it "
                         "first".format(source))
    return source


def write_case(grid_or_refined, case_directory, mach=M6_MACH, alpha_degrees=M6_ALPHA_DEGREES, pressure=None,
               temperature=M6_TEMPERATURE, reynolds_number=None, model="euler", length_unit=0.001,
               reference_length=M6_REFERENCE_LENGTH, reference_area=M6_REFERENCE_AREA,
               moment_point=M6_MOMENT_POINT, iterations=DEFAULT_ITERATIONS, solver=DEFAULT_SOLVER,
               write_interval=None,
               semispan=M6_SEMISPAN, max_courant=None, startup_iterations=50, startup_courant=0.25,
               initial_solution=None, wall_damped_start=None, force=False):
    """Writes a complete OpenFOAM case and returns its directory.

    grid_or_refined: a bvmesh grid (refine's result or a StructuredGrid), or the path of a case
    directory holding constant/polyMesh (copied; in model units, so a case written here, already
    in metres, needs length_unit=1) with patches wall, outer ones and symmetry on a half model. mach, alpha_degrees (x-z plane, y the span), temperature (K) and pressure (Pa) of the
    free stream; without a pressure it is set from reynolds_number on reference_length (1e5 Pa
    when neither is given). model: 'euler' (inviscid, slip wall) or 'rans' (Spalart-Allmaras,
    Sutherland viscosity, noSlip wall; needs reynolds_number or a pressure). length_unit: metres
    per model unit of the grid. reference_length (m), reference_area (m^2), moment_point (m): the
    force coefficients' references. semispan (m): kept for the post-processing's span stations.
    solver: 'rhoPimpleFoam' (pressure-based, local time stepping), 'rhoSimpleFoam' (SIMPLE,
    transonic) or 'rhoCentralFoam' (density-based, Kurganov & Tadmor's central-upwind fluxes,
    explicit with local time stepping; euler only).
    iterations: solver steps; write_interval: steps between writes (default iterations).
    max_courant: the local time step's Courant number (default 2 for rhoPimpleFoam, 0.5 for it
    on model 'rans', 0.2 for rhoCentralFoam); rhoPimpleFoam runs its first startup_iterations at startup_courant, since
    the impulsive start from the uniform free stream diverged at Courant 2 on the 295 k-cell M6
    grid and at 0.5 on a 59 k-cell one (a run of no more steps runs at startup_courant
    throughout, and so does its continuation); rhoCentralFoam runs its last third (from the last write
    before two thirds of the iterations) at half of max_courant, where its CL settles
    (bvmesh.openfoam_run.run_case runs the stages).
    initial_solution: a case written by write_case and run (an euler solution on the same wing,
    on this grid or another one with the same patches): run_case first maps its latest fields onto
    this grid (mapFields, cell-point interpolation) instead of starting from the free stream.
    wall_damped_start (default: for model 'rans' only): run_case first damps U within the
    flat-plate boundary-layer thickness at reference_length (flat_plate_boundary_layer_thickness)
    by the 1/7th-power profile in the wall distance (applyBoundaryLayer), so that the no-slip
    wall does not stop the free stream at once in the wall cells. Both are done once, before the
    first stage of a case that has no time step written yet (start_case).
    force: let the grid writer accept non-positive cells.
    """
    if model not in MODELS:
        raise ValueError("model must be one of {}, got {!r}".format(", ".join(MODELS), model))
    if solver not in SOLVERS:
        raise ValueError("solver must be one of {}, got {!r}".format(", ".join(SOLVERS), solver))
    if not (isinstance(iterations, int) and iterations > 0):
        raise ValueError("iterations must be a positive integer, got {!r}".format(iterations))
    write_interval = iterations if write_interval is None else write_interval
    if not (isinstance(write_interval, int) and write_interval > 0):
        raise ValueError("write_interval must be a positive integer, got {!r}".format(write_interval))
    if not (length_unit > 0.0 and math.isfinite(length_unit)):
        raise ValueError("length_unit must be > 0 (metres per model unit), got {!r}".format(length_unit))
    if not (reference_length > 0.0 and reference_area > 0.0):
        raise ValueError("reference_length and reference_area must be > 0, got {!r} and {!r}".format(
            reference_length, reference_area))
    if solver in EULER_ONLY_SOLVERS and model != "euler":
        raise ValueError("solver {} is set up for model 'euler' only; use rhoPimpleFoam for {!r}".format(
            solver, model))
    if max_courant is None:
        max_courant = DEFAULT_RANS_COURANT if model == "rans" and solver == "rhoPimpleFoam" else DEFAULT_COURANT[solver]
    if not (max_courant > 0.0 and math.isfinite(max_courant)):
        raise ValueError("max_courant must be > 0, got {!r}".format(max_courant))
    if not (startup_courant > 0.0 and math.isfinite(startup_courant)):
        raise ValueError("startup_courant must be > 0, got {!r}".format(startup_courant))
    if not (isinstance(startup_iterations, int) and startup_iterations >= 0):
        raise ValueError("startup_iterations must be an integer >= 0, got {!r}".format(startup_iterations))
    if iterations % write_interval:
        raise ValueError("write_interval ({}) must divide iterations ({}): OpenFOAM writes only at write "
                         "times".format(write_interval, iterations))
    if len(moment_point) != 3:
        raise ValueError("moment_point must be 3 coordinates, got {!r}".format(moment_point))
    if model == "rans" and reynolds_number is None and pressure is None:
        raise ValueError("model 'rans' needs reynolds_number (or a pressure that sets it)")
    flow = freestream(mach, alpha_degrees, temperature, pressure, reynolds_number, reference_length)
    wall_damped_start = model == "rans" if wall_damped_start is None else wall_damped_start
    if wall_damped_start and model != "rans":
        raise ValueError("wall_damped_start is for model 'rans' (a no-slip wall); model {!r} has a slip wall".format(
            model))
    if initial_solution is not None:
        initial_solution = _check_initial_solution(initial_solution)

    case = os.path.abspath(os.fspath(case_directory))
    try:
        os.makedirs(case, exist_ok=True)
        probe = os.path.join(case, ".bvmesh_write_test")
        with open(probe, "w"):
            pass
        os.remove(probe)
    except OSError as error:
        raise ValueError("cannot write the case directory {}: {}".format(case, error)) from None
    _clear_earlier_case(case)

    if isinstance(grid_or_refined, (str, os.PathLike)):
        source = os.path.abspath(os.fspath(grid_or_refined))
        check_patches(source)
        if length_unit != 1.0 and os.path.isfile(os.path.join(source, SETTINGS_FILE)):
            raise ValueError("{} is a case written by write_case, already in metres: pass length_unit=1 "
                             "(got {!r})".format(source, length_unit))
        if source != case:
            target = os.path.join(case, "constant", "polyMesh")
            shutil.rmtree(target, ignore_errors=True)
            shutil.copytree(os.path.join(source, "constant", "polyMesh"), target)
    else:
        from . import grid as bvgrid

        bvgrid.write_openfoam(grid_or_refined, case, force)
    patches = check_patches(case)
    if length_unit != 1.0:
        scale_points(case, length_unit)
    if initial_solution is not None and set(read_boundary(initial_solution)) != set(patches):
        raise ValueError("initial_solution {} has the patches {}, this case {}: mapFields maps between equal "
                         "patch sets".format(initial_solution, ", ".join(read_boundary(initial_solution)),
                                             ", ".join(patches)))

    fields = _fields(case, flow, model, patches)
    _constant(case, flow, model)
    reference = dict(length=reference_length, area=reference_area, moment_point=tuple(moment_point))
    _system(case, flow, model, solver, iterations, write_interval, reference, fields, max_courant)
    stages = [dict(end=iterations, max_courant=max_courant, write_interval=write_interval)]
    if solver == "rhoPimpleFoam" and 0 < startup_iterations < iterations:
        stages.insert(0, dict(end=startup_iterations, max_courant=startup_courant,
                              write_interval=startup_iterations))
    elif solver == "rhoPimpleFoam" and startup_iterations > 0:
        # A run no longer than the start-up is all start-up (a continuation goes on at its Courant
        # number): started at max_courant, a sphere's and the hemisphere-cylinder's euler grids
        # diverged in their first step.
        stages = [dict(end=iterations, max_courant=startup_courant, write_interval=write_interval)]
    if solver == "rhoCentralFoam":
        # The last third at half the Courant number: on the 300 k-cell M6 grid CL wandered by 2 %
        # over thousands of steps at 0.2 and settled to 0.15 % at 0.1 (docs/cfd.md).
        settling = (2 * iterations // 3) // write_interval * write_interval
        if settling > 0:
            stages = [dict(end=settling, max_courant=max_courant, write_interval=write_interval),
                      dict(end=iterations, max_courant=0.5 * max_courant, write_interval=write_interval)]
    settings = dict(model=model, solver=solver, iterations=iterations, stages=stages, max_courant=max_courant,
                    length_unit=length_unit,
                    semispan=semispan, reference=reference, freestream=flow,
                    wall_faces=patches["wall"]["nFaces"], fields=fields,
                    start=dict(initial_solution=initial_solution,
                               boundary_layer_thickness=flat_plate_boundary_layer_thickness(
                                   flow["reynolds_number"], reference_length) if wall_damped_start else None))
    with open(os.path.join(case, SETTINGS_FILE), "w") as file:
        json.dump(settings, file, indent=2)
    open(os.path.join(case, "case.foam"), "w").close()  # for ParaView
    return case


def m6_grid(preset="euler", level=2, edge_points=None, normal_points=None, reynolds_number=11.72e6, wing_file=None,
            target_cells=None, leading_edge_spacing=2.0, y_plus=None, knife_edge_fans=False):
    """A grid of the bundled ONERA M6 half wing (mm): the half_wing template fitted at `level`
    (1e-5 root chord tolerance), the volume mesh (reference length 805 mm; above level 2 marched
    from the level-2 wall, as the main job's) and bvmesh.grid.refine(..., preset, target_cells,
    normal_points; reynolds_number and y_plus, the first cell's flat-plate y+ (default the preset's
    1), for 'rans'): about target_cells cells (default 300 000),
    spaced as the wall needs, or with edge_points points on every block edge instead.
    leading_edge_spacing (mm; 0 or None: none): the wall's spacing away from the leading edge, a
    feature line along the measured leading-edge sweep from the root's nose (with counts from
    the wall alone the nose gets about 8 cells).
    Euler at level 2 with the defaults is the 300 k-cell grid of docs/cfd.md (checkMesh "Mesh
    OK."; 32 faces above 70 degrees, all on the tip cap, where the nose's clustering runs out;
    none without the leading-edge spacing). Equal edge counts give the wall's small blocks (the
    trailing edge's tip corner) the counts of the large ones: 17 edge points make 1102 faces
    above 70 degrees, and rhoPimpleFoam diverges on that grid in its first iterations.
    edge_points=5, normal_points=9 gives 3 k cells. knife_edge_fans: the sharp trailing edge cut
    open with a fan of prisms round it (bvmesh.volume.offset_and_farfield)."""
    from . import grid as bvgrid
    from . import load_core, paths, polyhedra, volume

    if edge_points is not None and target_cells is not None:
        raise ValueError("m6_grid takes edge_points or target_cells, not both")
    core = load_core()
    wing, _, _ = polyhedra.half_model_target(core.read_cad_file_as_brep(wing_file or paths.EXAMPLE_WING))
    placed = polyhedra.place("half_wing", wing)

    def fitted(max_level):
        fitter = core.SurfaceFitter(wing, placed["mesh"], placed["feature_map"],
                                    symmetry_plane=placed["symmetry_plane"], max_level=max_level,
                                    tolerance=1e-5 * 805.0, check_samples_per_face=0)
        fitter.run()
        return fitter

    marching_wall = fitted(volume.WING_MARCHING_LEVEL) if level > volume.WING_MARCHING_LEVEL else None
    mesh = volume.offset_and_farfield(fitted(level), marching_wall=marching_wall, reference_length=805.0,
                                      knife_edge_fans=knife_edge_fans)
    options = dict(edge_points=edge_points) if edge_points is not None else dict(target_cells=target_cells or 300000)
    if normal_points is not None:
        options["normal_points"] = normal_points
    if preset == "rans":
        options["reynolds_number"] = reynolds_number
        if y_plus is not None:
            options["y_plus"] = y_plus
    elif y_plus is not None:
        raise ValueError("y_plus is for the 'rans' preset")
    if leading_edge_spacing:
        options["feature_spacings"] = [{"points": _leading_edge(placed), "spacing": leading_edge_spacing,
                                        "tolerance": 2.0}]
    return bvgrid.refine(mesh, preset, **options)


def _leading_edge(placed):
    """The half wing's leading edge as a straight polyline: from the root's nose (the placed root
    ring's vertex farthest upstream) along the measured sweep to the tip's span."""
    import numpy as np

    planform = placed["planform"]
    vertices = np.asarray(placed["mesh"].vertices)
    span = np.asarray(planform["span_direction"])
    root = vertices[np.abs(vertices @ span) < 1e-6 * planform["span"]]
    nose = root[np.argmin(root[:, 0])]
    s = np.linspace(0.0, planform["span"], 60)[:, None]
    along = span + math.tan(math.radians(planform["leading_edge_sweep_deg"])) * np.array([1.0, 0.0, 0.0])
    return nose + s * along


def read_settings(case):
    path = os.path.join(case, SETTINGS_FILE)
    try:
        with open(path) as file:
            return json.load(file)
    except OSError:
        raise ValueError("{} is not a case written by bvmesh.openfoam_case (no {})".format(
            case, SETTINGS_FILE)) from None

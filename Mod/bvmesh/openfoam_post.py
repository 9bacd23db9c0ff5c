"""Post-processing of a case written by bvmesh.openfoam_case: residual and force-coefficient
histories, the wall pressure cut at span stations as Cp = (p - p_inf) / (0.5 rho_inf U_inf^2),
the comparison with the ONERA M6 measurements (AGARD AR-138 test 2308), plots and a report.

    import bvmesh.openfoam_post as post
    summary = post.write_report("m6_euler", "build/cfd")      # PNGs and report.md

Pure Python with numpy (matplotlib for the plots).
"""

import math
import os
import re

import numpy as np

from .paths import RESOURCES_DIR

EXPERIMENT_FILE = os.path.join(RESOURCES_DIR, "reference", "onera_m6_cp_experiment_case2308.dat")
STATIONS = (0.20, 0.44, 0.65, 0.80, 0.90, 0.96, 0.99)


def _latest_dir(folder):
    """The numerically largest time sub-directory of folder (function objects restart in a new one)."""
    if not os.path.isdir(folder):
        return []
    times = []
    for entry in os.listdir(folder):
        try:
            times.append((float(entry), entry))
        except ValueError:
            pass
    return [os.path.join(folder, entry) for _, entry in sorted(times)]


def _read_table(folder, file_name):
    """Columns of a function object's .dat files (all restarts, later ones overriding earlier rows)
    as {header name: array}, or {} when there is none."""
    rows, names = {}, None
    for directory in _latest_dir(folder):
        path = os.path.join(directory, file_name)
        if not os.path.isfile(path):
            continue
        with open(path) as file:
            for line in file:
                if line.startswith("#"):
                    fields = line[1:].split()
                    if fields and fields[0] == "Time":
                        names = fields
                    continue
                values = line.split()
                if names and len(values) == len(names):
                    rows[float(values[0])] = values
    if not rows:
        return {}
    times = sorted(rows)
    table = {}
    for column, name in enumerate(names):
        try:
            table[name] = np.array([float(rows[t][column]) for t in times])
        except ValueError:
            pass  # solver names, convergence flags
    return table


def read_residuals(case):
    """Residuals per field from the residuals function object: the pressure-based solvers' initial
    residuals (vector fields: the largest component), {'iteration': array, 'p': array, 'U': array,
    'e': array, ...}, or rhoCentralFoam's cell mean of |d/dt| per conserved variable,
    {'iteration', 'rho', 'rhoU', 'rhoE'}."""
    folder = os.path.join(case, "postProcessing", "residuals")
    rates = _read_table(folder, "volFieldValue.dat")
    if rates:
        result = {"iteration": rates["Time"]}
        for name, values in rates.items():
            match = re.fullmatch(r"average\(mag\(ddt\((\w+)\)\)\)", name)
            if match:
                result[match.group(1)] = values
        return result
    table = _read_table(folder, "solverInfo.dat")
    if not table:
        return {}
    result = {"iteration": table["Time"]}
    groups = {}
    for name in table:
        if name.endswith("_initial"):
            base = name[:-len("_initial")]
            if base[-1] in "xyz" and all(base[:-1] + c + "_initial" in table for c in "xyz"):
                base = base[:-1]
            groups.setdefault(base, []).append(table[name])
    for field, components in groups.items():
        result[field] = np.max(components, axis=0)
    return result


def read_force_coefficients(case):
    """{'iteration', 'Cd', 'Cl', 'CmPitch', ...} from the forceCoeffs function object ({} if none)."""
    table = _read_table(os.path.join(case, "postProcessing", "forceCoeffs"), "coefficient.dat")
    if table:
        table["iteration"] = table.pop("Time")
    return table


def read_vtk_polydata(path):
    """A legacy ASCII VTK POLYDATA file (as OpenFOAM's surface writer writes it): points (n, 3),
    faces (a list of vertex-index arrays), point_data and cell_data ({name: array})."""
    with open(path) as file:
        tokens = file.read().split()
    position = 0

    def take(count, kind=float):
        nonlocal position
        values = np.array(tokens[position:position + count], dtype=kind)
        position += count
        return values

    points, faces, point_data, cell_data, target = None, [], {}, {}, None
    while position < len(tokens):
        word = tokens[position]
        position += 1
        if word == "POINTS":
            count = int(tokens[position])
            position += 2
            points = take(3 * count).reshape(count, 3)
        elif word == "POLYGONS":
            count, size = int(tokens[position]), int(tokens[position + 1])
            position += 2
            flat = take(size, int)
            at = 0
            for _ in range(count):
                faces.append(flat[at + 1:at + 1 + flat[at]])
                at += flat[at] + 1
        elif word in ("POINT_DATA", "CELL_DATA"):
            target = point_data if word == "POINT_DATA" else cell_data
            position += 1
        elif word == "FIELD" and target is not None:
            arrays = int(tokens[position + 1])
            position += 2
            for _ in range(arrays):
                name, components, count = tokens[position], int(tokens[position + 1]), int(tokens[position + 2])
                position += 4
                values = take(components * count)
                target[name] = values.reshape(count, components) if components > 1 else values
        elif word == "SCALARS" and target is not None:
            name = tokens[position]
            position += 2 if tokens[position + 2] == "LOOKUP_TABLE" else 3
            position += 2  # LOOKUP_TABLE default
            count = len(points) if target is point_data else len(faces)
            target[name] = take(count)
    if points is None:
        raise ValueError("{} holds no POINTS".format(path))
    return dict(points=points, faces=faces, point_data=point_data, cell_data=cell_data)


def wall_surface_file(case, time=None):
    """The wall-pressure surface written at `time` (default: the latest)."""
    folders = _latest_dir(os.path.join(case, "postProcessing", "wallPressure"))
    if time is not None:
        folders = [f for f in folders if float(os.path.basename(f)) == float(time)]
    for folder in reversed(folders):
        path = os.path.join(folder, "wall.vtk")
        if os.path.isfile(path):
            return path
    raise ValueError("{} has no wall pressure surface (postProcessing/wallPressure/<time>/wall.vtk){}".format(
        case, "" if time is None else " at time {}".format(time)))


def pressure_coefficient(p, freestream):
    """Cp = (p - p_inf) / (0.5 rho_inf U_inf^2); freestream: a dict with p, rho and speed."""
    dynamic = 0.5 * freestream["rho"] * freestream["speed"] ** 2
    return (np.asarray(p, dtype=float) - freestream["p"]) / dynamic


def cut(points, faces, values, position, axis=1):
    """The surface (points (n, 3), polygon faces, point values (n,)) cut by the plane
    points[:, axis] = position. Values are interpolated linearly along the cut edges, so a field
    linear in space is reproduced exactly. Returns the cut's polylines, each as (xyz (m, 3),
    values (m,)), chained through shared edges (closed loops repeat their first point)."""
    points = np.asarray(points, dtype=float)
    values = np.asarray(values, dtype=float)
    if values.shape != (len(points),):
        raise ValueError("values must hold one value per point ({}), got shape {}".format(len(points), values.shape))
    distance = points[:, axis] - position
    above = distance >= 0.0
    crossing = {}
    segments = []
    for face in faces:
        face = np.asarray(face)
        if above[face].all() or not above[face].any():
            continue
        keys = []
        for a, b in zip(face, np.roll(face, -1)):
            if above[a] != above[b]:
                key = (min(a, b), max(a, b))
                if key not in crossing:
                    t = distance[a] / (distance[a] - distance[b])
                    crossing[key] = (points[a] + t * (points[b] - points[a]), values[a] + t * (values[b] - values[a]))
                keys.append(key)
        # A face crosses the plane an even number of times; pair the crossings in order around it.
        for k in range(0, len(keys) - 1, 2):
            segments.append((keys[k], keys[k + 1]))
    if not segments:
        return []
    neighbours = {}
    for s, (a, b) in enumerate(segments):
        neighbours.setdefault(a, []).append(s)
        neighbours.setdefault(b, []).append(s)
    used = np.zeros(len(segments), dtype=bool)
    lines = []
    # Open lines start at an end point (a key on one segment only), then the closed loops.
    starts = [key for key, owners in neighbours.items() if len(owners) == 1] + [a for a, _ in segments]
    for start in starts:
        free = [s for s in neighbours[start] if not used[s]]
        if not free:
            continue
        chain, key = [start], start
        while True:
            free = [s for s in neighbours[key] if not used[s]]
            if not free:
                break
            used[free[0]] = True
            a, b = segments[free[0]]
            key = b if a == key else a
            chain.append(key)
        xyz = np.array([crossing[k][0] for k in chain])
        value = np.array([crossing[k][1] for k in chain])
        lines.append((xyz, value))
    return lines


def section(points, faces, values, position, axis=1, lift_axis=2):
    """The wall's section at points[:, axis] = position split at its leading edge (smallest x)
    and trailing edge (largest x) into upper and lower surfaces (the one with the larger mean
    lift_axis coordinate is upper): {'upper': (x/c, values), 'lower': (x/c, values),
    'leading_edge', 'trailing_edge', 'chord'}, each surface ordered from the leading edge.
    Raises ValueError when the plane misses the surface."""
    lines = cut(points, faces, values, position, axis)
    if not lines:
        raise ValueError("the plane {} = {} does not cut the wall".format("xyz"[axis], position))
    # The longest line is the section; a section broken by a vertex on the plane is rejoined.
    lines.sort(key=lambda line: -len(line[0]))
    xyz, value = lines[0]
    for other_xyz, other_value in lines[1:]:
        gaps = [np.linalg.norm(xyz[-1] - other_xyz[0]), np.linalg.norm(xyz[-1] - other_xyz[-1])]
        if gaps[1] < gaps[0]:
            other_xyz, other_value = other_xyz[::-1], other_value[::-1]
        xyz, value = np.vstack([xyz, other_xyz]), np.concatenate([value, other_value])
    if np.allclose(xyz[0], xyz[-1]):
        xyz, value = xyz[:-1], value[:-1]
    leading, trailing = int(np.argmin(xyz[:, 0])), int(np.argmax(xyz[:, 0]))
    # Roll so the loop starts at the leading edge; the two branches then meet at the trailing edge.
    xyz, value = np.roll(xyz, -leading, axis=0), np.roll(value, -leading)
    trailing = (trailing - leading) % len(xyz)
    first = (xyz[:trailing + 1], value[:trailing + 1])
    second = (np.vstack([xyz[trailing:], xyz[:1]])[::-1], np.concatenate([value[trailing:], value[:1]])[::-1])
    chord = xyz[trailing, 0] - xyz[0, 0]
    if chord <= 0.0:
        raise ValueError("the section at {} = {} has no chord".format("xyz"[axis], position))
    if first[0][:, lift_axis].mean() > second[0][:, lift_axis].mean():
        upper, lower = first, second
    else:
        upper, lower = second, first

    def chordwise(branch):
        return (branch[0][:, 0] - xyz[0, 0]) / chord, branch[1]

    return dict(upper=chordwise(upper), lower=chordwise(lower), leading_edge=xyz[0], trailing_edge=xyz[trailing],
                chord=chord)


def read_experiment(path=EXPERIMENT_FILE):
    """The measured Cp of AGARD AR-138 test 2308 (Tecplot zones, one per section): a list of
    {'section', 'eta', 'upper': (x/c, cp), 'lower': (x/c, cp)} ordered by x/c."""
    zones, current = [], None
    with open(path) as file:
        for line in file:
            text = line.strip()
            if text.startswith("ZONE"):
                current = []
                zones.append(current)
            elif current is not None and text and text[0] in "+-.0123456789":
                current.append([float(v) for v in text.split()])
    sections = []
    for rows in zones:
        data = np.array(rows)
        number = int(round(data[0, 0]))
        if not 1 <= number <= len(STATIONS):
            raise ValueError("{}: unexpected section number {}".format(path, number))
        result = dict(section=number, eta=STATIONS[number - 1])
        for name, side in (("upper", data[:, 3] > 0.0), ("lower", data[:, 3] <= 0.0)):
            order = np.argsort(data[side, 2])
            result[name] = (data[side, 2][order], data[side, 4][order])
        sections.append(result)
    if not sections:
        raise ValueError("{} holds no zones".format(path))
    return sections


def rms_difference(computed, measured):
    """RMS of computed - measured Cp at the measured x/c of both surfaces (computed interpolated
    linearly along its own x/c), and the number of taps used."""
    differences = []
    for name in ("upper", "lower"):
        x, cp = computed[name]
        order = np.argsort(x)
        x, cp = x[order], cp[order]
        tap_x, tap_cp = measured[name]
        inside = (tap_x >= x[0]) & (tap_x <= x[-1])
        differences.append(np.interp(tap_x[inside], x, cp) - tap_cp[inside])
    differences = np.concatenate(differences)
    return float(np.sqrt(np.mean(differences ** 2))), len(differences)


# An upper-surface shock: a compression of at least SHOCK_MIN_RISE in Cp whose every segment rises
# by at least SHOCK_MIN_SLOPE per chord. On the wind-tunnel taps this finds the lambda's two
# shocks at eta 0.20-0.80 and the merged one outboard (their rises 0.18-0.78); a smeared
# recompression (rhoPimpleFoam's upwind one, about 1-2 per chord) is not a shock, nor is a run
# that rises all the way to the trailing edge: the sharp edge's recovery towards stagnation, 1.5
# per chord on the taps and 4.5 in the last 5 % of the chord on the 300 k grid's euler solution.
SHOCK_MIN_SLOPE = 3.0
SHOCK_MIN_RISE = 0.15


def shock_positions(x, cp, min_slope=SHOCK_MIN_SLOPE, min_rise=SHOCK_MIN_RISE):
    """The shocks of an upper-surface Cp distribution aft of its suction peak (its lowest Cp):
    each run of consecutive segments rising by at least min_slope per unit x whose whole rise is
    at least min_rise and that ends before the last point (a rise to the trailing edge is its
    recovery), placed where Cp crosses half its rise (the same point on a resolved jump, a
    smeared one and the coarse taps of a measurement). x: x/c (any order; repeated x dropped).
    Returns the positions in x order."""
    x, cp = np.asarray(x, dtype=float), np.asarray(cp, dtype=float)
    if x.shape != cp.shape or x.ndim != 1:
        raise ValueError("x and cp must be 1-d arrays of one length, got shapes {} and {}".format(x.shape, cp.shape))
    order = np.argsort(x, kind="stable")
    x, cp = x[order], cp[order]
    distinct = np.concatenate([[True], np.diff(x) > 0.0])
    x, cp = x[distinct], cp[distinct]
    if len(x) < 2 or not np.all(np.isfinite(cp)):
        return []
    steep = np.diff(cp) / np.diff(x) >= min_slope
    positions, segment = [], int(np.argmin(cp))
    while segment < len(steep):
        if not steep[segment]:
            segment += 1
            continue
        last = segment
        while last + 1 < len(steep) and steep[last + 1]:
            last += 1
        low, high = cp[segment], cp[last + 1]
        if high - low >= min_rise and last + 1 < len(steep):
            half = 0.5 * (low + high)
            k = segment + int(np.argmax(cp[segment + 1:last + 2] >= half))  # Cp rises through the run
            positions.append(float(x[k] + (half - cp[k]) / (cp[k + 1] - cp[k]) * (x[k + 1] - x[k])))
        segment = last + 1
    return positions


def shock_offsets(computed, measured):
    """Per measured shock, the offset (computed - measured, x/c) of the computed shock paired with
    it, or None: pairs are taken closest first, each shock in at most one, so one computed shock
    where the measurement has a lambda's two answers for one of them only."""
    pairs = sorted((abs(c - m), i, j) for i, m in enumerate(measured) for j, c in enumerate(computed))
    offsets, used = [None] * len(measured), set()
    for _, i, j in pairs:
        if offsets[i] is None and j not in used:
            offsets[i] = computed[j] - measured[i]
            used.add(j)
    return offsets


def read_log(path):
    """Solver wall time (s, summed over restarts: ClockTime starts again at each) and the
    number of time steps in a solver log."""
    clock, total, steps = 0.0, 0.0, 0
    with open(path, errors="replace") as file:
        for line in file:
            if line.startswith("Time = "):
                steps += 1
            match = re.search(r"ClockTime = ([0-9.eE+-]+) s", line)
            if match:
                value = float(match.group(1))
                if value < clock:
                    total += clock
                clock = value
    return dict(wall_time=total + clock, time_steps=steps)


def read_internal_field(case, time, name):
    """A field's cell values as written in ascii (write_case's start writes 0/ so): an (n,) or (n, 3)
    array; a uniform field gives one row per cell from the mesh's cell count."""
    path = os.path.join(case, str(time), name)
    with open(path, errors="replace") as file:
        text = file.read()
    text = re.sub(r"/\*.*?\*/|//[^\n]*", "", text, flags=re.S)
    if re.search(r"format\s+binary\s*;", text):
        raise ValueError("{} is written in binary; read_internal_field reads ascii fields".format(path))
    match = re.search(r"internalField\s+(uniform|nonuniform)\s+", text)
    if not match:
        raise ValueError("{} has no internalField".format(path))
    rest = text[match.end():]
    if match.group(1) == "uniform":
        value = rest[:rest.index(";")].strip().strip("()").split()
        values = np.tile(np.array(value, float), (cell_count(case), 1))
        return values[:, 0] if len(value) == 1 else values
    header = re.match(r"List<(\w+)>\s*(\d+)\s*\(", rest)
    if not header:
        raise ValueError("{}: cannot read its nonuniform internalField".format(path))
    count = int(header.group(2))
    body = rest[header.end():rest.index(";")]
    values = np.array(re.sub(r"[()]", " ", body).split()[:count * (3 if header.group(1) == "vector" else 1)], float)
    return values.reshape(count, 3) if header.group(1) == "vector" else values


def cell_count(case):
    with open(os.path.join(case, "constant", "polyMesh", "owner")) as file:
        head = file.read(2000)
    match = re.search(r"nCells:\s*(\d+)", head)
    if not match:
        raise ValueError("{}: the owner file's header has no nCells note".format(case))
    return int(match.group(1))


def residual_drop(residuals, orders=3.0):
    """The first iteration from which every field's residual stays `orders` decades below its
    largest value, or None; and the decades reached by the worst field at the end."""
    fields = [f for f in residuals if f != "iteration"]
    ratio = np.max([residuals[f] / residuals[f].max() for f in fields], axis=0)
    # Largest ratio from each iteration to the end: below the threshold means it stays there.
    ahead = np.maximum.accumulate(ratio[::-1])[::-1]
    reached = np.nonzero(ahead <= 10.0 ** -orders)[0]
    # + 0.0: a last residual at its peak reads 0 decades, not -0.
    return (int(residuals["iteration"][reached[0]]) if len(reached) else None), float(-np.log10(ratio[-1])) + 0.0


def station_results(case, experiment_path=EXPERIMENT_FILE, time=None):
    """Cp of the latest (or given) wall surface at every measured station, with the RMS
    difference to the measurement and the upper surface's shocks (shock_positions) computed and
    measured: a list of {eta, y, section, measured, rms, taps, shocks: {computed, measured,
    offsets}}."""
    from .openfoam_case import read_settings

    settings = read_settings(case)
    surface = read_vtk_polydata(wall_surface_file(case, time))
    if "p" not in surface["point_data"]:
        raise ValueError("the wall surface of {} has no point field p".format(case))
    cp = pressure_coefficient(surface["point_data"]["p"], settings["freestream"])
    results = []
    for measured in read_experiment(experiment_path):
        y = measured["eta"] * settings["semispan"]
        computed = section(surface["points"], surface["faces"], cp, y)
        rms, taps = rms_difference(computed, measured)
        shocks = dict(computed=shock_positions(*computed["upper"]), measured=shock_positions(*measured["upper"]))
        shocks["offsets"] = shock_offsets(shocks["computed"], shocks["measured"])
        results.append(dict(eta=measured["eta"], y=y, section=computed, measured=measured, rms=rms, taps=taps,
                            shocks=shocks))
    return results


def plot_station(result, path, title=""):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(6.4, 4.6))
    for name, colour in (("upper", "#c0392b"), ("lower", "#2e86c1")):
        x, cp = result["section"][name]
        axis.plot(x, cp, "-", color=colour, label="computed, {}".format(name))
        tap_x, tap_cp = result["measured"][name]
        axis.plot(tap_x, tap_cp, "o" if name == "upper" else "s", mfc="none", color=colour,
                  label="measured, {}".format(name))
    shocks = result.get("shocks", {})
    for kind, style in (("computed", "--"), ("measured", ":")):
        for k, position in enumerate(shocks.get(kind, [])):
            axis.axvline(position, linestyle=style, color="0.35", linewidth=0.9,
                         label="upper-surface shock, {}".format(kind) if k == 0 else None)
    axis.invert_yaxis()
    axis.set_xlabel("x / c")
    axis.set_ylabel("Cp")
    axis.set_title("{}eta = {:.2f} (y = {:.4g} m), RMS dCp = {:.3f}".format(
        title, result["eta"], result["y"], result["rms"]))
    axis.grid(alpha=0.3)
    axis.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def plot_upper_surface(surface, cp, path, stations=(), semispan=None, title=""):
    """Cp on the upper surface (faces whose normal points up), seen from above: where a lambda
    shock would show as two converging lines of steep Cp rise."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    points = surface["points"]
    corners = [points[face] for face in surface["faces"]]
    normals = np.array([np.cross(c[2] - c[0], c[-1] - c[1]) if len(c) > 3 else np.cross(c[1] - c[0], c[2] - c[0])
                        for c in corners])
    centres = np.array([c.mean(axis=0) for c in corners])
    # OpenFOAM's wall normals point out of the fluid, into the body; orient them away from the
    # body's centroid whatever the writer did.
    if np.einsum("ij,ij", normals, centres - points.mean(axis=0)) < 0.0:
        normals = -normals
    upper = normals[:, 2] > 0.0
    polygons = [c[:, :2] for c, up in zip(corners, upper) if up]
    values = [cp[face].mean() for face, up in zip(surface["faces"], upper) if up]
    # The figure takes the planform's proportions (a wing's, or a slender body's seen from above).
    extent = np.ptp(points[:, :2], axis=0)
    figure, axis = plt.subplots(figsize=(7.0, min(6.4, max(2.4, 1.6 + 5.0 * extent[1] / max(extent[0], 1e-30)))))
    values = np.array(values)
    # Colour range from the inboard faces' 1st to 99th percentile (the tip cap and the tip's
    # trailing-edge corner would flatten the rest), in 0.05 bands so that isobars show.
    inboard = np.array([p[:, 1].mean() for p in polygons]) < 0.95 * points[:, 1].max()
    low, high = np.percentile(values[inboard] if inboard.any() else values, [1.0, 99.0])
    low, high = 0.05 * math.floor(low / 0.05), 0.05 * math.ceil(high / 0.05)
    colours = matplotlib.colors.BoundaryNorm(np.arange(low, high + 0.025, 0.05), 256, extend="both")
    collection = PolyCollection(polygons, array=values, cmap="jet_r", norm=colours, edgecolors="face",
                                linewidths=0.2)
    axis.add_collection(collection)
    axis.autoscale()
    axis.set_aspect("equal")
    for eta in stations:
        axis.axhline(eta * semispan, color="k", lw=0.5, ls="--")
    figure.colorbar(collection, ax=axis, label="Cp (upper surface)")
    axis.set_xlabel("x (m)")
    axis.set_ylabel("y (m)")
    axis.set_title(title + "upper surface Cp" + ("; dashed: measured stations" if len(stations) else ""))
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def plot_convergence(residuals, coefficients, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (top, bottom) = plt.subplots(2, 1, figsize=(6.4, 6.4), sharex=True)
    # Each field over its own peak (rhoCentralFoam's rates differ by orders of magnitude between
    # rho and rho E): the scale on which residual_drop counts decades.
    for field in [f for f in residuals if f != "iteration"]:
        top.semilogy(residuals["iteration"], residuals[field] / residuals[field].max(), label=field)
    top.set_ylabel("residual / its peak")
    top.grid(alpha=0.3)
    top.legend()
    if coefficients:
        bottom.plot(coefficients["iteration"], coefficients["Cl"], color="k", label="CL")
        bottom.plot(coefficients["iteration"], 10 * coefficients["Cd"], color="#c0392b", label="10 CD")
        bottom.legend()
    bottom.set_xlabel("iteration")
    bottom.set_ylabel("coefficient")
    bottom.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def _positions(values):
    return ", ".join("{:.3f}".format(v) for v in values) or "none"


def _shock_verdict(stations, up_to_eta=0.90, within=0.05):
    """The flow-run goal of issue 17 in one line: every measured shock up to eta 0.90 has a
    computed one within 5 % of the chord."""
    offsets = [(r["eta"], o) for r in stations if r["eta"] <= up_to_eta + 1e-9 for o in r["shocks"]["offsets"]]
    if not offsets:
        return "No measured shock up to eta {:.2f}.".format(up_to_eta)
    missing = sorted({eta for eta, o in offsets if o is None})
    matched = [(abs(o), eta) for eta, o in offsets if o is not None]
    inside = sum(1 for miss, _ in matched if miss <= within)
    text = "Up to eta {:.2f}: {} of {} measured shocks have a computed shock within {:g} of the chord".format(
        up_to_eta, inside, len(offsets), within)
    if matched:
        text += "; the largest offset of a paired shock is {:.3f} (eta {:.2f})".format(*max(matched))
    if missing:
        text += "; {} without a computed shock (at eta {})".format(
            sum(1 for _, o in offsets if o is None), ", ".join("{:.2f}".format(e) for e in missing))
    return text + "."


def write_report(case, output_directory, experiment_path=EXPERIMENT_FILE, title="ONERA M6"):
    """Plots (cp_eta_<eta>.png per station, convergence.png), report.md and summary.json of a
    finished (or stopped) run in output_directory. Returns the summary dict. experiment_path None:
    a body the M6 measurements do not belong to; the report then has the run's convergence,
    forces and upper-surface Cp without the station cuts (summary['stations'] empty)."""
    import json

    from .openfoam_case import read_settings

    settings = read_settings(case)
    try:
        os.makedirs(output_directory, exist_ok=True)
    except OSError as error:
        raise ValueError("cannot write the report directory {}: {}".format(output_directory, error)) from None
    residuals, coefficients = read_residuals(case), read_force_coefficients(case)
    if not residuals:
        raise ValueError("{} has no residual history: run the solver first".format(case))
    log_path = os.path.join(case, "log.{}".format(settings["solver"]))
    log = read_log(log_path) if os.path.isfile(log_path) else dict(wall_time=float("nan"), time_steps=0)
    surface_time = os.path.basename(os.path.dirname(wall_surface_file(case)))
    stations = station_results(case, experiment_path) if experiment_path is not None else []
    surface = read_vtk_polydata(wall_surface_file(case))
    plot_upper_surface(surface, pressure_coefficient(surface["point_data"]["p"], settings["freestream"]),
                       os.path.join(output_directory, "upper_surface_cp.png"), [r["eta"] for r in stations],
                       settings["semispan"], title + ", ")
    drop_iteration, decades = residual_drop(residuals)
    plot_convergence(residuals, coefficients, os.path.join(output_directory, "convergence.png"))
    for result in stations:
        plot_station(result, os.path.join(output_directory, "cp_eta_{:.2f}.png".format(result["eta"])), title + ", ")
    flow = settings["freestream"]
    summary = dict(
        case=os.path.abspath(case), model=settings["model"], solver=settings["solver"], cells=cell_count(case),
        iterations=int(residuals["iteration"][-1]), wall_time=log["wall_time"], surface_time=float(surface_time),
        three_decades_at=drop_iteration, decades_reached=decades,
        final_residuals={f: float(v[-1]) for f, v in residuals.items() if f != "iteration"},
        CL=float(coefficients["Cl"][-1]) if coefficients else None,
        CD=float(coefficients["Cd"][-1]) if coefficients else None,
        CM=float(coefficients["CmPitch"][-1]) if coefficients else None,
        # Peak-to-peak CL over the last tenth of the run: the residuals' peak is the impulsive
        # start, so their drop alone flatters the convergence.
        CL_range_last_tenth=float(np.ptp(coefficients["Cl"][-max(1, len(coefficients["Cl"]) // 10):]))
        if coefficients else None,
        mach=flow["mach"], alpha_degrees=flow["alpha_degrees"],
        stations=[dict(eta=r["eta"], y=r["y"], chord=float(r["section"]["chord"]), rms=r["rms"], taps=r["taps"],
                       shocks=r["shocks"]) for r in stations])
    with open(os.path.join(output_directory, "summary.json"), "w") as file:
        json.dump(summary, file, indent=2)
    lines = ["# {}: {} ({}), Mach {:g}, alpha {:g} deg".format(title, settings["model"], settings["solver"],
                                                               flow["mach"], flow["alpha_degrees"]), "",
             "| quantity | value |", "|---|---|",
             "| cells | {} |".format(summary["cells"]),
             "| iterations | {} |".format(summary["iterations"]),
             "| wall time | {:.0f} s |".format(summary["wall_time"]),
             "| residuals 3 decades below their peak from | {} |".format(
                 "iteration {}".format(drop_iteration) if drop_iteration else "not reached"),
             "| decades reached (worst field, last iteration) | {:.2f} |".format(decades),
             "| final residuals | {} |".format(", ".join("{} {:.2e}".format(f, v)
                                                         for f, v in summary["final_residuals"].items())),
             "| CL | {} |".format("{:.4f}".format(summary["CL"]) if coefficients else "-"),
             "| CL peak to peak over the last tenth of the iterations | {} |".format(
                 "{:.2e}".format(summary["CL_range_last_tenth"]) if coefficients else "-"),
             "| CD | {} |".format("{:.5f}".format(summary["CD"]) if coefficients else "-"),
             "| CM (pitch, about ({}) m) | {} |".format(
                 ", ".join("{:g}".format(c) for c in settings["reference"]["moment_point"]),
                 "{:.4f}".format(summary["CM"]) if coefficients else "-"),
             "| wall surface from iteration | {} |".format(surface_time), ""]
    if stations:
        lines += _station_lines(stations, settings["semispan"])
    lines += ["![convergence](convergence.png)", "", "![upper surface Cp](upper_surface_cp.png)", ""] + [
        "![eta {0:.2f}](cp_eta_{0:.2f}.png)".format(r["eta"]) for r in stations]
    with open(os.path.join(output_directory, "report.md"), "w") as file:
        file.write("\n".join(lines) + "\n")
    return summary


def _station_lines(stations, semispan):
    """The report's comparison with the measurements: RMS dCp per station and the shocks."""
    lines = ["Cp = (p - p_inf) / (0.5 rho_inf U_inf^2) on the wall cut at y = eta * {:g} m, against AGARD AR-138 "
             "test 2308; RMS of the difference at the taps (computed curve interpolated along x/c).".format(
                 semispan), "",
             "| eta | y (m) | local chord (m) | taps | RMS dCp | plot |", "|---|---|---|---|---|---|"]
    for r in stations:
        lines.append("| {:.2f} | {:.4f} | {:.4f} | {} | {:.3f} | cp_eta_{:.2f}.png |".format(
            r["eta"], r["y"], r["section"]["chord"], r["taps"], r["rms"], r["eta"]))
    lines += ["", "Upper-surface shocks (x/c where Cp crosses half a compression of at least {:g} rising by "
              "{:g} per chord or more, aft of the suction peak; `openfoam_post.shock_positions`) and, per measured "
              "shock, the nearest computed one's offset:".format(SHOCK_MIN_RISE, SHOCK_MIN_SLOPE), "",
              "| eta | computed | measured | offset (computed - measured) |", "|---|---|---|---|"]
    for r in stations:
        shocks = r["shocks"]
        lines.append("| {:.2f} | {} | {} | {} |".format(
            r["eta"], _positions(shocks["computed"]), _positions(shocks["measured"]),
            ", ".join("none" if o is None else "{:+.3f}".format(o) for o in shocks["offsets"]) or "-"))
    return lines + ["", _shock_verdict(stations), ""]

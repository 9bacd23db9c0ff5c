"""Grid convergence of a flow quantity over three grids of one family: Richardson extrapolation and
the grid convergence index (GCI), by the procedure of Celik et al., "Procedure for estimation and
reporting of uncertainty due to discretization in CFD applications", J. Fluids Eng. 130 (2008),
which takes refinement ratios that differ between the two grid pairs.

    from bvmesh import grid_convergence
    study = grid_convergence.richardson([0.2800, 0.2783, 0.2745], [64000, 27000, 8000])
    print(study["order"], study["extrapolated"], study["gci_fine"])

`python3 -m bvmesh grid-convergence REPORT REPORT REPORT` reads the summary.json that
`openfoam-case --report` writes for each run and prints the study of CL, CD and CM.
"""

import json
import math
import os

# Fixed-point iterations for the observed order with unequal refinement ratios, and the change in
# the order below which it has converged.
ORDER_ITERATIONS = 200
ORDER_TOLERANCE = 1e-12
# Celik et al.'s factor of safety for three grids.
SAFETY_FACTOR = 1.25
QUANTITIES = ("CL", "CD", "CM")


def _checked_grids(values, cells, dimension):
    if len(values) != 3 or len(cells) != 3:
        raise ValueError("a grid convergence study takes three grids, got {} values and {} cell counts".format(
            len(values), len(cells)))
    if dimension not in (2, 3):
        raise ValueError("dimension must be 2 or 3, got {!r}".format(dimension))
    for value in values:
        if not math.isfinite(value):
            raise ValueError("the grids' values must be finite, got {}".format(list(values)))
    for count in cells:
        if not (isinstance(count, int) and count > 0):
            raise ValueError("cell counts must be positive integers, got {}".format(list(cells)))
    if len(set(cells)) != 3:
        raise ValueError("the three grids need different cell counts, got {}".format(list(cells)))
    order = sorted(range(3), key=lambda g: -cells[g])
    return [values[g] for g in order], [cells[g] for g in order]


def richardson(values, cells, dimension=3):
    """The study of one quantity: values and cells of three grids in any order (sorted here from
    the finest, grid 1, to the coarsest, grid 3). The representative spacing is h = N^(-1/dimension).
    Returns a dict: cells and values finest first, h, the ratios r21 = h2 / h1 and r32, 'convergence'
    ('monotone', 'oscillatory' when the differences change sign, 'none' when the two finer grids
    agree exactly, 'divergent' when the differences grow as the grid is refined, or when only the two
    coarser grids agree), the observed order p, the extrapolated value, the fine grid's approximate and
    extrapolated relative errors, and gci_fine, its grid convergence index (a relative uncertainty;
    None with the order where it is not defined)."""
    phi, counts = _checked_grids(values, cells, dimension)
    h = [count ** (-1.0 / dimension) for count in counts]
    r21, r32 = h[1] / h[0], h[2] / h[1]
    e21, e32 = phi[1] - phi[0], phi[2] - phi[1]
    result = dict(cells=counts, values=phi, h=h, r21=r21, r32=r32, order=None, extrapolated=None,
                  relative_error=abs(e21 / phi[0]) if phi[0] != 0 else None, extrapolated_error=None, gci_fine=None)
    if e21 == 0.0:
        result["convergence"] = "none"
        return result
    if e32 == 0.0:
        result["convergence"] = "divergent"  # the finer pair differs where the coarser agreed
        return result
    sign = 1.0 if e32 / e21 > 0 else -1.0
    result["convergence"] = "monotone" if sign > 0 else "oscillatory"
    # The order solves p ln r21 = ln |e32 / e21| + q(p). Celik et al. take the absolute value of the
    # right-hand side, which gives a positive order to values whose differences grow as the grid is
    # refined; here such values are 'divergent' and get no order.
    log_ratio, log_r21 = math.log(abs(e32 / e21)), math.log(r21)
    order = log_ratio / log_r21
    for _ in range(ORDER_ITERATIONS):
        if not order > 0.0:
            break
        shift = math.log((r21 ** order - sign) / (r32 ** order - sign))
        updated = (log_ratio + shift) / log_r21
        settled = abs(updated - order) < ORDER_TOLERANCE * max(1.0, abs(order))
        order = updated
        if settled:
            break
    else:
        raise ValueError("the observed order does not settle for values {} (r21 {:.4g}, r32 {:.4g})".format(
            phi, r21, r32))
    if not (order > 0.0 and math.isfinite(order)):
        if sign > 0:
            result["convergence"] = "divergent"
        return result
    gain = r21 ** order
    extrapolated = (gain * phi[0] - phi[1]) / (gain - 1.0)
    result.update(order=order, extrapolated=extrapolated,
                  extrapolated_error=abs((extrapolated - phi[0]) / extrapolated) if extrapolated != 0 else None,
                  gci_fine=SAFETY_FACTOR * abs(e21 / phi[0]) / (gain - 1.0) if phi[0] != 0 else None)
    return result


def read_summary(report_directory):
    """The summary.json that openfoam_post.write_report left in report_directory."""
    path = os.path.join(report_directory, "summary.json")
    try:
        with open(path) as file:
            summary = json.load(file)
    except OSError as error:
        raise ValueError("cannot read the run's summary {}: {}".format(path, error.strerror)) from None
    except json.JSONDecodeError as error:
        raise ValueError("{} is not a run summary (JSON): {}".format(path, error)) from None
    for key in ("cells",) + QUANTITIES:
        if not isinstance(summary, dict) or summary.get(key) is None:
            raise ValueError("{} has no {} (write it with openfoam-case --report)".format(path, key))
    return summary


def study_reports(report_directories, quantities=QUANTITIES):
    """The study of each quantity over three runs' reports: {quantity: richardson(...)}."""
    summaries = [read_summary(directory) for directory in report_directories]
    cells = [int(summary["cells"]) for summary in summaries]
    return {name: richardson([float(summary[name]) for summary in summaries], cells) for name in quantities}


def table(studies):
    """Markdown lines of the studies: one row per quantity."""
    def number(value, digits=5):
        return "-" if value is None else "{:.{}g}".format(value, digits)

    def percent(value):
        return "-" if value is None else "{:.2f} %".format(100.0 * value)

    first = next(iter(studies.values()))
    lines = ["Grids (finest first): {} cells; refinement ratios r21 = {:.3f}, r32 = {:.3f}.".format(
        " / ".join(str(c) for c in first["cells"]), first["r21"], first["r32"]), "",
        "| quantity | fine / medium / coarse | convergence | observed order | extrapolated | GCI fine |",
        "|---|---|---|---|---|---|"]
    for name, study in studies.items():
        lines.append("| {} | {} | {} | {} | {} | {} |".format(
            name, " / ".join(number(v) for v in study["values"]), study["convergence"], number(study["order"], 3),
            number(study["extrapolated"]), percent(study["gci_fine"])))
    return lines

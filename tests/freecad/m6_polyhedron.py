"""A coarse hand-made control polyhedron for the ONERA M6 half wing, built from sections of the
CAD: 3 spanwise stations of 8 chordwise points (trailing edge, 3 upper, leading edge, 3 lower),
the root ring on y = 0 (open: the root is the symmetry plane), a tip cap over 3 extra points on
the tip's rim. The trailing-edge edges along the span are creases. Tests use it until templates
exist; it is deliberately rough so that the fit has real work to do."""

import FreeCAD

ROOT_FACE = "Face9"  # the root plane, on the symmetry plane y = 0
STATIONS = (0.0, 0.5, 0.995)  # of the straight part of the span (up to the tip cap)
UPPER_CHORD = (0.75, 0.35, 0.08)
TIP_CHORD = (0.75, 0.35, 0.08)


def _section_points(shape, y):
    points = []
    for wire in shape.slice(FreeCAD.Vector(0, 1, 0), y):
        points.extend(wire.discretize(Number=400))
    return points


def _on_side(points, x, upper):
    side = [p for p in points if (p.z >= 0.0) == upper]
    return min(side, key=lambda p: abs(p.x - x))


def _ring(shape, y, y_vertex):
    points = _section_points(shape, y)
    te = max(points, key=lambda p: p.x)
    le = min(points, key=lambda p: p.x)
    chord = te.x - le.x
    upper = [_on_side(points, le.x + f * chord, True) for f in UPPER_CHORD]
    lower = [_on_side(points, le.x + f * chord, False) for f in reversed(UPPER_CHORD)]
    ring = [te] + upper + [le] + lower
    return [(p.x, y_vertex, p.z) for p in ring]


def wing_polyhedron(wing_shape):
    """(vertices, faces, creases) of the coarse polyhedron for the M6 wing shape (all 11 faces;
    the sections are taken on the wing's faces)."""
    box = wing_shape.BoundBox
    # The straight wing ends where the tip cap starts: the root-to-tip extent of the big faces.
    span = max(f.BoundBox.YMax for f in wing_shape.Faces if f.Area > 1e5)
    vertices = []
    for s in STATIONS:
        y = s * span
        vertices.extend(_ring(wing_shape, max(y, 1e-3 * span), y))
    n = 8
    faces = []
    for station in range(len(STATIONS) - 1):
        a, b = station * n, (station + 1) * n
        for i in range(n):
            j = (i + 1) % n
            faces.append([a + i, a + j, b + j, b + i])
    # Tip cap: three points on the tip's rim (z = 0, at the outermost y) between the last ring's
    # upper and lower points.
    tip = (len(STATIONS) - 1) * n
    tip_y = box.YMax
    le_x = vertices[tip + 4][0]
    te_x = vertices[tip][0]
    rim = len(vertices)
    for f in TIP_CHORD:
        vertices.append((le_x + f * (te_x - le_x), tip_y, 0.0))
    t, u1, u2, u3, le, d3, d2, d1 = (tip + k for k in range(8))
    m1, m2, m3 = rim, rim + 1, rim + 2
    faces += [
        [t, u1, m1], [u1, u2, m2, m1], [u2, u3, m3, m2], [u3, le, m3],
        [le, d3, m3], [d3, d2, m2, m3], [d2, d1, m1, m2], [d1, t, m1],
    ]
    creases = [[s * n, (s + 1) * n] for s in range(len(STATIONS) - 1)]
    return [list(map(float, v)) for v in vertices], faces, creases

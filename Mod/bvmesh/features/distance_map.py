"""The distance map: the limit surface of a surface fit, tessellated (SamplesPerFace x
SamplesPerFace quads per ptex face, split into triangles) and coloured per vertex by its distance
to the target. A Mesh feature, so FreeCAD's mesh view shows the colours (VertexColors)."""

import numpy as np

from bvmesh.features.common import READ_ONLY, Proxy, add_property

TYPE = "BVMesh::DistanceMap"

# Colour ramp from 0 (blue) to ColorMax and above (red).
RAMP = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [0.0, 0.8, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0]])


def ramp_colors(values, top):
    """(n, 3) RGB of the ramp for values in [0, top] (clipped)."""
    t = np.clip(np.asarray(values, dtype=float) / top, 0.0, 1.0) if top > 0 else np.zeros(len(values))
    stops = np.linspace(0.0, 1.0, len(RAMP))
    return np.stack([np.interp(t, stops, RAMP[:, c]) for c in range(3)], axis=1)


def limit_triangles(mesh, samples_per_face):
    """Triangles (list of 3-point lists) of the limit surface of a bvmesh.ControlMesh."""
    from bvmesh import load_core

    n = max(1, int(samples_per_face))
    evaluator = load_core().LimitEvaluator(mesh)
    ticks = np.linspace(0.0, 1.0, n + 1)
    us, vs = np.meshgrid(ticks, ticks, indexing="ij")
    faces = np.repeat(np.arange(evaluator.num_ptex_faces), us.size)
    u = np.tile(us.ravel(), evaluator.num_ptex_faces)
    v = np.tile(vs.ravel(), evaluator.num_ptex_faces)
    positions = evaluator.evaluate(mesh.vertices, faces, u, v)[0]
    grid = positions.reshape(evaluator.num_ptex_faces, n + 1, n + 1, 3)
    triangles = []
    for g in grid:
        for i in range(n):
            for j in range(n):
                a, b, c, d = g[i, j], g[i + 1, j], g[i + 1, j + 1], g[i, j + 1]
                triangles.append([tuple(a), tuple(b), tuple(c)])
                triangles.append([tuple(a), tuple(c), tuple(d)])
    return triangles


class DistanceMapProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        add_property(obj, "App::PropertyLink", "Fit", "Distance map", "The surface fit whose limit surface is shown")
        add_property(obj, "App::PropertyInteger", "SamplesPerFace", "Distance map",
                     "Tessellation: quads per ptex face and direction", 3)
        add_property(obj, "App::PropertyFloat", "ColorMax", "Distance map",
                     "Distance shown in red (model units); 0: the 99th percentile of the distances, so "
                     "that a few outliers do not paint the rest blue", 0.0)
        add_property(obj, "App::PropertyColorList", "VertexColors", "Result",
                     "Colour of each mesh point by its distance", mode=READ_ONLY)
        add_property(obj, "App::PropertyFloatList", "Distances", "Result",
                     "Distance of each mesh point to the target", mode=READ_ONLY)
        add_property(obj, "App::PropertyFloat", "MaxDistance", "Result", "Largest distance", mode=READ_ONLY)
        add_property(obj, "App::PropertyFloat", "RmsDistance", "Result", "RMS distance", mode=READ_ONLY)
        add_property(obj, "App::PropertyFloat", "LegendMax", "Result",
                     "Distance at the red end of the legend", mode=READ_ONLY)

    def compute(self, obj):
        import Mesh

        from bvmesh.features import surface_fit

        fit = obj.Fit
        if fit is None or not fit.ControlVertices:
            raise ValueError("the distance map needs a computed surface fit")
        triangles = limit_triangles(surface_fit.result_mesh(fit), obj.SamplesPerFace)
        mesh = Mesh.Mesh(triangles)
        points = np.array([(p.x, p.y, p.z) for p in mesh.Topology[0]])
        target = fit.Target.Proxy.core_target(fit.Target)
        distances = target.project(points)["distances"]
        top = obj.ColorMax if obj.ColorMax > 0 else float(np.percentile(distances, 99.0))
        obj.Mesh = mesh
        obj.Distances = [float(d) for d in distances]
        obj.MaxDistance = float(distances.max())
        obj.RmsDistance = float(np.sqrt(np.mean(distances ** 2)))
        obj.LegendMax = top
        obj.VertexColors = [tuple(map(float, c)) for c in ramp_colors(distances, top)]


def create(doc, name="DistanceMap"):
    obj = doc.addObject("Mesh::FeaturePython", name)
    DistanceMapProxy(obj)
    return obj

"""The control polyhedron: the coarse polygon mesh the fit starts from. Vertices, faces, crease
edges and corner vertices are properties; its Shape is the wireframe (Edge<i+1> is the mesh's
edge i, in the core's edge order), so edges and vertices can be picked to mark features.
A feature map (which target curves and vertices the features follow) is optional."""

import FreeCAD
import Part

from bvmesh.features.common import READ_ONLY, Proxy, add_property

TYPE = "BVMesh::ControlPolyhedron"


def flatten_faces(faces):
    """(sizes, flat indices) of a list of vertex-id lists."""
    faces = [[int(v) for v in face] for face in faces]
    return [len(face) for face in faces], [v for face in faces for v in face]


def unflatten_faces(sizes, indices):
    faces, start = [], 0
    for size in sizes:
        faces.append(list(indices[start:start + size]))
        start += size
    if start != len(indices):
        raise ValueError("face sizes add up to {} indices, but there are {}".format(start, len(indices)))
    return faces


def pairs(flat):
    if len(flat) % 2:
        raise ValueError("crease list must hold vertex pairs (even length), got {} numbers".format(len(flat)))
    return [[flat[i], flat[i + 1]] for i in range(0, len(flat), 2)]


def wireframe(vertices, edges):
    """Compound of one line per mesh edge, in edge order: Edge<i+1> is edge i."""
    points = [FreeCAD.Vector(*map(float, p)) for p in vertices]
    return Part.makeCompound([Part.LineSegment(points[a], points[b]).toShape() for a, b in edges])


def parse_feature_curves(lines):
    return [[int(e) for e in line.split()] for line in lines]


class PolyhedronProxy(Proxy):
    Type = TYPE

    def setup(self, obj):
        add_property(obj, "App::PropertyVectorList", "Vertices", "Polyhedron", "Vertex positions (#V)")
        add_property(obj, "App::PropertyIntegerList", "FaceSizes", "Polyhedron", "Vertex count of each face (#F)")
        add_property(obj, "App::PropertyIntegerList", "FaceIndices", "Polyhedron",
                     "Vertex ids of all faces, one after the other, counter-clockwise")
        add_property(obj, "App::PropertyIntegerList", "Creases", "Polyhedron",
                     "Crease edges as vertex-id pairs, flattened (a0 b0 a1 b1 ...)")
        add_property(obj, "App::PropertyIntegerList", "Corners", "Polyhedron", "Corner vertex ids")
        add_property(obj, "App::PropertyStringList", "FeatureCurves", "Feature map",
                     "Target edge chains the creases follow: target edge ids per line")
        add_property(obj, "App::PropertyIntegerList", "EdgeCurves", "Feature map",
                     "Per mesh edge: index into FeatureCurves, or -1 (empty: none)")
        add_property(obj, "App::PropertyIntegerList", "VertexCadVertices", "Feature map",
                     "Per mesh vertex: target vertex id it stays on, or -1 (empty: none)")
        add_property(obj, "App::PropertyFloat", "RootChord", "Template",
                     "Root chord of the wing a wing template was placed on, as the placement measured it (0: not "
                     "placed from a wing template); a VolumeMesh whose ReferenceLength is 0 takes it", 0.0,
                     mode=READ_ONLY)
        add_property(obj, "App::PropertyString", "Summary", "Result", "Counts of the polyhedron", mode=READ_ONLY)

    def compute(self, obj):
        mesh = control_mesh(obj)
        obj.Shape = wireframe(mesh.vertices, mesh.edges)
        obj.Summary = "{} vertices, {} faces, {} edges, {} creases, {} corners".format(
            mesh.num_vertices, mesh.num_faces, mesh.num_edges, len(mesh.creases), len(mesh.corners))


def control_mesh(obj):
    """The bvmesh.ControlMesh of a polyhedron object (the core validates it)."""
    from bvmesh import load_core

    vertices = [(v.x, v.y, v.z) for v in obj.Vertices]
    faces = unflatten_faces(obj.FaceSizes, obj.FaceIndices)
    return load_core().ControlMesh(vertices, faces, creases=pairs(obj.Creases) or None,
                                   corners=list(obj.Corners) or None)


def feature_map(obj):
    """The feature dict for bvmesh.SurfaceFitter, or None when the polyhedron has none."""
    if not (obj.FeatureCurves or obj.EdgeCurves or obj.VertexCadVertices):
        return None
    return {"curves": parse_feature_curves(obj.FeatureCurves), "edge_curve": list(obj.EdgeCurves),
            "vertex_cad_vertex": list(obj.VertexCadVertices)}


def create(doc, name="ControlPolyhedron"):
    obj = doc.addObject("Part::FeaturePython", name)
    PolyhedronProxy(obj)
    return obj


def edge_of_element(obj, element):
    """Mesh edge id of a picked sub-element name Edge<i> of the polyhedron's wireframe."""
    if not element.startswith("Edge"):
        raise ValueError("'{}' is not an edge".format(element))
    return int(element[4:]) - 1


def vertex_of_element(obj, element):
    """Mesh vertex id of a picked Vertex<i> of the wireframe (the vertex at the same point)."""
    point = obj.Shape.getElement(element).Point
    distances = [(v - point).Length for v in obj.Vertices]
    return distances.index(min(distances))

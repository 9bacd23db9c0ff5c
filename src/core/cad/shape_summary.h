// What a CAD shape holds: faces and their surface types, bounding box, and the edges classified
// by how many faces meet there and at which dihedral angle (sharp feature edges, free edges).
//
// Indexing follows TopExp::MapShapes order, 0-based, which is the order of FreeCAD's
// Shape.Faces / Shape.Edges: face i is FreeCAD's "Face<i+1>", edge j its "Edge<j+1>".
#pragma once

#include <TopoDS_Shape.hxx>

#include <array>
#include <string>
#include <vector>

namespace bvmesh::cad {

enum class EdgeKind {
  Smooth,       // two faces meet at a dihedral angle below the threshold
  Sharp,        // two faces meet at a dihedral angle at or above the threshold
  Free,         // one face only: an open boundary of the shape
  Seam,         // the same face on both sides (periodic surface seam)
  NonManifold,  // three or more faces
  Degenerate,   // no 3D extent (a collapsed edge, e.g. at a sphere pole)
};

struct EdgeInfo {
  EdgeKind kind = EdgeKind::Smooth;
  std::vector<int> faces;            // indices of the faces that share the edge
  double maxDihedralDegrees = 0.0;   // largest angle between the faces' normals along the edge
  double meanDihedralDegrees = 0.0;  // their mean over points spread evenly along the edge
  double length = 0.0;
};

struct ShapeSummaryOptions {
  double sharpAngleDegrees = 30.0;  // dihedral angles at or above this make a feature edge
  int samplesPerEdge = 7;           // points along each edge where the dihedral angle is measured
};

struct ShapeSummary {
  int solidCount = 0;
  int shellCount = 0;
  std::vector<std::string> faceSurfaceTypes;  // per face: "Plane", "BSplineSurface", ...
  std::vector<double> faceAreas;
  std::vector<int> faceWireCounts;  // per face: its outer boundary and one wire per hole
  std::vector<EdgeInfo> edges;
  int vertexCount = 0;
  std::array<double, 3> boundsMin{};
  std::array<double, 3> boundsMax{};

  int faceCount() const { return static_cast<int>(faceSurfaceTypes.size()); }
  int countEdges(EdgeKind kind) const;
  int countFacesOfType(const std::string& surfaceType) const;
  // The faces' surface as a cell complex: vertices - edges + the faces' own characteristics, each
  // face a planar region bounded by its wires (2 - wires; a periodic face cut open along its
  // seams is a disk), degenerate edges (a sphere's poles) being points. A closed connected
  // surface of genus g (g holes through the body) has 2 - 2g.
  int eulerCharacteristic() const;
};

// Throws InvalidInputError for a null shape.
ShapeSummary summarizeShape(const TopoDS_Shape& shape, const ShapeSummaryOptions& options = {});

// The OCCT surface type of a face as a short name ("Plane", "Cylinder", "BSplineSurface", ...).
std::string surfaceTypeName(int geomAbsSurfaceType);

const char* edgeKindName(EdgeKind kind);

}  // namespace bvmesh::cad

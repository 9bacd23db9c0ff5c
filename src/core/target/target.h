// The CAD target of the fitting iteration: the faces of a shape (any OCCT surface, trimmed),
// its edges (with the dihedral angle between their faces, free boundary edges) and vertices,
// and a spatial index over a tessellation. Projects many points at once onto the trimmed
// surface, onto chains of edges, onto vertices, or along given directions (iteration step 3).
//
// Unit-agnostic: every tolerance is relative to the diagonal of the shape's bounding box.
// Thread-safe for concurrent const calls; each projection call runs on several threads.
#pragma once

#include <TopoDS_Shape.hxx>

#include <Eigen/Core>

#include "core/cad/shape_repair.h"
#include "core/cad/shape_summary.h"
#include "core/common/types.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace bvmesh::target {

using Points = RowMatrixX3d;
using Params = RowMatrixX2d;

// The finest relative deflection a Target takes (a sphere's tessellation there: 1.3 GB).
constexpr double kFinestRelativeDeflection = 1e-5;

struct TargetOptions {
  // Chordal deflection of the tessellation behind the spatial index, relative to the diagonal, at
  // least kFinestRelativeDeflection. Finer means fewer candidate faces per point and more memory;
  // results do not depend on it.
  double relativeDeflection = 3e-4;
  // Angular deflection of the tessellation (radians).
  double angularDeflection = 0.5;
  // Gaps between faces wider than this (relative to the diagonal) are reported.
  double relativeTolerance = 1e-6;
  // Edges whose faces meet at a normal angle of at least this are reported as sharp (degrees).
  double sharpAngleDeg = 30.0;
  // Gaps are searched up to this width (relative to the diagonal).
  double relativeGapSearch = 1e-2;
  // Worker threads for projections; 0 = one per hardware thread.
  int threads = 0;
};

// A free edge whose nearest free edge of another face is closer than the gap search width but
// farther than the tolerance: the faces should meet there but do not.
struct GapReport {
  int edge = 0;
  int otherEdge = 0;
  double width = 0.0;  // max distance from the edge's samples to the other edge
};

// What the target holds: the shape summary (faces, surface types, edges with their kind and
// dihedral angle, bounds; shared with the shape report) and what the target adds to it.
struct TargetReport {
  cad::ShapeSummary shape;
  int triangleCount = 0;
  double diagonal = 0.0;    // bounding-box diagonal: the model size all tolerances scale with
  double tolerance = 0.0;   // absolute gap tolerance
  double deflection = 0.0;  // absolute tessellation deflection
  std::vector<int> sharpEdges;          // edges between two faces at a dihedral angle >= sharpAngleDeg
  std::vector<int> freeEdges;           // edges of one face only (not seams)
  std::vector<int> nonManifoldEdges;    // edges of three or more faces
  std::vector<int> untessellatedFaces;  // faces BRepMesh could not mesh: not found by cold starts
  std::vector<GapReport> gaps;
  cad::RepairReport repair;  // what reading did to the shape (sewing, gaps, watertightness)
};

enum class ProjectionStatus : std::uint8_t {
  Ok = 0,              // closest point inside a face (or on the requested curve / vertex)
  OnTrimBoundary = 1,  // closest point on a face's trim boundary
  Fallback = 2,        // the requested kind of projection failed; closest point on the surface instead
  Failed = 3,          // nothing found; foot point = input point, distance = -1
};

// Results for #P points. Unit normals follow the faces' orientation (outward for a solid).
struct ProjectionResult {
  Points points;                          // #P x 3 foot points
  Eigen::VectorXd distances;              // #P distances from the input points to the foot points
  Eigen::VectorXi ids;                    // #P face ids (surface), edge ids (curves) or vertex ids; -1 if failed
  Eigen::VectorXi faces;                  // #P face the (u, v) belong to; -1 if none
  Params params;                          // #P x 2: (u, v) on faces(i); curves: (t, 0) on edge ids(i)
  Points normals;                         // #P x 3 surface normal of faces(i) at the foot point; 0 if none
  std::vector<ProjectionStatus> status;   // #P

  void resize(Eigen::Index count);
  // Row i takes every field of row k of `from`.
  void setRow(Eigen::Index i, const ProjectionResult& from, Eigen::Index k);
};

// Previous per-point locations on the surface, for warm starts: faces #P (-1 = no hint),
// uv #P x 2.
struct SurfaceHints {
  Eigen::VectorXi faces;
  Params uv;
};

// Points on the CAD surface (Target::surfaceSamples) with how precisely the CAD itself places
// each: the CAD's tolerance there (see Target::meshNodeTolerances).
struct SurfaceSamples {
  Points points;              // #P x 3
  Eigen::VectorXd tolerances;  // #P
};

class Target {
public:
  // Throws InvalidInputError for a null shape and TopologyError for a shape without faces.
  explicit Target(const TopoDS_Shape& shape, const TargetOptions& options = {});
  // A shape as read and repaired (cad::readShapeFileRepaired): its repair report goes into report().
  explicit Target(const cad::RepairedShape& shape, const TargetOptions& options = {});
  ~Target();
  Target(Target&&) noexcept;
  Target& operator=(Target&&) noexcept;
  Target(const Target&) = delete;
  Target& operator=(const Target&) = delete;

  const TargetReport& report() const;
  const TargetOptions& options() const;
  int faceCount() const;
  int edgeCount() const;
  int vertexCount() const;

  // Edges between two faces whose normals meet at an angle of at least angleDeg.
  std::vector<int> sharpEdges(double angleDeg) const;
  std::vector<int> freeEdges() const;
  Eigen::Vector3d vertexPosition(int vertex) const;
  // The two end vertices of an edge (-1 where OCCT gives none); the edge runs from the first to
  // the second (closed edges name the same vertex twice).
  std::array<int, 2> edgeVertices(int edge) const;
  // OCCT's tolerance of an edge: how far its faces and its curve may be apart along it.
  double edgeTolerance(int edge) const;
  // #K x 3 points along an edge from its first to its second vertex, within the tessellation
  // deflection of the curve; empty for degenerate edges.
  Points edgePolyline(int edge) const;

  // Closest points on the trimmed surface. points: #P x 3. hints (optional): previous
  // locations for a warm start; results equal those without hints.
  ProjectionResult project(const Eigen::Ref<const Points>& points, const SurfaceHints* hints = nullptr) const;
  // Closest points on the union of the given edges (a crease chain or a boundary curve).
  ProjectionResult projectToEdges(const Eigen::Ref<const Points>& points, const std::vector<int>& edges) const;
  // Closest points on the free boundary edges (empty shells have none: all points fail).
  ProjectionResult projectToFreeBoundary(const Eigen::Ref<const Points>& points) const;
  // Nearest of the given vertices.
  ProjectionResult projectToVertices(const Eigen::Ref<const Points>& points, const std::vector<int>& vertices) const;
  // Nearest intersection of the line p + s d (s of either sign) with the trimmed surface.
  // directions: #P x 3 (need not be unit). Points whose line misses get the closest point
  // with status Fallback.
  ProjectionResult projectAlong(const Eigen::Ref<const Points>& points, const Eigen::Ref<const Points>& directions) const;

  // Triangles of the index: #T x 3 node ids into nodes (#N x 3) and the face of each triangle.
  const Points& meshNodes() const;
  // #N: how precisely the CAD itself places each node: the largest OCCT tolerance of the edges
  // and vertices the node lies on (where neighbouring faces may be that far apart), else its face's.
  const Eigen::VectorXd& meshNodeTolerances() const;
  // Points on the trimmed CAD surface `subdivisions` times denser along each side of the
  // tessellation's triangles: the lattice points (i, j) / subdivisions of every triangle (the
  // tessellation's own nodes for 1), located in the face's (u, v) domain by the triangle's node
  // parameters and evaluated exactly on the face's surface; each point once (the nodes first, in
  // their order, then the points inside the triangles' edges, then inside the triangles).
  // k subdivisions give about k^2 times the nodes. Tolerance of a point: the smallest of the
  // CAD's tolerances at the nodes it lies between (an edge's on a CAD edge, else the face's).
  SurfaceSamples surfaceSamples(int subdivisions) const;
  const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>& meshTriangles() const;
  const Eigen::VectorXi& meshTriangleFaces() const;

  struct Data;

private:
  std::unique_ptr<Data> data_;
};

}  // namespace bvmesh::target

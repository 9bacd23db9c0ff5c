// Splitting an all-quad Catmull-Clark control mesh into rectangular charts along the
// separatrices of its extraordinary vertices, its creases and its boundaries. A chart is an
// m x n grid of quads; its limit surface becomes one B-spline surface, and later one block face
// of the volume mesh.
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

#include "core/mesh/control_mesh.h"

namespace bvmesh::surface {

using RowMatrixX4i = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;

// An all-quad control mesh as plain arrays (see limit_points.h for the conversions from and to
// ControlMesh). Crease edges and corners are infinitely sharp; boundary edges behave like creases
// (OpenSubdiv VTX_BOUNDARY_EDGE_AND_CORNER).
struct QuadControlMesh {
  RowMatrixX3d vertices;     // #V x 3 vertex positions
  RowMatrixX4i faces;        // #F x 4 vertex ids, counter-clockwise seen from the front side
  RowMatrixX2i creases;      // #C x 2 vertex pairs, each a mesh edge
  std::vector<int> corners;  // vertex ids of sharp corners
};

// A quad control mesh from point, quad and crease lists (not validated).
QuadControlMesh makeQuadControlMesh(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<std::array<int, 4>>& quads,
                                    const std::vector<std::array<int, 2>>& creases = {});

// Checks finite coordinates, index ranges, quads with four distinct vertices, manifold edges with
// consistent orientation, and creases that are edges. Throws InvalidInputError / TopologyError
// naming the offending element.
void validateQuadControlMesh(const QuadControlMesh& mesh);

// Sides of a chart, in its (u, v) parameter grid. Positions along a side count vertices from the
// side's low-parameter end: VMin and VMax run along u, UMin and UMax along v.
enum class ChartSide { VMin = 0, UMax = 1, VMax = 2, UMin = 3 };

// One use of a border segment by a chart side: segment vertex k sits at side position
// `first + k` (or `first - k` when reversed).
struct SegmentUse {
  int chart = -1;
  ChartSide side = ChartSide::VMin;
  int first = 0;
  bool reversed = false;
};

enum class BorderKind { Boundary, Crease, Separatrix };

// A run of border edges between two nodes (chart corners). Shared by the one or two chart sides
// that contain it; both see the same vertex chain.
struct BorderSegment {
  std::vector<int> vertices;  // chain of #edges + 1 vertex ids, from one node to the other
  BorderKind kind = BorderKind::Separatrix;
  std::vector<SegmentUse> uses;  // 1 (boundary) or 2 entries
};

// A maximal chain of segments joined at nodes that some chart side passes straight through (no
// corner there). Such a side needs a simple knot at the node, so the whole chain is fitted as one
// curve; sides and segments get restrictions of it. A chain that would close on itself is broken
// by an extra cut during the layout, so every line has two clamped ends (possibly the same node).
struct BorderLine {
  std::vector<int> segments;   // in order along the line
  std::vector<bool> reversed;  // segment k runs against the line's direction
};

// A rectangular chart: cell (i, j), 0 <= i < uCells, 0 <= j < vCells, is one mesh face; its
// corners (i, j), (i+1, j), (i+1, j+1), (i, j+1) run counter-clockwise like the face's vertices,
// so the chart's normal agrees with the mesh orientation.
struct QuadChart {
  int uCells = 0;                                // m
  int vCells = 0;                                // n
  std::vector<int> faces;                        // m x n face ids, cell (i, j) at i * n + j
  std::vector<int> rotations;                    // m x n: cell corner k is face vertex (k + rotation) % 4
  std::vector<int> vertices;                     // (m + 1) x (n + 1) vertex ids, (i, j) at i * (n + 1) + j
  std::array<std::vector<int>, 4> sideSegments;  // per ChartSide, segment ids by increasing position

  int face(int i, int j) const { return faces[static_cast<size_t>(i * vCells + j)]; }
  int rotation(int i, int j) const { return rotations[static_cast<size_t>(i * vCells + j)]; }
  int vertex(int i, int j) const { return vertices[static_cast<size_t>(i * (vCells + 1) + j)]; }
  int sideLength(ChartSide side) const;
  // Mesh vertex at a position along a side.
  int sideVertex(ChartSide side, int position) const;
};

struct ChartLayout {
  std::vector<QuadChart> charts;
  std::vector<BorderSegment> segments;
  std::vector<BorderLine> lines;
  std::vector<int> nodes;      // vertex ids that are a corner of some chart, increasing
  std::vector<int> faceChart;  // #F: chart of each face
  std::vector<int> junctions;  // extraordinary / irregular crease / corner vertices, increasing
  // Corners, increasing: tagged corners and vertices on three or more sharp edges. The limit
  // surface has a cone point there, no tangent plane.
  std::vector<int> corners;
};

// Builds the charts. Throws TopologyError when a component cannot be made rectangular.
ChartLayout buildChartLayout(const QuadControlMesh& mesh);

}  // namespace bvmesh::surface

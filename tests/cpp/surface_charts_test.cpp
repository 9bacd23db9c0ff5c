#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "core/common/errors.h"
#include "core/surface/quad_charts.h"
#include "surface_test_meshes.h"

namespace bvmesh::surface {
namespace {

using testing::cube;
using testing::cubeWithCreasedEquator;
using testing::grid;
using testing::subdivide;

double flat(double, double) { return 0.0; }

// Checks what every layout must satisfy, from the mesh arrays alone: each face in exactly one
// chart, cells that are the faces with matching corners, segments that run along the chart sides
// they claim, sides tiled by their segments, and mesh boundary edges exactly on boundary segments.
void expectConsistentLayout(const QuadControlMesh& mesh, const ChartLayout& layout) {
  const Eigen::Index faceCount = mesh.faces.rows();
  std::vector<int> seen(static_cast<size_t>(faceCount), 0);
  const int di[4] = {0, 1, 1, 0};
  const int dj[4] = {0, 0, 1, 1};
  for (size_t c = 0; c < layout.charts.size(); ++c) {
    const QuadChart& chart = layout.charts[c];
    for (int i = 0; i < chart.uCells; ++i) {
      for (int j = 0; j < chart.vCells; ++j) {
        const int f = chart.face(i, j);
        ++seen[static_cast<size_t>(f)];
        EXPECT_EQ(layout.faceChart[static_cast<size_t>(f)], static_cast<int>(c));
        for (int k = 0; k < 4; ++k) {
          EXPECT_EQ(chart.vertex(i + di[k], j + dj[k]), mesh.faces(f, (k + chart.rotation(i, j)) % 4))
              << "chart " << c << " cell " << i << "," << j;
        }
      }
    }
  }
  for (Eigen::Index f = 0; f < faceCount; ++f) EXPECT_EQ(seen[static_cast<size_t>(f)], 1) << "face " << f;

  // Undirected edges with their face count, to recognise boundary edges.
  std::map<std::pair<int, int>, int> edgeFaces;
  for (Eigen::Index f = 0; f < faceCount; ++f) {
    for (int k = 0; k < 4; ++k) {
      const int a = mesh.faces(f, k);
      const int b = mesh.faces(f, (k + 1) % 4);
      ++edgeFaces[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::set<std::pair<int, int>> boundarySegmentEdges;
  for (size_t s = 0; s < layout.segments.size(); ++s) {
    const BorderSegment& segment = layout.segments[s];
    const int length = static_cast<int>(segment.vertices.size()) - 1;
    ASSERT_GE(length, 1);
    EXPECT_EQ(segment.uses.size(), segment.kind == BorderKind::Boundary ? 1u : 2u) << "segment " << s;
    for (const SegmentUse& use : segment.uses) {
      const QuadChart& chart = layout.charts[static_cast<size_t>(use.chart)];
      for (int k = 0; k <= length; ++k) {
        EXPECT_EQ(chart.sideVertex(use.side, use.reversed ? use.first - k : use.first + k),
                  segment.vertices[static_cast<size_t>(k)]);
      }
    }
    for (int k = 0; k < length; ++k) {
      const int a = segment.vertices[static_cast<size_t>(k)];
      const int b = segment.vertices[static_cast<size_t>(k + 1)];
      const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      EXPECT_EQ(edgeFaces.at(key) == 1, segment.kind == BorderKind::Boundary);
      if (segment.kind == BorderKind::Boundary) boundarySegmentEdges.insert(key);
    }
  }
  for (const auto& [edge, count] : edgeFaces) {
    if (count == 1) {
      EXPECT_TRUE(boundarySegmentEdges.count(edge)) << "boundary edge not on a boundary segment";
    }
  }
  for (size_t c = 0; c < layout.charts.size(); ++c) {
    const QuadChart& chart = layout.charts[c];
    for (int s = 0; s < 4; ++s) {
      const auto side = static_cast<ChartSide>(s);
      int position = 0;
      for (int segment : chart.sideSegments[static_cast<size_t>(s)]) {
        const BorderSegment& seg = layout.segments[static_cast<size_t>(segment)];
        const int length = static_cast<int>(seg.vertices.size()) - 1;
        const bool found = std::any_of(seg.uses.begin(), seg.uses.end(), [&](const SegmentUse& use) {
          return use.chart == static_cast<int>(c) && use.side == side &&
                 use.first == (use.reversed ? position + length : position);
        });
        EXPECT_TRUE(found) << "chart " << c << " side " << s << " segment " << segment;
        position += length;
      }
      EXPECT_EQ(position, chart.sideLength(side)) << "chart " << c << " side " << s;
    }
  }
  // Every segment belongs to exactly one line.
  std::vector<int> inLine(layout.segments.size(), 0);
  for (const BorderLine& line : layout.lines) {
    for (int s : line.segments) ++inLine[static_cast<size_t>(s)];
  }
  for (size_t s = 0; s < inLine.size(); ++s) EXPECT_EQ(inLine[s], 1) << "segment " << s;
}

std::multiset<std::pair<int, int>> chartSizes(const ChartLayout& layout) {
  std::multiset<std::pair<int, int>> sizes;
  for (const QuadChart& chart : layout.charts) {
    sizes.insert({std::min(chart.uCells, chart.vCells), std::max(chart.uCells, chart.vCells)});
  }
  return sizes;
}

TEST(SurfaceCharts, RegularGridIsOneChart) {
  const QuadControlMesh mesh = grid(5, 3, flat);
  const ChartLayout layout = buildChartLayout(mesh);
  expectConsistentLayout(mesh, layout);
  ASSERT_EQ(layout.charts.size(), 1u);
  EXPECT_EQ(layout.charts[0].uCells, 5);
  EXPECT_EQ(layout.charts[0].vCells, 3);
  // The four grid corners (one face each) are the only junctions and nodes; one segment per side.
  EXPECT_EQ(layout.junctions, (std::vector<int>{0, 3, 20, 23}));
  EXPECT_EQ(layout.nodes, layout.junctions);
  EXPECT_EQ(layout.segments.size(), 4u);
}

TEST(SurfaceCharts, LShapeSplitsAtTheConcaveCorner) {
  // 4 x 4 grid without its top-right 2 x 2 block: the concave boundary vertex (2, 2) has three
  // faces, its two interior edges continue as separatrices to the boundary: three 2 x 2 charts.
  const QuadControlMesh mesh = grid(4, 4, flat, [](int i, int j) { return i < 2 || j < 2; });
  const ChartLayout layout = buildChartLayout(mesh);
  expectConsistentLayout(mesh, layout);
  EXPECT_EQ(chartSizes(layout), (std::multiset<std::pair<int, int>>{{2, 2}, {2, 2}, {2, 2}}));
  EXPECT_EQ(layout.junctions.size(), 6u);  // five convex corners + the concave one
  // Boundary: 6 sides of the L, split at the two separatrix ends: 8 boundary segments; 2 inner.
  int boundary = 0;
  for (const BorderSegment& segment : layout.segments)
    boundary += segment.kind == BorderKind::Boundary ? 1 : 0;
  EXPECT_EQ(boundary, 8);
  EXPECT_EQ(layout.segments.size(), 10u);
}

TEST(SurfaceCharts, SubdividedCubeGivesOneChartPerCubeFace) {
  // After one step the 8 cube corners are the only extraordinary vertices (valence 3). Their
  // separatrices run along the cube edges through the regular edge midpoints into the next
  // corner, so the borders are exactly the 12 cube edges: 6 charts of 2 x 2 quads, 12 segments.
  for (int levels : {1, 2}) {
    const QuadControlMesh mesh = subdivide(cube(), levels);
    const ChartLayout layout = buildChartLayout(mesh);
    expectConsistentLayout(mesh, layout);
    const int n = 1 << levels;
    EXPECT_EQ(chartSizes(layout),
              (std::multiset<std::pair<int, int>>({{n, n}, {n, n}, {n, n}, {n, n}, {n, n}, {n, n}})));
    EXPECT_EQ(layout.junctions.size(), 8u);
    EXPECT_EQ(layout.nodes.size(), 8u);
    EXPECT_EQ(layout.segments.size(), 12u);
    for (const BorderSegment& segment : layout.segments) {
      EXPECT_EQ(segment.kind, BorderKind::Separatrix);
      EXPECT_NE(segment.uses[0].chart, segment.uses[1].chart);
    }
  }
}

TEST(SurfaceCharts, CreasedEquatorSplitsTheSideFaces) {
  // The crease loop through the side-face centres stops the vertical separatrices at the edge
  // midpoints: top and bottom stay 2 x 2, each side face becomes two 2 x 1 charts.
  const QuadControlMesh mesh = cubeWithCreasedEquator();
  ASSERT_EQ(mesh.creases.rows(), 8);
  const ChartLayout layout = buildChartLayout(mesh);
  expectConsistentLayout(mesh, layout);
  std::multiset<std::pair<int, int>> expected{{2, 2}, {2, 2}};
  for (int k = 0; k < 8; ++k) expected.insert({1, 2});
  EXPECT_EQ(chartSizes(layout), expected);
  int crease = 0;
  for (const BorderSegment& segment : layout.segments) crease += segment.kind == BorderKind::Crease ? 1 : 0;
  EXPECT_EQ(crease, 4);  // the loop between the four edge-midpoint nodes
}

TEST(SurfaceCharts, CreaseDartsEmitSeparatrices) {
  // A crease from (2, 1) to (2, 3) inside a 4 x 4 grid: both ends are darts (one crease edge),
  // whose other edges continue as separatrices to the boundary. Columns x < 2, x > 2 times rows
  // y < 1, 1 < y < 3, y > 3: six charts.
  QuadControlMesh mesh = grid(4, 4, flat);
  mesh.creases.resize(2, 2);
  mesh.creases << 2 * 5 + 1, 2 * 5 + 2, 2 * 5 + 2, 2 * 5 + 3;
  const ChartLayout layout = buildChartLayout(mesh);
  expectConsistentLayout(mesh, layout);
  EXPECT_EQ(chartSizes(layout),
            (std::multiset<std::pair<int, int>>{{1, 2}, {1, 2}, {1, 2}, {1, 2}, {2, 2}, {2, 2}}));
}

TEST(SurfaceCharts, CreaseAcrossAGridEndsAtTheBoundary) {
  QuadControlMesh mesh = grid(4, 3, flat);
  mesh.creases.resize(3, 2);
  mesh.creases << 2 * 4 + 0, 2 * 4 + 1, 2 * 4 + 1, 2 * 4 + 2, 2 * 4 + 2, 2 * 4 + 3;
  const ChartLayout layout = buildChartLayout(mesh);
  expectConsistentLayout(mesh, layout);
  EXPECT_EQ(chartSizes(layout), (std::multiset<std::pair<int, int>>{{2, 3}, {2, 3}}));
}

TEST(SurfaceCharts, TorusIsCutIntoOneChart) {
  // No extraordinary vertex and no boundary: the single component is cut open twice.
  const QuadControlMesh mesh = testing::torus(8, 6);
  const ChartLayout layout = buildChartLayout(mesh);
  expectConsistentLayout(mesh, layout);
  ASSERT_EQ(layout.charts.size(), 1u);
  EXPECT_EQ(layout.charts[0].uCells * layout.charts[0].vCells, 48);
  EXPECT_EQ(layout.nodes.size(), 1u);
  ASSERT_EQ(layout.segments.size(), 2u);
  for (const BorderSegment& segment : layout.segments) {
    ASSERT_EQ(segment.uses.size(), 2u);
    EXPECT_EQ(segment.uses[0].chart, segment.uses[1].chart);
    EXPECT_EQ(segment.vertices.front(), segment.vertices.back());
  }
}

TEST(SurfaceCharts, TubeIsCutAlongItsLength) {
  const QuadControlMesh mesh = testing::tube(8, 3);
  const ChartLayout layout = buildChartLayout(mesh);
  expectConsistentLayout(mesh, layout);
  ASSERT_EQ(layout.charts.size(), 1u);
  EXPECT_EQ(chartSizes(layout), (std::multiset<std::pair<int, int>>{{3, 8}}));
}

TEST(SurfaceCharts, ClosedChainOfPassedNodesIsBrokenByACut) {
  const QuadControlMesh mesh = testing::staggeredCreasedTube();
  const ChartLayout layout = buildChartLayout(mesh);
  expectConsistentLayout(mesh, layout);
  // Bands of 8 x 1 and 8 x 2 quads, each cut open; one of them is cut a second time where the
  // crease ring's chain of passed nodes has to end.
  EXPECT_EQ(layout.charts.size(), 3u);
  int ringLines = 0;
  for (const BorderLine& line : layout.lines) {
    const BorderSegment& first = layout.segments[static_cast<size_t>(line.segments.front())];
    if (first.kind != BorderKind::Crease) continue;
    ++ringLines;
    EXPECT_EQ(line.segments.size(), 2u);
  }
  EXPECT_EQ(ringLines, 1);
}

TEST(SurfaceCharts, RejectsBadMeshes) {
  QuadControlMesh mesh = grid(2, 2, flat);
  QuadControlMesh bad = mesh;
  bad.vertices(4, 1) = std::nan("");
  EXPECT_THROW(buildChartLayout(bad), InvalidInputError);
  bad = mesh;
  bad.faces(1, 2) = 99;
  try {
    buildChartLayout(bad);
    FAIL() << "no exception";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("face 1 refers to vertex 99"), std::string::npos)
        << error.what();
  }
  bad = mesh;
  bad.faces(0, 3) = bad.faces(0, 1);
  EXPECT_THROW(buildChartLayout(bad), TopologyError);
  bad = mesh;
  bad.faces.row(0) = bad.faces.row(0).reverse().eval();  // flipped face
  EXPECT_THROW(buildChartLayout(bad), TopologyError);
  bad = mesh;
  bad.creases.resize(1, 2);
  bad.creases << 0, 4;  // a diagonal, not an edge
  EXPECT_THROW(buildChartLayout(bad), TopologyError);
  bad = mesh;
  bad.corners = {-1};
  EXPECT_THROW(buildChartLayout(bad), InvalidInputError);
  // Three faces on the boundary edge (0, 3).
  bad = mesh;
  bad.vertices.conservativeResize(bad.vertices.rows() + 4, 3);
  bad.vertices.bottomRows(4) << 0, 0, 1, 1, 0, 1, 0, 0, -1, 1, 0, -1;
  bad.faces.conservativeResize(bad.faces.rows() + 2, 4);
  bad.faces.bottomRows(2) << 3, 0, 9, 10, 0, 3, 12, 11;
  try {
    buildChartLayout(bad);
    FAIL() << "no exception";
  } catch (const TopologyError& error) {
    EXPECT_NE(std::string(error.what()).find("more than two faces"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace bvmesh::surface

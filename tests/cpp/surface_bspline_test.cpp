#include <gtest/gtest.h>

#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <Geom_BSplineSurface.hxx>
#include <TopAbs_ShapeEnum.hxx>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <iostream>
#include <string>
#include <utility>

#include "core/cad/bspline_face.h"
#include "core/common/errors.h"
#include "core/surface/limit_bsplines.h"
#include "surface_test_meshes.h"

namespace bvmesh::surface {
namespace {

using testing::cube;
using testing::cubeWithCreasedEquator;
using testing::grid;
using testing::subdivide;

double modelSize(const QuadControlMesh& mesh) {
  return (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).norm();
}

// The shared limit evaluator on a quad mesh, as the conversion uses it.
struct Limit {
  explicit Limit(const QuadControlMesh& mesh)
      : controlMesh(toControlMesh(mesh)), evaluator(controlMesh, {}, 8) {}
  RowMatrixX3d points(const std::vector<SurfaceLocation>& locations) const {
    return evaluator.evaluate(controlMesh.vertices(), locations).positions;
  }
  ControlMesh controlMesh;
  LimitEvaluator evaluator;
};

double bump(double x, double y) {
  return 0.3 * std::sin(1.3 * x + 0.4) * std::cos(0.9 * y - 0.2) + 0.05 * x * y;
}

// Face location of chart parameters, from the documented cell convention alone: cell corner k is
// face vertex (k + rotation) % 4, and the face's corners sit at (0,0), (1,0), (1,1), (0,1).
SurfaceLocation locateInCell(const QuadChart& chart, int i, int j, double a, double b) {
  const double cu[4] = {0, 1, 1, 0};
  const double cv[4] = {0, 0, 1, 1};
  const double weight[4] = {(1 - a) * (1 - b), a * (1 - b), a * b, (1 - a) * b};
  SurfaceLocation location{chart.face(i, j), 0.0, 0.0};
  for (int k = 0; k < 4; ++k) {
    const int corner = (k + chart.rotation(i, j)) % 4;
    location.u += weight[k] * cu[corner];
    location.v += weight[k] * cv[corner];
  }
  return location;
}

SurfaceLocation locate(const QuadChart& chart, double s, double t) {
  const int i = std::min(static_cast<int>(s), chart.uCells - 1);
  const int j = std::min(static_cast<int>(t), chart.vCells - 1);
  return locateInCell(chart, i, j, s - i, t - j);
}

Eigen::Vector3d occtPoint(const Handle(Geom_BSplineSurface) & surface, double s, double t) {
  const gp_Pnt p = surface->Value(s, t);
  return {p.X(), p.Y(), p.Z()};
}

// The uniform cubic B-spline basis, written out.
void uniformBasis(double t, double b[4]) {
  b[0] = (1 - t) * (1 - t) * (1 - t) / 6;
  b[1] = (3 * t * t * t - 6 * t * t + 4) / 6;
  b[2] = (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6;
  b[3] = t * t * t / 6;
}

// Max distance between the OCCT B-spline surfaces and the limit surface on a grid of points per
// cell that differs from both the fit and the check sampling.
double maxDistanceToLimit(const LimitBSplines& result, const Limit& limit, int perCell) {
  double worst = 0.0;
  for (size_t c = 0; c < result.layout.charts.size(); ++c) {
    const QuadChart& chart = result.layout.charts[c];
    const Handle(Geom_BSplineSurface) surface = cad::makeBSplineSurface(result.surfaces[c]);
    std::vector<SurfaceLocation> locations;
    std::vector<Eigen::Vector3d> fitted;
    for (int a = 0; a <= chart.uCells * perCell; ++a) {
      for (int b = 0; b <= chart.vCells * perCell; ++b) {
        const double s = static_cast<double>(a) / perCell;
        const double t = static_cast<double>(b) / perCell;
        locations.push_back(locate(chart, s, t));
        fitted.push_back(occtPoint(surface, s, t));
      }
    }
    const RowMatrixX3d points = limit.points(locations);
    for (size_t k = 0; k < fitted.size(); ++k) {
      worst = std::max(worst, (points.row(static_cast<Eigen::Index>(k)).transpose() - fitted[k]).norm());
    }
  }
  return worst;
}

// Chart parameters of segment parameter y (in edges from the segment's vertex 0) on one use.
std::pair<double, double> useParameters(const LimitBSplines& result, const SegmentUse& use, double y) {
  const QuadChart& chart = result.layout.charts[static_cast<size_t>(use.chart)];
  const double position = use.reversed ? use.first - y : use.first + y;
  double s = position;
  double t = 0.0;
  if (use.side == ChartSide::UMax || use.side == ChartSide::UMin) std::swap(s, t);
  if (use.side == ChartSide::UMax) s = chart.uCells;
  if (use.side == ChartSide::VMax) t = chart.vCells;
  return {s, t};
}

// Max distance between the two OCCT surfaces along every shared border segment.
double maxSharedBorderDistance(const LimitBSplines& result) {
  double worst = 0.0;
  for (const BorderSegment& segment : result.layout.segments) {
    if (segment.uses.size() != 2) continue;
    const int length = static_cast<int>(segment.vertices.size()) - 1;
    for (int q = 0; q <= 10 * length; ++q) {
      const double y = q / 10.0;
      Eigen::Vector3d p[2];
      for (int k = 0; k < 2; ++k) {
        const SegmentUse& use = segment.uses[static_cast<size_t>(k)];
        const auto [s, t] = useParameters(result, use, y);
        p[k] = occtPoint(cad::makeBSplineSurface(result.surfaces[static_cast<size_t>(use.chart)]), s, t);
      }
      worst = std::max(worst, (p[0] - p[1]).norm());
    }
  }
  return worst;
}

// Max angle in degrees between the OCCT surfaces' normals along every shared smooth segment, at
// `perEdge` points per edge (not the conversion's check points).
double maxSmoothBorderNormalJump(const LimitBSplines& result, int perEdge) {
  double worst = 0.0;
  for (const BorderSegment& segment : result.layout.segments) {
    if (segment.uses.size() != 2 || segment.kind == BorderKind::Crease) continue;
    const int length = static_cast<int>(segment.vertices.size()) - 1;
    for (int q = 0; q <= perEdge * length; ++q) {
      const double y = static_cast<double>(q) / perEdge;
      gp_Vec normal[2];
      for (int k = 0; k < 2; ++k) {
        const SegmentUse& use = segment.uses[static_cast<size_t>(k)];
        const auto [s, t] = useParameters(result, use, y);
        gp_Pnt p;
        gp_Vec du;
        gp_Vec dv;
        cad::makeBSplineSurface(result.surfaces[static_cast<size_t>(use.chart)])->D1(s, t, p, du, dv);
        normal[k] = du.Crossed(dv);
      }
      worst = std::max(worst, normal[0].Angle(normal[1]) * 180.0 / std::acos(-1.0));
    }
  }
  return worst;
}

// Volume inside the limit surface: divergence theorem on a k x k triangulation per face,
// Richardson-extrapolated from k and 2k (the error of the triangulation falls like 1/k^2).
double limitVolume(const QuadControlMesh& mesh, const Limit& limit, int k) {
  auto triangulated = [&](int n) {
    std::vector<SurfaceLocation> locations;
    for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
      for (int a = 0; a <= n; ++a) {
        for (int b = 0; b <= n; ++b)
          locations.push_back({static_cast<int>(f), static_cast<double>(a) / n, static_cast<double>(b) / n});
      }
    }
    const RowMatrixX3d p = limit.points(locations);
    double volume = 0.0;
    const int stride = (n + 1) * (n + 1);
    for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
      auto at = [&](int a, int b) {
        return Eigen::Vector3d(p.row(static_cast<Eigen::Index>(f * stride + a * (n + 1) + b)).transpose());
      };
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
          const Eigen::Vector3d p00 = at(a, b), p10 = at(a + 1, b), p11 = at(a + 1, b + 1),
                                p01 = at(a, b + 1);
          volume += p00.dot(p10.cross(p11)) / 6 + p00.dot(p11.cross(p01)) / 6;
        }
      }
    }
    return volume;
  };
  const double coarse = triangulated(k);
  const double fine = triangulated(2 * k);
  return (4 * fine - coarse) / 3;
}

TEST(SurfaceBSplines, RegularGridsAreReproducedExactly) {
  for (bool curved : {false, true}) {
    const int nx = 6;
    const int ny = 5;
    const QuadControlMesh mesh = grid(
        nx, ny, curved ? bump : [](double, double) { return 0.0; });
    const double size = modelSize(mesh);
    const LimitBSplines result = limitSurfaceToBSplines(mesh);
    ASSERT_EQ(result.surfaces.size(), 1u);
    EXPECT_LT(result.maxDeviation[0], 1e-12 * size);
    const Limit limit(mesh);
    EXPECT_LT(maxDistanceToLimit(result, limit, 7), 1e-12 * size);

    // Independent of OpenSubdiv: on every face the limit surface is the uniform bicubic B-spline
    // of the 4 x 4 surrounding control points, the net being extended across the boundary by
    // reflection, P(-1) = 2 P(0) - P(1) (boundary curves are the cubic B-splines of the boundary
    // vertices, corners are interpolated).
    const std::function<Eigen::Vector3d(int, int)> net = [&](int i, int j) -> Eigen::Vector3d {
      if (i < 0) return 2 * net(0, j) - net(1, j);
      if (i > nx) return 2 * net(nx, j) - net(nx - 1, j);
      if (j < 0) return 2 * net(i, 0) - net(i, 1);
      if (j > ny) return 2 * net(i, ny) - net(i, ny - 1);
      return mesh.vertices.row(i * (ny + 1) + j).transpose();
    };
    const QuadChart& chart = result.layout.charts[0];
    const Handle(Geom_BSplineSurface) surface = cad::makeBSplineSurface(result.surfaces[0]);
    double worst = 0.0;
    for (int ci = 0; ci < chart.uCells; ++ci) {
      for (int cj = 0; cj < chart.vCells; ++cj) {
        const int f = chart.face(ci, cj);
        const int i = f / ny;  // grid() numbers face (i, j) as i * ny + j
        const int j = f % ny;
        for (double a : {0.0, 0.3, 0.77, 1.0}) {
          for (double b : {0.0, 0.45, 0.9}) {
            const SurfaceLocation at = locateInCell(chart, ci, cj, a, b);
            double bu[4];
            double bv[4];
            uniformBasis(at.u, bu);
            uniformBasis(at.v, bv);
            Eigen::Vector3d expected = Eigen::Vector3d::Zero();
            for (int p = 0; p < 4; ++p) {
              for (int q = 0; q < 4; ++q) expected += bu[p] * bv[q] * net(i - 1 + p, j - 1 + q);
            }
            worst = std::max(worst, (occtPoint(surface, ci + a, cj + b) - expected).norm());
          }
        }
      }
    }
    EXPECT_LT(worst, 1e-12 * size) << (curved ? "curved" : "planar");
  }
}

TEST(SurfaceBSplines, PlanarMeshIsAtNoDistanceHoweverItsChartsAreParameterised) {
  // A flat fan of five quads around a valence-5 vertex, refined twice: the limit surface and every
  // chart lie in z = 0, so the charts are at distance 0 from it, while next to the extraordinary
  // vertex they run through the plane at other parameters than the limit does.
  std::vector<Eigen::Vector3d> points{Eigen::Vector3d::Zero()};
  std::vector<std::array<int, 4>> quads;
  const double step = 2.0 * std::acos(-1.0) / 5.0;
  for (int i = 0; i < 5; ++i) {
    points.emplace_back(std::cos(i * step), std::sin(i * step), 0.0);
    points.emplace_back(1.3 * std::cos((i + 0.5) * step), 1.3 * std::sin((i + 0.5) * step), 0.0);
  }
  for (int i = 0; i < 5; ++i) quads.push_back({0, 1 + 2 * i, 2 + 2 * i, 1 + 2 * ((i + 1) % 5)});
  const QuadControlMesh fan = subdivide(makeQuadControlMesh(points, quads), 2);
  const LimitBSplines result = limitSurfaceToBSplines(fan);
  double deviation = 0.0, distance = 0.0;
  for (size_t c = 0; c < result.surfaces.size(); ++c) {
    deviation = std::max(deviation, result.maxDeviation[c]);
    distance = std::max(distance, result.maxDistance[c]);
  }
  EXPECT_LT(distance, 1e-14);
  EXPECT_GT(deviation, 1e-6);
}

TEST(SurfaceBSplines, PassThroughBorderStaysExactAndShared) {
  // A crease along x = 2 and a notch at the top right: the notch's concave vertex sends a
  // separatrix into the crease at (2, 3), so the left chart's crease side passes a node where two
  // right charts meet. The left chart is regular (crease patches included): exact.
  QuadControlMesh mesh = grid(4, 4, bump, [](int i, int j) { return !(i == 3 && j == 3); });
  mesh.creases.resize(4, 2);
  mesh.creases << 10, 11, 11, 12, 12, 13, 13, 14;
  const double size = modelSize(mesh);
  const LimitBSplines result = limitSurfaceToBSplines(mesh);
  ASSERT_EQ(result.layout.charts.size(), 4u);
  bool sawLongLine = false;
  for (const BorderLine& line : result.layout.lines) sawLongLine |= line.segments.size() == 2;
  EXPECT_TRUE(sawLongLine);
  for (size_t c = 0; c < result.layout.charts.size(); ++c) {
    const QuadChart& chart = result.layout.charts[c];
    if (chart.uCells * chart.vCells == 8) {
      EXPECT_LT(result.maxDeviation[c], 1e-12 * size);
    }
  }
  EXPECT_LT(result.maxBorderGap, 1e-12 * size);
  EXPECT_LT(maxSharedBorderDistance(result), 1e-12 * size);
  // Sewing splits the long crease edge at the T-junction: a valid open shell whose free edges
  // are the 9 chart sides on the mesh boundary.
  const SewnShape sewn = sewBSplineSurfaces(result.surfaces);
  EXPECT_TRUE(sewn.valid);
  EXPECT_FALSE(sewn.solid);
  EXPECT_EQ(sewn.shape.ShapeType(), TopAbs_SHELL);
  EXPECT_EQ(sewn.freeEdges, 9);
}

void expectWatertightSolid(const QuadControlMesh& mesh, const std::string& name) {
  const double size = modelSize(mesh);
  const LimitBSplines result = limitSurfaceToBSplines(mesh);
  EXPECT_LT(result.maxBorderGap, 1e-12 * size) << name;
  EXPECT_LT(maxSharedBorderDistance(result), 1e-12 * size) << name;
  double maxDeviation = 0.0;
  for (double d : result.maxDeviation) maxDeviation = std::max(maxDeviation, d);

  const SewnShape sewn = sewBSplineSurfaces(result.surfaces);
  EXPECT_TRUE(sewn.solid) << name;
  EXPECT_TRUE(sewn.valid) << name;
  EXPECT_EQ(sewn.freeEdges, 0) << name;
  EXPECT_LE(sewn.maxEdgeTolerance, sewn.tolerance) << name;
  ASSERT_EQ(sewn.shape.ShapeType(), TopAbs_SOLID) << name;
  GProp_GProps volumeProps;
  BRepGProp::VolumeProperties(sewn.shape, volumeProps);
  GProp_GProps areaProps;
  BRepGProp::SurfaceProperties(sewn.shape, areaProps);
  const Limit limit(mesh);
  const double exact = limitVolume(mesh, limit, 24);
  // The volumes differ by at most area x max deviation (plus the extrapolated tessellation error).
  const double bound = areaProps.Mass() * maxDeviation + 1e-6 * exact;
  std::cout << name << ": charts " << result.surfaces.size() << ", max deviation " << maxDeviation
            << ", solid volume " << volumeProps.Mass() << ", limit volume " << exact << ", bound " << bound
            << ", sewing max tolerance " << sewn.maxEdgeTolerance << "\n";
  EXPECT_GT(volumeProps.Mass(), 0.0) << name;
  EXPECT_NEAR(volumeProps.Mass(), exact, bound) << name;
  EXPECT_LT(std::abs(volumeProps.Mass() - exact), 2e-3 * exact) << name;
}

TEST(SurfaceBSplines, SubdividedCubeIsAWatertightSolid) {
  expectWatertightSolid(subdivide(cube(), 1), "cube");
}

TEST(SurfaceBSplines, CreasedCubeIsAWatertightSolidWithASharpCrease) {
  const QuadControlMesh mesh = cubeWithCreasedEquator();
  expectWatertightSolid(mesh, "creased cube");
  // Across the crease the two neighbouring surfaces meet at an angle (normals differ).
  const LimitBSplines result = limitSurfaceToBSplines(mesh);
  int creaseSegments = 0;
  for (const BorderSegment& segment : result.layout.segments) {
    if (segment.kind != BorderKind::Crease) continue;
    ++creaseSegments;
    gp_Vec normal[2];
    for (int k = 0; k < 2; ++k) {
      const SegmentUse& use = segment.uses[static_cast<size_t>(k)];
      const auto [s, t] = useParameters(result, use, 0.5);
      gp_Pnt p;
      gp_Vec du;
      gp_Vec dv;
      cad::makeBSplineSurface(result.surfaces[static_cast<size_t>(use.chart)])->D1(s, t, p, du, dv);
      normal[k] = du.Crossed(dv).Normalized();
    }
    EXPECT_LT(normal[0].Dot(normal[1]), 0.95);
  }
  EXPECT_EQ(creaseSegments, 4);
}

TEST(SurfaceBSplines, CubeWithCreasedTopRimAndCornersIsAWatertightSolid) {
  // Crease corners: at the top corners one side of the rim crease holds 1 face, the other 2.
  for (bool tagCorners : {false, true}) {
    QuadControlMesh base = cube();
    base.creases.resize(4, 2);
    base.creases << 4, 5, 5, 7, 7, 6, 6, 4;
    if (tagCorners) base.corners = {4, 5, 6, 7};
    const QuadControlMesh mesh = subdivide(base, 1);
    EXPECT_EQ(buildChartLayout(mesh).charts.size(), 6u);
    expectWatertightSolid(mesh, tagCorners ? "creased rim with corners" : "creased rim");
  }
}

TEST(SurfaceBSplines, DeviationShrinksUnderSubdivision) {
  // Same limit surface, finer control meshes: the approximation near the 8 extraordinary
  // vertices improves. Near a valence-n vertex the limit surface deviates from a polynomial
  // patch through its characteristic map, whose scale shrinks by the subdominant eigenvalue
  //   lambda_n = (5 + cos(2 pi / n) + cos(pi / n) sqrt(18 + 2 cos(2 pi / n))) / 16
  // per step, so the rate log2(d_k / d_{k+1}) tends to log2(1 / lambda_3) = 1.286.
  const double pi = std::acos(-1.0);
  const double lambda3 =
      (5 + std::cos(2 * pi / 3) + std::cos(pi / 3) * std::sqrt(18 + 2 * std::cos(2 * pi / 3))) / 16;
  const QuadControlMesh base = cube();
  double previous = 0.0;
  double previousKink = 0.0;
  double rate = 0.0;
  for (int levels = 1; levels <= 4; ++levels) {
    const QuadControlMesh mesh = subdivide(base, levels);
    const LimitBSplines result = limitSurfaceToBSplines(mesh);
    double deviation = 0.0;
    for (double d : result.maxDeviation) deviation = std::max(deviation, d);
    std::cout << "cube level " << levels << ": " << mesh.faces.rows() << " faces, max deviation " << deviation
              << ", max kink " << result.maxKinkDegrees << " degrees";
    if (levels > 1) {
      EXPECT_LT(result.maxKinkDegrees, previousKink);
    }
    previousKink = result.maxKinkDegrees;
    if (levels > 1) {
      rate = std::log2(previous / deviation);
      std::cout << ", rate " << rate;
      EXPECT_LT(deviation, previous / 2);
    }
    std::cout << "\n";
    EXPECT_GT(deviation, 0.0);  // extraordinary vertices: not in the spline space
    previous = deviation;
  }
  std::cout << "expected asymptotic rate log2(1 / lambda_3) = " << std::log2(1 / lambda3) << "\n";
  EXPECT_NEAR(rate, std::log2(1 / lambda3), 0.05);
}

TEST(SurfaceBSplines, ChartsShareTheirTangentPlanesAcrossSmoothBorders) {
  // Next to the cube's valence-3 vertices the limit surface is not bicubic: charts fitted on their
  // own meet at up to 4.0 / 1.8 / 0.78 degrees on the refined cube (levels 1-3) and 1.9 on the
  // creased one. With tangentContinuity, within 0.1 degree along every smooth border (0.005 /
  // 0.034 / 0.030 / 0.046), measured at 16 points per edge (the conversion checks 9).
  LimitBSplineOptions options;
  options.tangentContinuity = true;
  for (const QuadControlMesh& mesh : {subdivide(cube(), 1), subdivide(cube(), 2), subdivide(cube(), 3),
                                      subdivide(cubeWithCreasedEquator(), 1)}) {
    const LimitBSplines result = limitSurfaceToBSplines(mesh, options);
    const double jump = maxSmoothBorderNormalJump(result, 16);
    std::cout << mesh.faces.rows() << " faces: max normal jump " << jump << " degrees (" << result.maxKinkDegrees
              << " at the check points)\n";
    EXPECT_LT(jump, 0.1);
    EXPECT_LT(result.maxKinkDegrees, 0.1);
  }
}

TEST(SurfaceBSplines, TorusAndTubeCharts) {
  // Cut charts share a border with themselves: the fit still closes up exactly.
  for (const QuadControlMesh& mesh : {testing::torus(8, 6), testing::tube(8, 3)}) {
    const double size = modelSize(mesh);
    const LimitBSplines result = limitSurfaceToBSplines(mesh);
    ASSERT_EQ(result.surfaces.size(), 1u);
    EXPECT_LT(result.maxDeviation[0], 1e-12 * size);
    EXPECT_LT(maxSharedBorderDistance(result), 1e-12 * size);
    EXPECT_LT(result.maxKinkDegrees, 1e-6);  // regular: the cut is invisible (C2 across it)
  }
  // A closed crease ring fitted as one clamped curve from its single break node round to it.
  const QuadControlMesh ringed = testing::staggeredCreasedTube();
  const LimitBSplines ring = limitSurfaceToBSplines(ringed);
  for (double deviation : ring.maxDeviation) EXPECT_LT(deviation, 1e-12 * modelSize(ringed));
  EXPECT_LT(maxSharedBorderDistance(ring), 1e-12 * modelSize(ringed));
  const SewnShape sewn = sewBSplineSurfaces(limitSurfaceToBSplines(testing::torus(8, 6)).surfaces);
  EXPECT_EQ(sewn.freeEdges, 0);
  EXPECT_TRUE(sewn.solid);
  EXPECT_TRUE(sewn.valid);
}

TEST(SurfaceBSplines, OpenGridSewsIntoAShellWithFreeEdges) {
  const QuadControlMesh mesh = grid(4, 4, bump, [](int i, int j) { return i < 2 || j < 2; });
  const SewnShape sewn = sewBSplineSurfaces(limitSurfaceToBSplines(mesh).surfaces);
  EXPECT_FALSE(sewn.solid);
  EXPECT_TRUE(sewn.valid);
  EXPECT_EQ(sewn.shape.ShapeType(), TopAbs_SHELL);
  EXPECT_EQ(sewn.freeEdges, 8);  // the L's outline in boundary segments
}

TEST(SurfaceBSplines, ControlMeshConversionKeepsSharpFeaturesAndRejectsTheRest) {
  const QuadControlMesh quads = cubeWithCreasedEquator();
  const QuadControlMesh back = toQuadControlMesh(toControlMesh(quads));
  EXPECT_EQ(back.faces, quads.faces);
  EXPECT_EQ(back.creases, quads.creases);
  EXPECT_EQ(back.vertices, quads.vertices);
  // Semi-sharp creases are smooth in the limit but not polynomial: no chart border, not supported.
  RowMatrixX2i crease(1, 2);
  crease << quads.creases(0, 0), quads.creases(0, 1);
  const ControlMesh semiSharp(quads.vertices, std::vector<int>(static_cast<size_t>(quads.faces.rows()), 4),
                              std::vector<int>(quads.faces.data(), quads.faces.data() + quads.faces.size()),
                              crease, Eigen::VectorXd::Constant(1, 2.0));
  EXPECT_THROW(toQuadControlMesh(semiSharp), InvalidInputError);
  const ControlMesh triangle(RowMatrixX3d::Identity(3, 3), {3}, {0, 1, 2});
  try {
    toQuadControlMesh(triangle);
    FAIL() << "no exception";
  } catch (const InvalidInputError& error) {
    EXPECT_NE(std::string(error.what()).find("face 0 has 3 vertices"), std::string::npos) << error.what();
  }
}

TEST(SurfaceBSplines, RejectsBadOptionsAndEvaluators) {
  const QuadControlMesh mesh = grid(2, 2, bump);
  LimitBSplineOptions options;
  options.samplesPerSpan = 3;
  EXPECT_THROW(limitSurfaceToBSplines(mesh, options), InvalidInputError);
  const LimitPointsFunction broken = [](const std::vector<SurfaceLocation>& locations, RowMatrixX3d& points,
                                        RowMatrixX3d*) {
    points = RowMatrixX3d::Constant(static_cast<Eigen::Index>(locations.size()), 3, std::nan(""));
  };
  EXPECT_THROW(fitLimitBSplines(buildChartLayout(mesh), broken), SolverError);
  LimitBSplineOptions shallow;
  shallow.isolationLevel = 0;
  EXPECT_THROW(limitSurfaceToBSplines(mesh, shallow), InvalidInputError);
  EXPECT_THROW(sewBSplineSurfaces({}), InvalidInputError);
}

}  // namespace
}  // namespace bvmesh::surface

#include "core/quality/cell_quality.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/common/errors.h"
#include "core/common/parallel.h"
#include "core/volume/hex_scaled_jacobian.h"

namespace bvmesh::quality {
namespace {

using Eigen::Vector3d;
constexpr double kRootVSmall = 1e-150;  // OpenFOAM's ROOTVSMALL
constexpr double kDegrees = 180.0 / M_PI;

struct FaceGeometry {
  Vector3d centre;
  Vector3d area;  // area vector, along the face's normal
};

// OpenFOAM's face centre and area: triangles from each edge to the points' average, the centre
// weighted by triangle area. A face of a cell on a collapsed face may be a triangle.
FaceGeometry faceGeometry(const RowMatrixX3d& points, const grid::HexFace& face) {
  const auto corners = static_cast<size_t>(face.size);
  Vector3d average = Vector3d::Zero();
  for (size_t v = 0; v < corners; ++v) average += points.row(face.points[v]).transpose();
  average /= static_cast<double>(corners);
  Vector3d sumN = Vector3d::Zero(), sumAc = Vector3d::Zero();
  double sumA = 0.0;
  for (size_t v = 0; v < corners; ++v) {
    const Vector3d a = points.row(face.points[v]).transpose();
    const Vector3d b = points.row(face.points[(v + 1) % corners]).transpose();
    const Vector3d n = (b - a).cross(average - a);
    const double area = n.norm();
    sumN += n;
    sumA += area;
    sumAc += area * (a + b + average);
  }
  return {sumA > kRootVSmall ? Vector3d(sumAc / (3.0 * sumA)) : average, 0.5 * sumN};
}

struct CellGeometry {
  Vector3d centre;
  double volume;
  std::array<FaceGeometry, 6> faces;
  int faceCount = 0;  // 6, 5 for a prism
};

// OpenFOAM's cell centre and volume: pyramids from the faces to the face centres' average. The
// faces of a cell on a collapsed face lose their repeated points, and those left with fewer
// than three are none (a prism has five faces).
CellGeometry cellGeometry(const RowMatrixX3d& points, const std::array<Eigen::Index, 8>& corners) {
  CellGeometry cell{};
  Vector3d estimate = Vector3d::Zero();
  for (int side = 0; side < 6; ++side) {
    const grid::HexFace face = grid::hexCellFace(corners, side);
    if (face.size < 3) continue;
    const FaceGeometry& geometry = cell.faces[static_cast<size_t>(cell.faceCount++)] =
        faceGeometry(points, face);
    estimate += geometry.centre;
  }
  estimate /= static_cast<double>(cell.faceCount);
  Vector3d weighted = Vector3d::Zero();
  double volume3 = 0.0;
  for (int f = 0; f < cell.faceCount; ++f) {
    const FaceGeometry& face = cell.faces[static_cast<size_t>(f)];
    const double pyramid = std::max(face.area.dot(face.centre - estimate), kRootVSmall);
    weighted += pyramid * (0.75 * face.centre + 0.25 * estimate);
    volume3 += pyramid;
  }
  cell.centre = weighted / volume3;
  cell.volume = volume3 / 3.0;
  return cell;
}

// OpenFOAM's skewness of a face between a cell centre and a point (the neighbour's centre, or
// the face centre pushed out along the normal on a boundary).
double faceSkewness(const RowMatrixX3d& points, const grid::HexFace& face, const FaceGeometry& geometry,
                    const Vector3d& ownerCentre, const Vector3d& d) {
  const Vector3d toFace = geometry.centre - ownerCentre;
  const Vector3d offset = toFace - (geometry.area.dot(toFace) / (geometry.area.dot(d) + kRootVSmall)) * d;
  const Vector3d direction = offset / (offset.norm() + kRootVSmall);
  double reach = 0.2 * d.norm() + kRootVSmall;
  for (int v = 0; v < face.size; ++v) {
    reach = std::max(reach, std::abs(direction.dot(points.row(face.points[static_cast<size_t>(v)]).transpose() - geometry.centre)));
  }
  return offset.norm() / reach;
}

// The q-quantile, interpolated between the two order statistics around it, found by selection
// (a sort of each metric's million values took most of a grid's quality summary); reorders
// `values`.
double percentile(std::vector<double>& values, double q) {
  const double position = q * static_cast<double>(values.size() - 1);
  const auto below = static_cast<size_t>(std::floor(position));
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(below);
  std::nth_element(values.begin(), at, values.end());
  if (below + 1 == values.size()) return *at;
  const double above = *std::min_element(at + 1, values.end());  // every value past `at` is >= it
  return *at + (position - static_cast<double>(below)) * (above - *at);
}

MetricSummary summary(const std::string& name, std::vector<double> values) {
  MetricSummary result;
  result.name = name;
  result.count = static_cast<Eigen::Index>(values.size());
  if (values.empty()) return result;
  const auto [smallest, largest] = std::minmax_element(values.begin(), values.end());
  result.min = *smallest;
  result.max = *largest;
  result.p01 = percentile(values, 0.01);
  result.median = percentile(values, 0.5);
  result.p99 = percentile(values, 0.99);
  return result;
}

}  // namespace

CellQuality measureCellQuality(const grid::HexTopology& topology) {
  const RowMatrixX3d& points = topology.points().points;
  const Eigen::Index cells = topology.cellCount();
  CellQuality quality;
  quality.scaledJacobian = cellScaledJacobians(topology);
  quality.aspectRatio.resize(static_cast<size_t>(cells));
  quality.volume.resize(static_cast<size_t>(cells));
  quality.nonOrthogonality.assign(static_cast<size_t>(cells), 0.0);
  quality.skewness.assign(static_cast<size_t>(cells), 0.0);
  quality.growthRatio.assign(static_cast<size_t>(cells), 1.0);
  std::vector<Vector3d> centres(static_cast<size_t>(cells));
  parallelChunks(cells, 4096, [&](std::int64_t begin, std::int64_t end) {
    for (Eigen::Index c = begin; c < end; ++c) {
      const std::array<Eigen::Index, 8> corners = topology.cellCorners(c);
      std::array<Vector3d, 8> x;
      for (size_t v = 0; v < 8; ++v) x[v] = points.row(corners[v]).transpose();
      // Mean edge length per direction: i edges 0-1 3-2 4-5 7-6, j edges 0-3 1-2 4-7 5-6, k edges 0-4 1-5 2-6 3-7.
      const double edgeI = (x[1] - x[0]).norm() + (x[2] - x[3]).norm() + (x[5] - x[4]).norm() + (x[6] - x[7]).norm();
      const double edgeJ = (x[3] - x[0]).norm() + (x[2] - x[1]).norm() + (x[7] - x[4]).norm() + (x[6] - x[5]).norm();
      const double edgeK = (x[4] - x[0]).norm() + (x[5] - x[1]).norm() + (x[6] - x[2]).norm() + (x[7] - x[3]).norm();
      const double shortest = std::min({edgeI, edgeJ, edgeK});
      quality.aspectRatio[static_cast<size_t>(c)] =
          shortest > 0.0 ? std::max({edgeI, edgeJ, edgeK}) / shortest : std::numeric_limits<double>::infinity();
      const CellGeometry geometry = cellGeometry(points, corners);
      centres[static_cast<size_t>(c)] = geometry.centre;
      quality.volume[static_cast<size_t>(c)] = geometry.volume;
    }
  });
  auto worsen = [](double& slot, double value) { slot = std::max(slot, value); };
  // Per cell over its internal faces: the sum of a a^T (xx, yy, zz, xy, xz, yz) and of |a| (area
  // vectors a), and their count.
  std::vector<std::array<double, 6>> areaTensor(static_cast<size_t>(cells), std::array<double, 6>{});
  std::vector<double> areaSum(static_cast<size_t>(cells), 0.0);
  std::vector<int> internalFaces(static_cast<size_t>(cells), 0);
  topology.forEachInternalFace([&](const grid::HexFace& face) {
    const FaceGeometry geometry = faceGeometry(points, face);
    const Vector3d& a = geometry.area;
    const Vector3d& own = centres[static_cast<size_t>(face.owner)];
    const Vector3d d = centres[static_cast<size_t>(face.neighbour)] - own;
    const double cosine = geometry.area.dot(d) / (geometry.area.norm() * d.norm() + kRootVSmall);
    const double angle = std::acos(std::min(1.0, std::max(-1.0, cosine))) * kDegrees;
    const double skew = faceSkewness(points, face, geometry, own, d);
    const double v0 = quality.volume[static_cast<size_t>(face.owner)];
    const double v1 = quality.volume[static_cast<size_t>(face.neighbour)];
    const double growth = std::max(v0, v1) / std::max(std::min(v0, v1), kRootVSmall);
    for (Eigen::Index cell : {face.owner, face.neighbour}) {
      worsen(quality.nonOrthogonality[static_cast<size_t>(cell)], angle);
      worsen(quality.skewness[static_cast<size_t>(cell)], skew);
      worsen(quality.growthRatio[static_cast<size_t>(cell)], growth);
      std::array<double, 6>& t = areaTensor[static_cast<size_t>(cell)];
      t[0] += a.x() * a.x(), t[1] += a.y() * a.y(), t[2] += a.z() * a.z();
      t[3] += a.x() * a.y(), t[4] += a.x() * a.z(), t[5] += a.y() * a.z();
      areaSum[static_cast<size_t>(cell)] += a.norm();
      ++internalFaces[static_cast<size_t>(cell)];
    }
  });
  quality.determinant.assign(static_cast<size_t>(cells), 0.0);
  for (size_t c = 0; c < quality.determinant.size(); ++c) {
    if (internalFaces[c] == 0 || !(areaSum[c] > 0.0)) continue;
    const double meanArea = areaSum[c] / internalFaces[c];
    const std::array<double, 6>& t = areaTensor[c];
    Eigen::Matrix3d tensor;
    tensor << t[0], t[3], t[4], t[3], t[1], t[5], t[4], t[5], t[2];
    quality.determinant[c] = std::abs((tensor / (meanArea * meanArea)).determinant()) / 8.0;
  }
  topology.forEachBoundaryFace([&](size_t, const grid::HexFace& face) {
    const FaceGeometry geometry = faceGeometry(points, face);
    const Vector3d& own = centres[static_cast<size_t>(face.owner)];
    const Vector3d normal = geometry.area / (geometry.area.norm() + kRootVSmall);
    const Vector3d d = 2.0 * normal * normal.dot(geometry.centre - own);  // to the mirrored centre
    worsen(quality.skewness[static_cast<size_t>(face.owner)], faceSkewness(points, face, geometry, own, d));
  });
  // The wall, block face by block face: per wall cell the angle between the wall face's normal
  // and the mean of the cell's four edges off the wall; per wall point the first edge's length.
  for (const grid::GridBlock& block : topology.grid().blocks()) {
    for (int side = 0; side < 6; ++side) {
      if (block.faces[static_cast<size_t>(side)].condition != volume::BoundaryCondition::Wall) continue;
      const int normal = side / 2;
      const int inward = side % 2 == 0 ? 1 : -1;
      const std::array<int, 2> counts = volume::faceGridCounts(block.size, side);
      // The wall point at face position (a, b) and the one above it.
      auto pair = [&](int a, int b) {
        std::array<int, 3> ijk = volume::faceGridPosition(block.size, side, a, b);
        const Vector3d wall = block.points.row(block.index(ijk[0], ijk[1], ijk[2])).transpose();
        ijk[static_cast<size_t>(normal)] += inward;
        return std::pair<Vector3d, Vector3d>{wall, block.points.row(block.index(ijk[0], ijk[1], ijk[2])).transpose()};
      };
      for (int b = 0; b < counts[1]; ++b) {
        for (int a = 0; a < counts[0]; ++a) {
          const auto [wall, above] = pair(a, b);
          quality.firstCellHeight.push_back((above - wall).norm());
          if (a + 1 == counts[0] || b + 1 == counts[1]) continue;
          const auto [p00, q00] = pair(a, b);
          const auto [p10, q10] = pair(a + 1, b);
          const auto [p11, q11] = pair(a + 1, b + 1);
          const auto [p01, q01] = pair(a, b + 1);
          const Vector3d faceNormal = (p11 - p00).cross(p01 - p10);
          const Vector3d meanEdge = (q00 - p00) + (q10 - p10) + (q11 - p11) + (q01 - p01);
          const double cosine = std::abs(faceNormal.dot(meanEdge)) / (faceNormal.norm() * meanEdge.norm() + kRootVSmall);
          quality.wallAngle.push_back(std::acos(std::min(1.0, cosine)) * kDegrees);
        }
      }
    }
  }
  return quality;
}

std::vector<MetricSummary> summarizeQuality(const grid::HexTopology& topology, const CellQuality& quality, int block) {
  const bool all = block < 0;
  const Eigen::Index begin = all ? 0 : topology.cellOffset(static_cast<size_t>(block));
  const Eigen::Index end = all ? topology.cellCount() : topology.cellOffset(static_cast<size_t>(block) + 1);
  // Per metric its values in the block (the wall's metrics, per wall cell or point, only over all).
  struct Values {
    const char* name;
    std::vector<double>::const_iterator first, last;
  };
  auto cells = [&](const char* name, const std::vector<double>& values) {
    return Values{name, values.begin() + begin, values.begin() + end};
  };
  std::vector<Values> metrics{cells("scaled_jacobian", quality.scaledJacobian),
                              cells("non_orthogonality", quality.nonOrthogonality),
                              cells("skewness", quality.skewness),
                              cells("aspect_ratio", quality.aspectRatio),
                              cells("growth_ratio", quality.growthRatio),
                              cells("determinant", quality.determinant)};
  if (all && !quality.wallAngle.empty()) {
    metrics.push_back({"wall_angle", quality.wallAngle.begin(), quality.wallAngle.end()});
    metrics.push_back({"first_cell_height", quality.firstCellHeight.begin(), quality.firstCellHeight.end()});
  }
  std::vector<MetricSummary> result(metrics.size());
  parallelChunks(static_cast<std::int64_t>(metrics.size()), 1, [&](std::int64_t first, std::int64_t last) {
    for (auto m = static_cast<size_t>(first); m < static_cast<size_t>(last); ++m) {
      result[m] = summary(metrics[m].name, std::vector<double>(metrics[m].first, metrics[m].last));
    }
  });
  return result;
}

// A cell's twelve edges as pairs of its corners (order 000 100 110 010 001 101 111 011).
constexpr std::array<std::array<size_t, 2>, 12> kCellEdges{
    {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

std::vector<double> cellScaledJacobians(const grid::HexTopology& topology) {
  const RowMatrixX3d& points = topology.points().points;
  std::vector<double> jacobians(static_cast<size_t>(topology.cellCount()));
  parallelChunks(topology.cellCount(), 4096, [&](std::int64_t begin, std::int64_t end) {
    for (Eigen::Index c = begin; c < end; ++c) {
      const std::array<Eigen::Index, 8> corners = topology.cellCorners(c);
      std::array<Vector3d, 8> x;
      for (size_t v = 0; v < 8; ++v) x[v] = points.row(corners[v]).transpose();
      // Corners at one place that are not one merged point (an axis a grid pinches to without
      // a collapsed face) make no cell: its faces there would have no area.
      const bool pinched =
          std::any_of(kCellEdges.begin(), kCellEdges.end(), [&](const std::array<size_t, 2>& e) {
            return corners[e[0]] != corners[e[1]] && x[e[0]] == x[e[1]];
          });
      jacobians[static_cast<size_t>(c)] = pinched ? -1.0 : volume::hexScaledJacobian(x);
    }
  });
  return jacobians;
}

void requirePositiveCells(const grid::HexTopology& topology) {
  const std::vector<double> jacobians = cellScaledJacobians(topology);
  const auto first = std::find_if(jacobians.begin(), jacobians.end(), [](double value) { return !(value > 0.0); });
  if (first == jacobians.end()) return;
  const Eigen::Index cell = first - jacobians.begin();
  size_t b = 0;
  while (topology.cellOffset(b + 1) <= cell) ++b;
  const grid::GridBlock& block = topology.grid().blocks()[b];
  const Eigen::Index local = cell - topology.cellOffset(b);
  const Eigen::Index ni = block.size[0] - 1, nj = block.size[1] - 1;
  const auto inverted = std::count_if(jacobians.begin(), jacobians.end(),
                                      [](double value) { return !(value > 0.0); });
  throw InvalidInputError("the grid has " + std::to_string(inverted) + " cells with a non-positive Jacobian, the first in block " +
                          std::to_string(b) + " at cell (" + std::to_string(local % ni) + ", " +
                          std::to_string((local / ni) % nj) + ", " + std::to_string(local / (ni * nj)) +
                          ") (scaled Jacobian " + std::to_string(*first) + "); it is not written unless forced");
}

}  // namespace bvmesh::quality

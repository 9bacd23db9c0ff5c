#include "core/volume/marching.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <optional>
#include <set>
#include <string>

#include "core/common/distinct_corners.h"
#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/common/number_text.h"
#include "core/volume/boundary_layer_lines.h"
#include "core/volume/hex_scaled_jacobian.h"
#include "core/volume/turning.h"

namespace bvmesh::volume {
namespace {

using Eigen::Vector3d;

// Rounds of local smoothing before a poor cell is accepted (if positive) or reported.
constexpr int kRepairs = 30;
// A far-field cell that folds with less than this share of its layer's median growth in area
// (its area over its wall cell's) lies where the layers converge: a concave groove or corner
// (two fused spheres' waist), which neither more smoothing nor a lower growth opened.
constexpr double kConvergedAreaShare = 0.25;

// Twice a front quad's area times its unit normal: the cross product of its diagonals.
Vector3d quadAreaVector(const RowMatrixX3d& points, const std::array<int, 4>& quad) {
  const Vector3d diagonal = (points.row(quad[2]) - points.row(quad[0])).transpose();
  return diagonal.cross((points.row(quad[3]) - points.row(quad[1])).transpose());
}

class Marcher {
 public:
  Marcher(const MarchingFront& front, const MarchingOptions& options)
      : front_(front),
        options_(options),
        neighbours_(frontNeighbours(front)),
        fanQuad_(front.quads.size(), 0) {
    std::vector<char> fan(static_cast<size_t>(front.points.rows()), 0);
    for (const FanPoint& point : front.fanPoints) fan[static_cast<size_t>(point.point)] = 1;
    for (size_t q = 0; q < front.quads.size(); ++q) {
      for (int p : front.quads[q]) fanQuad_[q] = static_cast<char>(fanQuad_[q] | fan[static_cast<size_t>(p)]);
    }
    if (front.points.rows() > 0) {
      wallSize_ = (front.points.colwise().maxCoeff() - front.points.colwise().minCoeff()).norm();
    }
  }

  MarchingResult run() {
    checkOptions();
    MarchingResult result;
    result.layers.push_back(front_.points);
    result.layerDistance.push_back(0.0);
    // Boundary layer: straight lines along the wall normals, geometric growth.
    const int nBl = options_.boundaryLayerLayers;
    const double r = options_.boundaryLayerGrowth;
    double h = r == 1.0 ? options_.boundaryLayerThickness / nBl
                        : options_.boundaryLayerThickness * (r - 1.0) / (std::pow(r, nBl) - 1.0);
    std::vector<double> blDistance;
    for (int k = 1; k <= nBl; ++k) {
      blDistance.push_back(k == nBl ? options_.boundaryLayerThickness : (k == 1 ? h : blDistance.back() + h));
      if (k < nBl) h *= r;
    }
    // Straight grid lines along the wall normals; where a cell would be poor (a patch smaller
    // than the boundary layer is thick, next to a sharp edge), the lines' directions are smoothed
    // there alone, so the wall stays orthogonal everywhere else.
    BoundaryLayerLines bl = boundaryLayerLines(front_, options_.planes, options_.boundaryLayerThickness,
                                               options_.sharpEdgeSplay * options_.boundaryLayerThickness);
    RowMatrixX3d& lines = bl.directions;
    const Eigen::VectorXd reach = foldLimitedReach(lines, bl.lengths).cwiseProduct(bl.lengths);
    std::vector<RowMatrixX3d> blLayers;
    for (int repair = 0;; ++repair) {
      blLayers.clear();
      std::vector<char> bad(front_.quads.size(), 0);
      double worst = 1.0;
      int worstQuad = -1;
      int worstLayer = 1;
      bool poor = false;
      for (int k = 0; k < nBl; ++k) {
        RowMatrixX3d layer = front_.points + blDistance[static_cast<size_t>(k)] * (reach.asDiagonal() * lines);
        keepOnPlane(layer);
        const RowMatrixX3d& below = k == 0 ? front_.points : blLayers.back();
        const PoorCells cells = markPoorCells(below, layer, bad);
        poor = poor || cells.any;
        if (cells.worst < worst) {
          worst = cells.worst;
          worstQuad = cells.where;
          worstLayer = k + 1;
        }
        blLayers.push_back(std::move(layer));
      }
      if (!poor || (repair >= kRepairs && worst > 0.0)) break;
      if (repair >= kRepairs || options_.smoothing == 0.0) {
        fold(worstLayer, worst, worstQuad, front_.points,
             "in the boundary layer: a thinner boundary layer, a finer wall there or a coarser level of the "
             "wall to "
             "march from keeps its grid lines apart");
      }
      smoothDirections(lines, 4, markAround(bad));
      turnFans(front_, options_.planes, lines);
    }
    for (int k = 0; k < nBl; ++k) {
      result.layers.push_back(std::move(blLayers[static_cast<size_t>(k)]));
      result.layerDistance.push_back(blDistance[static_cast<size_t>(k)]);
    }
    double distance = options_.boundaryLayerThickness;
    // Far field: layer thicknesses grow by farfieldGrowth from the last boundary-layer one, scaled
    // so that their sum reaches the domain boundary from the front's mean radius.
    const RowMatrixX3d& top = result.layers.back();
    double meanRadius = 0.0;
    for (Eigen::Index p = 0; p < top.rows(); ++p) meanRadius += (top.row(p).transpose() - options_.domain.centre).norm();
    meanRadius /= static_cast<double>(std::max<Eigen::Index>(1, top.rows()));
    const double remaining = options_.farfieldDistance - meanRadius;
    const double first = h * options_.farfieldGrowth;
    if (remaining < 4 * first) {
      throw InvalidInputError(
          "far-field distance " + numberText(options_.farfieldDistance) +
          " leaves no room outside the boundary layer (its top lies at a mean distance of " +
          numberText(meanRadius) + " from the domain centre)");
    }
    const double g = options_.farfieldGrowth;
    const int nFar = std::max(2, static_cast<int>(std::ceil(std::log(1.0 + remaining * (g - 1.0) / first) / std::log(g))));
    if (nBl + nFar > options_.maxLayers) {
      throw InvalidInputError("the far field needs " + std::to_string(nFar) + " layers at growth " +
                              numberText(g) + ", more than max_layers (" +
                              std::to_string(options_.maxLayers) +
                              "): raise the far-field growth or max_layers");
    }
    const double layerPoints = static_cast<double>(nBl + nFar + 1) * static_cast<double>(front_.points.rows());
    if (options_.maxLayerPoints > 0 && layerPoints > static_cast<double>(options_.maxLayerPoints)) {
      throw InvalidInputError("marching " + std::to_string(nBl + nFar) + " layers of " +
                              std::to_string(front_.points.rows()) + " points (" + numberText(layerPoints) +
                              " layer points) is more than max_layer_points (" +
                              std::to_string(options_.maxLayerPoints) +
                              ", the memory budget): march from a coarser level of the wall, or with fewer layers "
                              "(a larger far-field growth)");
    }
    const double scale = remaining * (g - 1.0) / (first * (std::pow(g, nFar) - 1.0));
    double step = first * scale;
    // Marching directions remember the previous layer's: at a sharp convex edge (a trailing edge)
    // the front's own normal is the near-cancelling sum of both sides' and says little.
    RowMatrixX3d directions = lines;
    std::optional<HyperbolicStepper> hyperbolic;
    if (options_.farfieldScheme == FarfieldScheme::Hyperbolic) {
      HyperbolicOptions scaled = options_.hyperbolic;
      scaled.explicitSmoothing *= options_.smoothing;
      scaled.implicitSmoothing *= options_.smoothing;
      hyperbolic.emplace(front_.points.rows(), front_.quads, front_.onPlanes, options_.planes, scaled);
    }
    for (int k = 1; k <= nFar; ++k) {
      const double progress = static_cast<double>(k) / nFar;
      const double towardsDomain = std::min(1.0, distance / wallSize_);
      const RowMatrixX3d& points = result.layers.back();
      // A hyperbolic layer that would fold (a convex box corner's splayed boundary-layer top)
      // takes the smoothed step, whose radial turn and point smoothing open it, or the smoothed
      // step round its fold alone (smoothedOrBlended).
      RowMatrixX3d next;
      if (!hyperbolic) {
        next = marchOnce(points, directions, step, progress, towardsDomain, nBl + k);
      } else {
        HyperbolicAttempt attempt = hyperbolicOnce(*hyperbolic, result.layers[result.layers.size() - 2],
                                                   points, step, progress, directions);
        if (attempt.points) {
          next = std::move(*attempt.points);
        } else {
          ++result.farfieldLayersSmoothed;
          next = smoothedOrBlended(points, directions, step, progress, towardsDomain, nBl + k, attempt);
        }
      }
      distance += step;
      result.layers.push_back(std::move(next));
      result.layerDistance.push_back(distance);
      step *= g;
    }
    blendOntoDomain(result, nBl);
    result.layerMinScaledJacobian.push_back(1.0);
    for (size_t k = 1; k < result.layers.size(); ++k) {
      result.layerMinScaledJacobian.push_back(worstCell(result.layers[k - 1], result.layers[k]));
    }
    return result;
  }

 private:
  void checkOptions() const {
    checkFiniteAtLeast(options_.boundaryLayerThickness, 0.0, "boundary-layer thickness", true);
    checkFiniteAtLeast(options_.farfieldDistance, 0.0, "far-field distance", true);
    if (options_.boundaryLayerLayers < 1 || options_.boundaryLayerLayers > 100) {
      throw InvalidInputError("boundary-layer layers must be in 1..100, got " + std::to_string(options_.boundaryLayerLayers));
    }
    if (!(options_.boundaryLayerGrowth >= 1.0 && options_.boundaryLayerGrowth <= 3.0)) {
      throw InvalidInputError("boundary-layer growth must be in [1, 3], got " +
                              numberText(options_.boundaryLayerGrowth));
    }
    if (!(options_.farfieldGrowth > 1.0 && options_.farfieldGrowth <= 3.0)) {
      throw InvalidInputError("far-field growth must be in (1, 3], got " +
                              numberText(options_.farfieldGrowth));
    }
    if (!(options_.smoothing >= 0.0 && options_.smoothing <= 10.0)) {
      throw InvalidInputError("smoothing must be in [0, 10], got " + numberText(options_.smoothing));
    }
    if (!(options_.sharpEdgeSplay >= 0.0 && options_.sharpEdgeSplay <= 20.0)) {
      throw InvalidInputError("sharp-edge splay must be in [0, 20] boundary-layer thicknesses, got " +
                              numberText(options_.sharpEdgeSplay));
    }
    if (!(options_.minScaledJacobian >= 0.0 && options_.minScaledJacobian < 1.0)) {
      throw InvalidInputError("minimum scaled Jacobian must be in [0, 1), got " +
                              numberText(options_.minScaledJacobian));
    }
    options_.domain.validate();
    if (front_.points.rows() == 0 || front_.quads.empty()) throw InvalidInputError("the wall to march has no cells");
    if (front_.normals.rows() != front_.points.rows()) throw InvalidInputError("one wall normal per point is needed");
    for (Eigen::Index p = 0; p < front_.points.rows(); ++p) {
      if (!front_.points.row(p).allFinite() || !(std::abs(front_.normals.row(p).norm() - 1.0) < 1e-6)) {
        throw InvalidInputError("wall point " + std::to_string(p) + " has a non-finite position or no unit normal");
      }
    }
  }

  unsigned planesOf(Eigen::Index p) const { return front_.planesAt(p); }
  bool onPlane(Eigen::Index p) const { return planesOf(p) != 0; }
  // A direction at point p kept in the boundary planes the point lies on.
  Vector3d inPlanes(Eigen::Index p, const Vector3d& d) const { return options_.planes.along(d, planesOf(p)); }

  // Mirrored ghost points: a symmetric stencil across a plane reduces to the projection.
  void keepOnPlane(RowMatrixX3d& points) const {
    for (Eigen::Index p = 0; p < points.rows(); ++p) {
      if (!onPlane(p)) continue;
      points.row(p) = options_.planes.onto(points.row(p).transpose(), planesOf(p)).transpose();
    }
  }

  RowMatrixX3d frontNormals(const RowMatrixX3d& points) const {
    RowMatrixX3d normals = RowMatrixX3d::Zero(points.rows(), 3);
    for (const auto& q : front_.quads) {
      const Vector3d n = quadAreaVector(points, q);
      for (int k = 0; k < 4; ++k) normals.row(q[static_cast<size_t>(k)]) += n.transpose();
    }
    for (Eigen::Index p = 0; p < normals.rows(); ++p) {
      Vector3d n = normals.row(p).transpose();
      n = inPlanes(p, n);
      normals.row(p) = n.normalized().transpose();
    }
    return normals;
  }

  // Points of the marked cells and their neighbours.
  std::vector<char> markAround(const std::vector<char>& cells) const {
    std::vector<char> marks(static_cast<size_t>(front_.points.rows()), 0);
    for (size_t q = 0; q < cells.size(); ++q) {
      if (cells[q] == 0) continue;
      for (int p : front_.quads[q]) {
        marks[static_cast<size_t>(p)] = 1;
        for (int n : neighbours_[static_cast<size_t>(p)]) marks[static_cast<size_t>(n)] = 1;
      }
    }
    return marks;
  }

  // Whether the cell on `quad` with this scaled Jacobian is below the quality wanted of it
  // (minScaledJacobian; a knife edge's fan, whose cells are thin by design where it closes, only
  // positive).
  bool isPoor(size_t quad, double quality) const {
    return fanQuad_[quad] != 0 ? !(quality > 0.0) : quality < options_.minScaledJacobian;
  }

  struct PoorCells {
    double worst = 1.0;  // the worst poor cell's scaled Jacobian
    int where = -1;      // and its quad
    bool any = false;    // some cell is poor
  };

  // Marks the poor cells between two layers; returns the worst of them and where.
  PoorCells markPoorCells(const RowMatrixX3d& lower, const RowMatrixX3d& upper,
                          std::vector<char>& bad) const {
    PoorCells result;
    for (size_t q = 0; q < front_.quads.size(); ++q) {
      const double quality = cellQuality(lower, upper, q);
      if (!isPoor(q, quality)) continue;
      bad[q] = 1;
      result.any = true;
      if (quality < result.worst) {
        result.worst = quality;
        result.where = static_cast<int>(q);
      }
    }
    return result;
  }

  // Direction smoothing at the marked points (the local repair of poor cells).
  void smoothDirections(RowMatrixX3d& directions, int iterations, const std::vector<char>& only) const {
    for (int it = 0; it < iterations; ++it) {
      RowMatrixX3d next = directions;
      for (Eigen::Index p = 0; p < directions.rows(); ++p) {
        if (only[static_cast<size_t>(p)] == 0) continue;
        const auto& near = neighbours_[static_cast<size_t>(p)];
        Vector3d mean = Vector3d::Zero();
        for (int q : near) mean += directions.row(q).transpose();
        mean /= static_cast<double>(near.size());
        Vector3d d = directions.row(p).transpose() + 0.5 * (mean - directions.row(p).transpose());
        d = inPlanes(p, d);
        next.row(p) = d.normalized().transpose();
      }
      directions = std::move(next);
    }
  }

  // Laplacian smoothing in the plane normal to each point's marching direction.
  void smoothPoints(RowMatrixX3d& points, const RowMatrixX3d& directions, int iterations, double weight,
                    const std::vector<char>& only = {}) const {
    for (int it = 0; it < iterations; ++it) {
      RowMatrixX3d next = points;
      for (Eigen::Index p = 0; p < points.rows(); ++p) {
        if (!only.empty() && only[static_cast<size_t>(p)] == 0) continue;
        const auto& near = neighbours_[static_cast<size_t>(p)];
        Vector3d mean = Vector3d::Zero();
        for (int q : near) mean += points.row(q).transpose();
        mean /= static_cast<double>(near.size());
        Vector3d move = mean - points.row(p).transpose();
        const Vector3d d = directions.row(p).transpose();
        move -= move.dot(d) * d;
        next.row(p) = points.row(p) + weight * move.transpose();
      }
      keepOnPlane(next);
      points = std::move(next);
    }
  }

  double cellQuality(const RowMatrixX3d& lower, const RowMatrixX3d& upper, size_t quad) const {
    std::array<Vector3d, 8> corners;
    for (int k = 0; k < 4; ++k) {
      corners[static_cast<size_t>(k)] = lower.row(front_.quads[quad][static_cast<size_t>(k)]).transpose();
      corners[static_cast<size_t>(k + 4)] = upper.row(front_.quads[quad][static_cast<size_t>(k)]).transpose();
    }
    return hexScaledJacobian(corners);
  }

  // Worst scaled Jacobian of the cells between two layers.
  double worstCell(const RowMatrixX3d& lower, const RowMatrixX3d& upper) const {
    double worst = 1.0;
    for (size_t q = 0; q < front_.quads.size(); ++q) worst = std::min(worst, cellQuality(lower, upper, q));
    return worst;
  }

  // Per point, the fraction of the boundary-layer thickness its grid line reaches. Straight lines
  // that converge or shear against their neighbours (a concave corner such as a wing-body junction,
  // splayed lines over wall cells much smaller than the layer is thick) fold a cell at some
  // distance; each wall quad's column is sampled for the first distance where a thin cell of it
  // falls below the quality threshold, its points' lines stop at half of that, and the fraction
  // rises back to 1 over a few cells around such a place so that the boundary layer's top has no
  // step. 1 wherever the whole thickness is safe.
  Eigen::VectorXd foldLimitedReach(const RowMatrixX3d& lines, const Eigen::VectorXd& lengths) const {
    constexpr int kSamples = 32;
    constexpr double kShareOfFold = 0.5;
    constexpr double kRisePerCell = 0.25;
    const double thickness = options_.boundaryLayerThickness;
    const Eigen::Index n = front_.points.rows();
    Eigen::VectorXd reach = Eigen::VectorXd::Ones(n);
    for (size_t quad = 0; quad < front_.quads.size(); ++quad) {
      std::array<Vector3d, 8> corners;
      for (int s = 0; s < kSamples; ++s) {
        const double lower = thickness * s / kSamples;
        const double upper = thickness * (s + 1) / kSamples;
        for (int k = 0; k < 4; ++k) {
          const int p = front_.quads[quad][static_cast<size_t>(k)];
          corners[static_cast<size_t>(k)] =
              (front_.points.row(p) + lower * lengths[p] * lines.row(p)).transpose();
          corners[static_cast<size_t>(k + 4)] =
              (front_.points.row(p) + upper * lengths[p] * lines.row(p)).transpose();
        }
        if (!isPoor(quad, hexScaledJacobian(corners))) continue;
        // Only a converging column (its cross-section shrinking: a concave corner) is stopped; a
        // column poor from the wall on, or one diverging around a convex sharp edge, is the splay
        // band's and the local repair's to mend.
        const auto area = [&](int base) {
          return (corners[static_cast<size_t>(base + 2)] - corners[static_cast<size_t>(base)])
              .cross(corners[static_cast<size_t>(base + 3)] - corners[static_cast<size_t>(base + 1)])
              .norm();
        };
        if (s > 0 && area(4) < area(0) * (1.0 - 1e-9)) {
          for (int p : front_.quads[quad]) reach[p] = std::min(reach[p], kShareOfFold * lower / thickness);
        }
        break;
      }
    }
    for (int round = 0; round < static_cast<int>(std::ceil(1.0 / kRisePerCell)); ++round) {
      Eigen::VectorXd next = reach;
      for (Eigen::Index p = 0; p < n; ++p) {
        for (int q : neighbours_[static_cast<size_t>(p)]) next[p] = std::min(next[p], reach[q] + kRisePerCell);
      }
      reach = std::move(next);
    }
    return reach;
  }

  // Implicit direction smoothing: solves (I + epsilon (I - mean of the neighbours)) d = target,
  // written with the neighbour counts as weights so that the matrix is symmetric. Unlike a fixed
  // number of explicit passes it spreads a corner's direction over as far as epsilon asks.
  RowMatrixX3d implicitlySmoothed(const RowMatrixX3d& target, double epsilon) const {
    const Eigen::Index n = target.rows();
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::VectorXd degree(n);
    for (Eigen::Index p = 0; p < n; ++p) {
      const auto& near = neighbours_[static_cast<size_t>(p)];
      degree(p) = static_cast<double>(near.size());
      entries.emplace_back(p, p, (1.0 + epsilon) * degree(p));
      for (int q : near) entries.emplace_back(p, q, -epsilon);
    }
    Eigen::SparseMatrix<double> matrix(n, n);
    matrix.setFromTriplets(entries.begin(), entries.end());
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(matrix);
    if (solver.info() != Eigen::Success) throw SolverError("the implicit direction smoothing could not be factored");
    RowMatrixX3d smoothed = solver.solve(Eigen::MatrixXd(degree.asDiagonal() * target));
    for (Eigen::Index p = 0; p < n; ++p) {
      Vector3d d = smoothed.row(p).transpose();
      d = inPlanes(p, d);
      smoothed.row(p) = d.normalized().transpose();
    }
    return smoothed;
  }

  // One far-field step. The direction: the previous one blended with the front's normal, then
  // turned towards the domain boundary's normal (radial from the domain centre) by the share
  // `towardsDomain`, then smoothed implicitly. Without the turn, the directions behind a swept
  // sharp trailing edge keep pointing inboard (normal to the edge) and, with the edge's mirror
  // image, form a concave corner at the symmetry plane whose cells are squeezed flat uniformly
  // (which no scaled Jacobian notices) until the grid lines cross the plane.
  RowMatrixX3d marchOnce(const RowMatrixX3d& points, RowMatrixX3d& previous, double step, double progress,
                         double towardsDomain, int layer) const {
    RowMatrixX3d directions;
    RowMatrixX3d next = smoothedStep(points, previous, step, progress, towardsDomain, directions);
    next = repairPoorCells(points, std::move(next), directions,
                           Eigen::VectorXd::Constant(points.rows(), step), layer);
    previous = std::move(directions);
    return next;
  }

  // The smoothed step's points before the local repair, and their `directions`.
  RowMatrixX3d smoothedStep(const RowMatrixX3d& points, const RowMatrixX3d& previous, double step,
                            double progress, double towardsDomain, RowMatrixX3d& directions) const {
    const RowMatrixX3d normals = frontNormals(points);
    RowMatrixX3d blended(points.rows(), 3);
    for (Eigen::Index p = 0; p < points.rows(); ++p) {
      const Vector3d before = previous.row(p).transpose();
      const Vector3d normal = normals.row(p).transpose();
      const Vector3d local = normal.dot(before) > 0 ? (before + normal).normalized() : before;
      const Vector3d fromCentre = points.row(p).transpose() - options_.domain.centre;
      const Vector3d radial = fromCentre.norm() > 0 ? fromCentre.normalized() : local;
      blended.row(p) = ((1.0 - towardsDomain) * local + towardsDomain * radial).normalized().transpose();
    }
    directions = implicitlySmoothed(blended, options_.smoothing * (2.0 + 20.0 * progress));
    const int pointIterations = static_cast<int>(std::lround(options_.smoothing * (1.0 + 10.0 * progress)));
    const double weight = std::min(0.5, 0.2 + 0.3 * progress);
    RowMatrixX3d next = points + step * directions;
    keepOnPlane(next);
    smoothPoints(next, directions, pointIterations, weight);
    return next;
  }

  // The local repair's outcome: the points, the cells still poor (`poor` marks them) and whether
  // that is a fold (a cell not positive, or any poor cell without smoothing).
  struct Repaired {
    RowMatrixX3d points;
    PoorCells left;
    std::vector<char> poor;
    bool failed = false;
  };

  // One far-field step by the hyperbolic equations, then the same local repair as marchOnce's
  // along the step's own directions and lengths, which become `previous` (the smoothed step's
  // memory, should a later layer fall back to it): the layer's points, or, where the repaired
  // step still folds, the repaired step and its poor cells (nothing for a degenerate front).
  struct HyperbolicAttempt {
    std::optional<RowMatrixX3d> points;
    std::optional<Repaired> folded;
  };
  HyperbolicAttempt hyperbolicOnce(HyperbolicStepper& stepper, const RowMatrixX3d& below,
                                   const RowMatrixX3d& points, double step, double progress,
                                   RowMatrixX3d& previous) const {
    HyperbolicAttempt attempt;
    RowMatrixX3d next;
    try {
      next = stepper.advance(below, points, step, progress);
    } catch (const SolverError&) {
      return attempt;
    }
    const RowMatrixX3d moves = next - points;
    RowMatrixX3d directions = moves.rowwise().normalized();
    Repaired repaired = repairedPoorCells(points, std::move(next), directions, moves.rowwise().norm());
    if (repaired.failed) {
      attempt.folded = std::move(repaired);
    } else {
      previous = std::move(directions);
      attempt.points = std::move(repaired.points);
    }
    return attempt;
  }

  // A layer the hyperbolic step folds: the smoothed step, whose radial turn and point smoothing
  // open a convex corner's fold (a box's splayed corner), or the hyperbolic step with the smoothed
  // one taken round its folded cells alone (a wing-body's junction behind the trailing edge, which
  // the smoothed step folds and the hyperbolic one holds), whichever holds with the better worst
  // cell; failing both, the smoothed step's error.
  RowMatrixX3d smoothedOrBlended(const RowMatrixX3d& points, RowMatrixX3d& previous, double step,
                                 double progress, double towardsDomain, int layer,
                                 const HyperbolicAttempt& attempt) const {
    RowMatrixX3d smoothedDirections;
    const RowMatrixX3d stepped =
        smoothedStep(points, previous, step, progress, towardsDomain, smoothedDirections);
    std::optional<RowMatrixX3d> smoothed;
    std::exception_ptr smoothedFold;
    try {
      smoothed = repairPoorCells(points, stepped, smoothedDirections,
                                 Eigen::VectorXd::Constant(points.rows(), step), layer);
    } catch (const SolverError&) {
      smoothedFold = std::current_exception();
    }
    std::optional<RowMatrixX3d> blended;
    RowMatrixX3d blendedDirections;
    if (attempt.folded) {
      try {
        RowMatrixX3d next =
            blendedWithSmoothed(points, attempt.folded->points, attempt.folded->poor, stepped);
        const RowMatrixX3d moves = next - points;
        blendedDirections = moves.rowwise().normalized();
        blended = repairPoorCells(points, std::move(next), blendedDirections, moves.rowwise().norm(), layer);
      } catch (const SolverError&) {
      }
    }
    const double blendedWorst = blended ? worstCell(points, *blended) : 0.0;
    if (blended && blendedWorst >= options_.minScaledJacobian &&
        (!smoothed || blendedWorst > worstCell(points, *smoothed))) {
      previous = std::move(blendedDirections);
      return std::move(*blended);
    }
    if (!smoothed) std::rethrow_exception(smoothedFold);
    previous = std::move(smoothedDirections);
    return std::move(*smoothed);
  }

  // The hyperbolic step `next` with the smoothed step's points `smoothed` (before its repair) taken
  // instead round the cells it folds (the `poor` ones not positive): on their points and
  // kSmoothedRings rings of neighbours wholly, blended back over kBlendRings more.
  RowMatrixX3d blendedWithSmoothed(const RowMatrixX3d& points, const RowMatrixX3d& next,
                                   const std::vector<char>& poor, const RowMatrixX3d& smoothed) const {
    constexpr int kSmoothedRings = 2;
    constexpr int kBlendRings = 8;
    const Eigen::Index n = points.rows();
    std::vector<int> ring(static_cast<size_t>(n), -1);
    std::vector<int> current;
    for (size_t q = 0; q < front_.quads.size(); ++q) {
      if (poor[q] == 0 || cellQuality(points, next, q) > 0.0) continue;
      for (int p : front_.quads[q]) {
        if (ring[static_cast<size_t>(p)] < 0) current.push_back(p);
        ring[static_cast<size_t>(p)] = 0;
      }
    }
    for (int r = 1; r <= kSmoothedRings + kBlendRings && !current.empty(); ++r) {
      std::vector<int> reached;
      for (int p : current) {
        for (int q : neighbours_[static_cast<size_t>(p)]) {
          if (ring[static_cast<size_t>(q)] >= 0) continue;
          ring[static_cast<size_t>(q)] = r;
          reached.push_back(q);
        }
      }
      current = std::move(reached);
    }
    RowMatrixX3d blended = next;
    for (Eigen::Index p = 0; p < n; ++p) {
      const int r = ring[static_cast<size_t>(p)];
      if (r < 0) continue;
      const double share =
          std::clamp(1.0 - static_cast<double>(r - kSmoothedRings) / (kBlendRings + 1), 0.0, 1.0);
      blended.row(p) += share * (smoothed.row(p) - next.row(p));
    }
    keepOnPlane(blended);
    return blended;
  }

  // Where a cell between `points` and `next` would be poor, more smoothing of the directions and
  // points there alone; each repaired point moves `lengths` along its direction.
  RowMatrixX3d repairPoorCells(const RowMatrixX3d& points, RowMatrixX3d next, RowMatrixX3d& directions,
                               const Eigen::VectorXd& lengths, int layer) const {
    Repaired repaired = repairedPoorCells(points, std::move(next), directions, lengths);
    if (repaired.failed) {
      const double share = areaShare(points, repaired.left.where);
      const double median = medianAreaShare(points);
      fold(layer, repaired.left.worst, repaired.left.where, points,
           share > 0.0 && share < kConvergedAreaShare * median
               ? "after local smoothing: the layers converge there, its cell has " + numberText(share) +
                     " of its area on the wall where the layer's median cell has " + numberText(median) +
                     "; a concave groove or corner, which neither more smoothing nor a lower growth opens: "
                     "docs/volume.md, \"Not there yet\""
               : "after local smoothing: raise the smoothing, lower the growth or refine the wall there");
    }
    return std::move(repaired.points);
  }

  Repaired repairedPoorCells(const RowMatrixX3d& points, RowMatrixX3d next, RowMatrixX3d& directions,
                             const Eigen::VectorXd& lengths) const {
    for (int repair = 0;; ++repair) {
      std::vector<char> bad(front_.quads.size(), 0);
      const PoorCells cells = markPoorCells(points, next, bad);
      if (!cells.any || (repair >= kRepairs && cells.worst > 0.0))
        return {std::move(next), cells, std::move(bad), false};
      if (repair >= kRepairs || options_.smoothing == 0.0)
        return {std::move(next), cells, std::move(bad), true};
      const std::vector<char> marks = markAround(bad);
      smoothDirections(directions, 4, marks);
      for (Eigen::Index p = 0; p < points.rows(); ++p) {
        if (marks[static_cast<size_t>(p)] != 0) next.row(p) = points.row(p) + lengths[p] * directions.row(p);
      }
      keepOnPlane(next);
      smoothPoints(next, directions, 4, 0.5, marks);
    }
  }

  // A front cell's area over its wall cell's (0 for a fan's cell, collapsed on the wall).
  double areaShare(const RowMatrixX3d& points, int quad) const {
    const auto& q = front_.quads[static_cast<size_t>(quad)];
    const double wall = quadAreaVector(front_.points, q).norm();
    return wall > 0.0 ? quadAreaVector(points, q).norm() / wall : 0.0;
  }

  double medianAreaShare(const RowMatrixX3d& points) const {
    std::vector<double> shares;
    for (size_t q = 0; q < front_.quads.size(); ++q) {
      const double share = areaShare(points, static_cast<int>(q));
      if (share > 0.0) shares.push_back(share);
    }
    if (shares.empty()) return 0.0;
    const auto middle = shares.begin() + static_cast<std::ptrdiff_t>(shares.size() / 2);
    std::nth_element(shares.begin(), middle, shares.end());
    return *middle;
  }

  [[noreturn]] void fold(int layer, double worst, int quad, const RowMatrixX3d& points, const std::string& hint) const {
    const std::string where = quad >= 0 && static_cast<size_t>(quad) < front_.quadNames.size()
                                  ? front_.quadNames[static_cast<size_t>(quad)]
                                  : "wall cell " + std::to_string(quad);
    const Vector3d at = quad >= 0 ? Vector3d(points.row(front_.quads[static_cast<size_t>(quad)][0]).transpose())
                                  : Vector3d::Zero();
    throw SolverError("marching folds at layer " + std::to_string(layer) + " above " + where + " at (" +
                      coordinatesText(at) + ") (scaled Jacobian " + numberText(worst) + " " + hint + ")");
  }

  // Moves the outer layers onto the domain boundary: the last layer is projected onto it along the
  // rays from the domain centre, and each far-field layer takes the share of that move that its
  // distance gives.
  void blendOntoDomain(MarchingResult& result, int nBl) const {
    RowMatrixX3d& last = result.layers.back();
    RowMatrixX3d move(last.rows(), 3);
    for (Eigen::Index p = 0; p < last.rows(); ++p) {
      const Vector3d x = last.row(p).transpose();
      move.row(p) = (options_.domain.onBoundary(x) - x).transpose();
    }
    const double start = result.layerDistance[static_cast<size_t>(nBl)];
    const double span = result.layerDistance.back() - start;
    for (size_t k = static_cast<size_t>(nBl) + 1; k < result.layers.size(); ++k) {
      const double share = (result.layerDistance[k] - start) / span;
      result.layers[k] += share * move;
      keepOnPlane(result.layers[k]);
    }
  }

  const MarchingFront& front_;
  const MarchingOptions& options_;
  std::vector<std::vector<int>> neighbours_;
  std::vector<char> fanQuad_;                     // per quad: a knife edge's fan's
  double wallSize_ = 1.0;  // bounding-box diagonal: the distance over which the directions turn radial
};

}  // namespace

std::vector<std::vector<int>> frontNeighbours(const MarchingFront& front, bool withoutFans) {
  std::vector<char> fan(static_cast<size_t>(front.points.rows()), 0);
  if (withoutFans) {
    for (const FanPoint& point : front.fanPoints) fan[static_cast<size_t>(point.point)] = 1;
  }
  std::vector<std::set<int>> sets(static_cast<size_t>(front.points.rows()));
  for (const auto& quad : front.quads) {
    const auto [corners, size] = distinctCorners(quad);
    for (int e = 0; e < size; ++e) {
      const int a = corners[static_cast<size_t>(e)];
      const int b = corners[static_cast<size_t>((e + 1) % size)];
      if (fan[static_cast<size_t>(a)] != 0 || fan[static_cast<size_t>(b)] != 0) continue;
      sets[static_cast<size_t>(a)].insert(b);
      sets[static_cast<size_t>(b)].insert(a);
    }
  }
  std::vector<std::vector<int>> result(sets.size());
  for (size_t p = 0; p < sets.size(); ++p) result[p].assign(sets[p].begin(), sets[p].end());
  return result;
}

void turnFans(const MarchingFront& front, const BoundaryPlanes& planes, RowMatrixX3d& lines) {
  for (const FanPoint& fan : front.fanPoints) {
    Vector3d d = turnedBetween(lines.row(fan.from).transpose(), lines.row(fan.to).transpose(), fan.fraction,
                               fan.outside);
    if (front.planesAt(fan.point) != 0) d = planes.along(d, front.planesAt(fan.point)).normalized();
    lines.row(fan.point) = d.transpose();
  }
}

FarfieldScheme farfieldSchemeOf(const std::string& name) {
  if (name == "smoothed") return FarfieldScheme::Smoothed;
  if (name == "hyperbolic") return FarfieldScheme::Hyperbolic;
  throw InvalidInputError("far-field scheme must be 'smoothed' or 'hyperbolic', got '" + name + "'");
}

MarchingResult marchLayers(const MarchingFront& front, const MarchingOptions& options) {
  return Marcher(front, options).run();
}

}  // namespace bvmesh::volume

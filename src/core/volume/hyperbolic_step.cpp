#include "core/volume/hyperbolic_step.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/UmfPackSupport>
#include <unsupported/Eigen/IterativeSolvers>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>

#include "core/common/distinct_corners.h"
#include "core/common/errors.h"
#include "core/common/math_constants.h"
#include "core/common/number_text.h"

namespace bvmesh::volume {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Exponent of the explicit smoothing's growth with the marched share (Chan & Steger's S_l).
constexpr double kSmoothingGrowthExponent = 0.15;
// GMRES's budgets of iterations: a few tens where the smoothing preconditioner suits the step;
// a handful with an earlier pseudo-step's factor while the front has moved little since it, beyond
// which the factor is stale and the step is solved directly, which refreshes it.
constexpr int kSmoothingIterations = 60;
constexpr int kFactorIterations = 12;
// Ring edges more than this many times apart in length: the step's direction stays Fourier's.
constexpr double kGradedRing = 8.0;

// Eigen's preconditioner interface for one prepared before the solver runs (given by `use`):
// the solver's own analysis and factorisation calls do nothing.
template <typename Derived>
class PreparedPreconditioner {
 public:
  template <typename Matrix>
  Derived& analyzePattern(const Matrix&) {
    return static_cast<Derived&>(*this);
  }
  template <typename Matrix>
  Derived& factorize(const Matrix&) {
    return static_cast<Derived&>(*this);
  }
  template <typename Matrix>
  Derived& compute(const Matrix&) {
    return static_cast<Derived&>(*this);
  }
  Eigen::ComputationInfo info() const { return Eigen::Success; }
};

// GMRES preconditioner: the step's smoothing part alone, (1 + 4 eps_I) I - eps_I (4 / M) sum over the
// ring, the same for x, y and z (without the ghosts' mirrored terms). It depends on the front's
// topology only, so it is factored once; the orthogonality and volume coupling, at most about the
// pseudo-step over the edge length, is left to the iterations.
class SmoothingPreconditioner : public PreparedPreconditioner<SmoothingPreconditioner> {
 public:
  void use(const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>* factor,
           const Eigen::VectorXd* rowScale) {
    factor_ = factor;
    rowScale_ = rowScale;
  }
  template <typename Rhs>
  Eigen::VectorXd solve(const Eigen::MatrixBase<Rhs>& b) const {
    const Eigen::Index n = b.rows() / 3;
    const Eigen::MatrixXd byComponent =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(Eigen::VectorXd(b).data(),
                                                                                    n, 3);
    const Eigen::MatrixXd solvedByComponent = factor_->solve(rowScale_->asDiagonal() * byComponent);
    const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> solved = solvedByComponent;
    return Eigen::Map<const Eigen::VectorXd>(solved.data(), 3 * n);
  }

 private:
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>* factor_ = nullptr;
  const Eigen::VectorXd* rowScale_ = nullptr;
};

// GMRES preconditioner where the smoothing one stalls (pseudo-steps as long as the edges, whose
// coupling is as large as the smoothing): the direct factor of an earlier pseudo-step's matrix.
// Successive pseudo-steps move the front by a fraction of an edge, so their matrices differ little
// and one factor serves many of them.
using StepLU = Eigen::UmfPackLU<Eigen::SparseMatrix<double>>;

class FactorPreconditioner : public PreparedPreconditioner<FactorPreconditioner> {
 public:
  void use(const StepLU* factor) { factor_ = factor; }
  template <typename Rhs>
  Eigen::VectorXd solve(const Eigen::MatrixBase<Rhs>& b) const {
    return factor_->solve(b);
  }

 private:
  const StepLU* factor_ = nullptr;
};

struct FanEdge {
  int next;  // the quad's neighbour of the point that comes first counter-clockwise
  int prev;
};

}  // namespace

// UMFPACK's solves read the factored matrix itself, which Eigen's wrapper references, not copies.
// The step's pattern is symmetric (a neighbour's block both ways), hence UMFPACK's symmetric
// strategy, and a preconditioner's solve needs no iterative refinement: with both, marching a
// 4 250-point front with the factor as every step's preconditioner took 3.1 s against 8.2 s with
// UMFPACK's defaults and 4.6 s with Eigen's SparseLU.
struct HyperbolicStepper::StepFactor {
  explicit StepFactor(Eigen::SparseMatrix<double> factored) : matrix(std::move(factored)) {
    lu.umfpackControl()(UMFPACK_STRATEGY) = UMFPACK_STRATEGY_SYMMETRIC;
    lu.umfpackControl()(UMFPACK_IRSTEP) = 0;
    lu.compute(matrix);
  }
  Eigen::SparseMatrix<double> matrix;
  StepLU lu;
};

HyperbolicStepper::~HyperbolicStepper() = default;

HyperbolicStepper::HyperbolicStepper(Eigen::Index pointCount, const std::vector<std::array<int, 4>>& quads,
                                     const std::vector<unsigned char>& onPlanes, const BoundaryPlanes& planes,
                                     const HyperbolicOptions& options)
    : quads_(quads),
      onPlanes_(onPlanes),
      planes_(planes),
      options_(options),
      rings_(static_cast<size_t>(pointCount)) {
  if (onPlanes_.empty()) onPlanes_.assign(static_cast<size_t>(pointCount), 0);
  std::vector<std::vector<FanEdge>> fans(static_cast<size_t>(pointCount));
  for (const auto& quad : quads) {
    // A quad that repeats a corner (a knife edge's fan closing at its end) is a triangle.
    const auto [corners, size] = distinctCorners(quad);
    for (int k = 0; k < size; ++k) {
      fans[static_cast<size_t>(corners[static_cast<size_t>(k)])].push_back(
          {corners[static_cast<size_t>((k + 1) % size)],
           corners[static_cast<size_t>((k + size - 1) % size)]});
    }
  }
  for (Eigen::Index p = 0; p < pointCount; ++p) {
    const auto& fan = fans[static_cast<size_t>(p)];
    auto fail = [&](const char* what) {
      throw InvalidInputError(
          "front point " + std::to_string(p) + " " + what +
          ": hyperbolic marching needs a manifold front, closed or open only on its boundary planes");
    };
    if (fan.empty()) fail("lies in no cell");
    // An open fan starts at the neighbour no cell reaches counter-clockwise.
    int start = fan.front().next;
    bool open = false;
    for (const FanEdge& edge : fan) {
      const bool reached =
          std::any_of(fan.begin(), fan.end(), [&](const FanEdge& e) { return e.prev == edge.next; });
      if (!reached) {
        start = edge.next;
        open = true;
        break;
      }
    }
    const unsigned planesHere = onPlanes_[static_cast<size_t>(p)];
    if (open && planesHere == 0) fail("lies on an open boundary off the symmetry and outflow planes");
    auto& ring = rings_[static_cast<size_t>(p)];
    int current = start;
    for (size_t walked = 0; walked <= fan.size(); ++walked) {
      ring.push_back({current, 0});
      const auto edge =
          std::find_if(fan.begin(), fan.end(), [&](const FanEdge& e) { return e.next == current; });
      if (edge == fan.end()) break;
      current = edge->prev;
      if (!open && current == start) break;
    }
    if (ring.size() != fan.size() + (open ? 1 : 0)) fail("has cells that do not form one fan around it");
    if (open) {
      // Mirror images of the fan close the ring, each walked so that it stays counter-clockwise. On
      // one plane: the fan's image backwards. On two (perpendicular) planes the fan is a quarter
      // from its first neighbour (on one plane) to its last (on the other): then its image in the
      // last one's plane backwards, its image in both forwards, its image in the first one's backwards.
      const size_t real = ring.size();
      if (planeCount(planesHere) == 1) {
        for (size_t m = real - 2; m >= 1; --m)
          ring.push_back({ring[m].point, static_cast<unsigned char>(planesHere)});
      } else {
        const auto first =
            static_cast<unsigned char>(planesHere & onPlanes_[static_cast<size_t>(ring.front().point)]);
        const auto last =
            static_cast<unsigned char>(planesHere & onPlanes_[static_cast<size_t>(ring.back().point)]);
        if (planeCount(first) != 1 || planeCount(last) != 1 || first == last)
          fail("lies on both boundary planes, but its cells do not reach from one to the other");
        for (size_t m = real - 1; m-- > 0;) ring.push_back({ring[m].point, last});
        for (size_t m = 1; m < real; ++m)
          ring.push_back({ring[m].point, static_cast<unsigned char>(first | last)});
        for (size_t m = real - 1; m-- > 1;) ring.push_back({ring[m].point, first});
      }
    }
    if (ring.size() < 3) fail("has fewer than three neighbours around it");
    const auto valence = static_cast<double>(ring.size());
    for (size_t m = 0; m < ring.size(); ++m) {
      const double angle = 2.0 * kPi * static_cast<double>(m) / valence;
      ring[m].xiWeight = (2.0 / valence) * std::cos(angle);
      ring[m].etaWeight = (2.0 / valence) * std::sin(angle);
    }
  }
  // Rows scaled by M / 4 make the smoothing operator symmetric (a neighbour pair weighs -eps_I both ways).
  std::vector<Eigen::Triplet<double>> entries;
  smoothingRowScale_.resize(pointCount);
  for (Eigen::Index p = 0; p < pointCount; ++p) {
    const auto& ring = rings_[static_cast<size_t>(p)];
    smoothingRowScale_[p] = static_cast<double>(ring.size()) / 4.0;
    entries.emplace_back(p, p, smoothingRowScale_[p] * (1.0 + 4.0 * options_.implicitSmoothing));
    for (const RingEntry& entry : ring) {
      if (entry.mirror == 0) entries.emplace_back(p, entry.point, -options_.implicitSmoothing);
    }
  }
  Eigen::SparseMatrix<double> smoothing(pointCount, pointCount);
  smoothing.setFromTriplets(entries.begin(), entries.end());
  smoothingFactor_.compute(smoothing);
  if (smoothingFactor_.info() != Eigen::Success)
    throw SolverError("hyperbolic marching: the smoothing operator is singular");
}

Vector3d HyperbolicStepper::ringPoint(const RowMatrixX3d& points, const RingEntry& entry) const {
  const Vector3d x = points.row(entry.point).transpose();
  return entry.mirror == 0 ? x : planes_.mirrored(x, entry.mirror);
}

// Each quad's area shared equally by its distinct corners (a triangle's by three); a point on the
// boundary plane counts its mirrored cells too (three more on two planes).
Eigen::VectorXd HyperbolicStepper::nodeAreas(const RowMatrixX3d& points) const {
  Eigen::VectorXd area = Eigen::VectorXd::Zero(points.rows());
  for (const auto& q : quads_) {
    const Vector3d diagonal1 = (points.row(q[2]) - points.row(q[0])).transpose();
    const Vector3d diagonal2 = (points.row(q[3]) - points.row(q[1])).transpose();
    const auto [corners, size] = distinctCorners(q);
    const double share = 0.5 * diagonal1.cross(diagonal2).norm() / size;
    for (int k = 0; k < size; ++k) area[corners[static_cast<size_t>(k)]] += share;
  }
  for (Eigen::Index p = 0; p < area.rows(); ++p) {
    area[p] *= static_cast<double>(1 << planeCount(onPlanes_[static_cast<size_t>(p)]));
  }
  return area;
}

// A short edge of the front: its 10th percentile (a few sliver cells, such as a wing tip's
// trailing-edge corner, would otherwise set every pseudo-step).
double HyperbolicStepper::shortEdge(const RowMatrixX3d& points) const {
  std::vector<double> lengths;
  lengths.reserve(4 * quads_.size());
  for (const auto& q : quads_) {
    for (int k = 0; k < 4; ++k) {
      const double length =
          (points.row(q[static_cast<size_t>(k)]) - points.row(q[static_cast<size_t>((k + 1) % 4)])).norm();
      if (length > 0.0) lengths.push_back(length);  // a triangle's repeated corner is no edge
    }
  }
  const auto tenth = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 10);
  std::nth_element(lengths.begin(), tenth, lengths.end());
  return *tenth;
}

RowMatrixX3d HyperbolicStepper::advance(const RowMatrixX3d& below, const RowMatrixX3d& points,
                                        double thickness, double progress) {
  const double edge = shortEdge(points);
  const double wanted = edge > 0.0 ? std::ceil(thickness / (options_.maxStepToEdge * edge)) : 1.0;
  const int steps = static_cast<int>(std::clamp(wanted, 1.0, static_cast<double>(options_.maxPseudoSteps)));
  // A new layer's steps are longer: its first pseudo-step tries the smoothing preconditioner again.
  stepFactor_.reset();
  RowMatrixX3d before = below;
  RowMatrixX3d current = points;
  for (int s = 0; s < steps; ++s) {
    RowMatrixX3d next = pseudoStep(before, current, thickness / steps, progress);
    before = std::move(current);
    current = std::move(next);
  }
  return current;
}

template <typename Preconditioner>
bool HyperbolicStepper::solveIteratively(const Eigen::SparseMatrix<double>& matrix,
                                         const Eigen::VectorXd& rhs, double step,
                                         Eigen::VectorXd& delta) const {
  Eigen::GMRES<Eigen::SparseMatrix<double>, Preconditioner> solver;
  if constexpr (std::is_same_v<Preconditioner, FactorPreconditioner>) {
    solver.preconditioner().use(&stepFactor_->lu);
    solver.setMaxIterations(kFactorIterations);
  } else {
    solver.preconditioner().use(&smoothingFactor_, &smoothingRowScale_);
    solver.setMaxIterations(kSmoothingIterations);
  }
  solver.compute(matrix);
  if (lastSolution_.size() == rhs.size()) {
    // GMRES measures its residual against the first guess's: the tolerance that stops it at
    // solverTolerance of the right-hand side.
    const Eigen::VectorXd guess = (step / lastStep_) * lastSolution_;
    const double start = (rhs - matrix * guess).norm() / rhs.norm();
    solver.setTolerance(std::min(0.5, options_.solverTolerance / start));
    delta = solver.solveWithGuess(rhs, guess);
  } else {
    solver.setTolerance(options_.solverTolerance);
    delta = solver.solve(rhs);
  }
  return solver.info() == Eigen::Success && delta.allFinite();
}

RowMatrixX3d HyperbolicStepper::pseudoStep(const RowMatrixX3d& before, const RowMatrixX3d& points,
                                           double step, double progress) {
  const Eigen::Index n = points.rows();
  const Eigen::VectorXd area = nodeAreas(points);
  // Cell volumes: the step times the point's area, smoothed over the front (Jacobi passes).
  Eigen::VectorXd volume = step * area;
  for (int pass = 0; pass < options_.volumeSmoothingPasses; ++pass) {
    Eigen::VectorXd next(n);
    for (Eigen::Index p = 0; p < n; ++p) {
      double mean = 0.0;
      for (const RingEntry& entry : rings_[static_cast<size_t>(p)]) mean += volume[entry.point];
      mean /= static_cast<double>(rings_[static_cast<size_t>(p)].size());
      next[p] = (1.0 - options_.volumeSmoothing) * volume[p] + options_.volumeSmoothing * mean;
    }
    volume = std::move(next);
  }
  const double growth = std::pow(std::clamp(progress, 1e-3, 1.0), kSmoothingGrowthExponent);
  const double implicitWeight = options_.implicitSmoothing;
  const double coupling = 1.0 + options_.implicitCoupling;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(n) * 9 * 8);
  auto addBlock = [&](Eigen::Index row, Eigen::Index column, const Matrix3d& block) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        if (block(i, j) != 0.0) entries.emplace_back(3 * row + i, 3 * column + j, block(i, j));
      }
    }
  };
  Eigen::VectorXd rhs(3 * n);
  for (Eigen::Index p = 0; p < n; ++p) {
    const auto& ring = rings_[static_cast<size_t>(p)];
    const auto valence = static_cast<double>(ring.size());
    const Vector3d x = points.row(p).transpose();
    const Vector3d xBefore = before.row(p).transpose();
    Vector3d rXi = Vector3d::Zero(), rEta = Vector3d::Zero(), laplacian = Vector3d::Zero();
    Vector3d unitXi = Vector3d::Zero(), unitEta = Vector3d::Zero();
    double lengthBefore = 0.0, length = 0.0;
    double shortestEdge = std::numeric_limits<double>::infinity(), longestEdge = 0.0;
    for (const RingEntry& entry : ring) {
      const Vector3d d = ringPoint(points, entry) - x;
      const double edgeLength = d.norm();
      const Vector3d unit = d.normalized();
      rXi += entry.xiWeight * d;
      rEta += entry.etaWeight * d;
      unitXi += entry.xiWeight * unit;
      unitEta += entry.etaWeight * unit;
      laplacian += (4.0 / valence) * d;
      length += edgeLength;
      shortestEdge = std::min(shortestEdge, edgeLength);
      longestEdge = std::max(longestEdge, edgeLength);
      lengthBefore += (ringPoint(before, entry) - xBefore).norm();
    }
    const Vector3d sigma = rXi.cross(rEta);
    if (!(sigma.norm() > 1e-14 * rXi.norm() * rEta.norm()) || !(area[p] > 0.0)) {
      throw SolverError("hyperbolic marching: the front is degenerate at point " + std::to_string(p) + " (" +
                        coordinatesText(x) + ")");
    }
    // The step's direction. Fourier's normal sigma weighs the ring's triangles by their area, which
    // on a convex front leans it towards the side of longer edges (at the corners of a box whose
    // long faces have 2:1 cells, 16 degrees off the diagonal, and the first far-field layer folded
    // there); where the front is convex the ring's unit edges give it, each triangle weighed by its
    // angle. Not where it is concave, nor on a ring whose edges differ more than kGradedRing times
    // in length (a tiny block's edges beside a large one's): there the unit edges folded a
    // wing-body's layers earlier and a thin tip's corner cells (docs/volume.md, "Direction").
    const Vector3d unitNormal = unitXi.cross(unitEta);
    const bool angleWeighted =
        laplacian.dot(sigma) < 0.0 && longestEdge <= kGradedRing * shortestEdge && unitNormal.norm() > 1e-12;
    const Vector3d rZeta = (volume[p] / area[p]) * (angleWeighted ? unitNormal : sigma).normalized();
    Matrix3d pMatrix, q1, q2;
    pMatrix << rXi.transpose(), rEta.transpose(), sigma.transpose();
    q1 << rZeta.transpose(), Eigen::RowVector3d::Zero(), rEta.cross(rZeta).transpose();
    q2 << Eigen::RowVector3d::Zero(), rZeta.transpose(), rZeta.cross(rXi).transpose();
    const Matrix3d pInverse = pMatrix.inverse();
    const Matrix3d b1 = pInverse * q1;
    const Matrix3d b2 = pInverse * q2;
    // Explicit smoothing, stronger where the front converges (the grid sensor: neighbour distances
    // shrinking since the last step) and further out.
    const double sensor = std::max(std::pow(lengthBefore / length, 2.0 / growth), 0.1);
    const double stepToEdge = rZeta.norm() / std::sqrt(rXi.norm() * rEta.norm());
    const Vector3d dissipation = options_.explicitSmoothing * growth * sensor * stepToEdge * 0.5 * laplacian;
    rhs.segment<3>(3 * p) = rZeta + dissipation;
    addBlock(p, p, (1.0 + 4.0 * implicitWeight) * Matrix3d::Identity());
    for (const RingEntry& entry : ring) {
      Matrix3d block = coupling * (entry.xiWeight * b1 + entry.etaWeight * b2) -
                       implicitWeight * (4.0 / valence) * Matrix3d::Identity();
      if (entry.mirror != 0) block = block * planes_.mirrorMatrix(entry.mirror);
      addBlock(p, entry.point, block);
    }
  }
  Eigen::SparseMatrix<double> matrix(3 * n, 3 * n);
  matrix.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd delta;
  const bool solved = stepFactor_ ? solveIteratively<FactorPreconditioner>(matrix, rhs, step, delta)
                                  : solveIteratively<SmoothingPreconditioner>(matrix, rhs, step, delta);
  if (!solved) {
    // The iterations stalled (or the factor no longer suits the step): a direct solve, whose factor
    // preconditions the layer's next pseudo-steps.
    stepFactor_ = std::make_unique<StepFactor>(matrix);
    if (stepFactor_->lu.info() == Eigen::Success) delta = stepFactor_->lu.solve(rhs);
    if (stepFactor_->lu.info() != Eigen::Success || !delta.allFinite()) {
      stepFactor_.reset();
      throw SolverError(
          "hyperbolic marching: the step's linear system is singular (the front is degenerate)");
    }
  }
  // The linearised volume equation undershoots where the front expands (its cross terms count the
  // front's growth over the step twice, Barth's coupling more): the step is scaled back to the
  // asked mean length, which keeps every cell's shape.
  // (Weighted by each point's own area: a boundary-plane point's mirrored cells are not the front's.)
  double weightedLength = 0.0, frontArea = 0.0;
  for (Eigen::Index p = 0; p < n; ++p) {
    const double own = area[p] / static_cast<double>(1 << planeCount(onPlanes_[static_cast<size_t>(p)]));
    weightedLength += own * delta.segment<3>(3 * p).norm();
    frontArea += own;
  }
  const double scale = step * frontArea / weightedLength;
  lastSolution_ = delta;
  lastStep_ = step;
  RowMatrixX3d next = points;
  for (Eigen::Index p = 0; p < n; ++p) {
    Vector3d x = points.row(p).transpose() + scale * delta.segment<3>(3 * p);
    x = planes_.onto(x, onPlanes_[static_cast<size_t>(p)]);
    next.row(p) = x.transpose();
  }
  return next;
}

}  // namespace bvmesh::volume

// The iterative surface fitting (thesis 1.3.1, Fig. 1.1): a control mesh is subdivided, its limit
// surface sampled, the samples projected onto the CAD target and the control points re-fitted
// by least squares, level after level, until the limit surface is within tolerance of the target.
//
// SurfaceFitter holds target, control mesh and options and exposes every step on its own, so a
// user (GUI or script) can stop after any step, move vertices and go on; run() drives the steps.
// Each step first brings what it needs up to date (limit samples after a subdivision, projections
// after the control points moved), so steps can be called in any order.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/fit/least_squares.h"
#include "core/fit/smoothing.h"
#include "core/mesh/control_mesh.h"
#include "core/subdiv/limit_samples.h"
#include "core/subdiv/subdivision.h"
#include "core/target/target.h"

namespace bvmesh::fit {

// Which CAD geometry the features of the control mesh follow (from the initial polyhedron).
// A crease or boundary sample whose edge has no curve goes to the target's sharp edges (crease)
// or free boundary (boundary); a corner without a CAD vertex stays on its curves.
struct FeatureMap {
  std::vector<std::vector<int>> curves;  // CAD edge chains: lists of target edge ids
  std::vector<int> edgeCurve;            // #E: curve index per control-mesh edge, or -1 (or empty)
  std::vector<int> vertexCadVertex;      // #V: target vertex per control-mesh vertex, or -1 (or empty)
};

// Least-squares weight per kind of sample.
struct SampleWeights {
  double smooth = 1.0;
  double crease = 1.0;
  double boundary = 1.0;
  double corner = 1.0;
};

struct SymmetryPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
};

// The most approximation passes one parameter correction takes (each is a solve).
constexpr int kMaxCorrectionPasses = 100;

struct FitOptions {
  double tolerance = 0.0;           // absolute max sample distance to reach; 0: relativeTolerance
  double relativeTolerance = 1e-5;  // of the target's bounding-box diagonal
  int maxLevel = 5;                 // subdivision levels at most
  // A level whose control mesh would have more control points is not made (0: no limit): a memory
  // budget (about 18 kB a control point at the M6's level 5), so that a tight tolerance stops the
  // fit (StopReason::MemoryLimit) instead of running its process out of memory.
  int maxControlPoints = 0;
  int maxCorrections = 4;           // parameter-correction passes per level at most
  // A pass whose max distance is above this fraction of the previous one ends the level's
  // corrections (stagnation); the run ends when a whole level stagnates like that.
  double stagnationRatio = 0.9;
  LeastSquaresOptions solver;
  SampleWeights weights;
  std::vector<int> fixedVertices;   // control points the approximation keeps (ids of the current mesh)
  // Boundary control points within planeTolerance (relative to the diagonal) of this plane are
  // kept exactly on it (the root of a half model on its symmetry plane).
  std::optional<SymmetryPlane> symmetryPlane;
  double relativePlaneTolerance = 1e-6;
  bool projectAlongNormals = false;  // project along limit normals instead of to the closest point
  // Closest points whose target normal opposes the limit normal (the far side of a thin part,
  // e.g. a trailing-edge wedge) are replaced by the hit along the limit normal when that hit
  // faces the sample's way and is at most 4 times as far; otherwise the two sides of the part
  // pinch together.
  bool rejectOpposingFeet = true;
  int checkSamplesPerFace = 4;       // per direction, for the two-sided distance check; 0: none
  // The check's target side: points on the CAD surface this many times denser along each side of
  // the tessellation's triangles (Target::surfaceSamples; 1: the tessellation's nodes alone).
  int checkTargetSubdivisions = 1;
  SubdivisionOptions subdivision;
};

// Distances between limit surface and target measured on a denser independent sampling.
struct TwoSidedDistance {
  double limitToTarget = 0.0;  // max over limit surface points of the distance to the target
  double targetToLimit = 0.0;  // max over target points (tessellation nodes or denser) of the distance to the limit
  int targetPoints = 0;        // how many target points were measured
  Eigen::Vector3d limitToTargetAt = Eigen::Vector3d::Zero();  // the limit surface point of that max
  Eigen::Vector3d targetToLimitAt = Eigen::Vector3d::Zero();  // the target node of that max
  // A node on a CAD edge is only as precise as the edge's own tolerance (its faces may be that far
  // apart there): max over nodes of (distance - the CAD's tolerance at the node), at least 0, and
  // the node of that max. This, not targetToLimit, is held against the fitting tolerance.
  double targetToLimitBeyondCad = 0.0;
  Eigen::Vector3d targetToLimitBeyondCadAt = Eigen::Vector3d::Zero();
  double cadToleranceAtTargetToLimit = 0.0;  // the CAD's tolerance at targetToLimitAt

  // Both sides within `tolerance` (the target side beyond the CAD's own tolerance).
  bool within(double tolerance) const { return limitToTarget <= tolerance && targetToLimitBeyondCad <= tolerance; }
};

// One pass of the iteration: the state after a step, measured.
struct PassRecord {
  int level = 0;        // subdivision level (0 = the initial polyhedron)
  int correction = 0;   // approximation passes done at this level
  int controlPoints = 0;
  int samples = 0;
  int failedProjections = 0;
  double maxDistance = 0.0;  // limit samples to their projections
  double rmsDistance = 0.0;
  std::optional<TwoSidedDistance> check;
  double seconds = 0.0;      // wall time since the previous record
};

// Converged: the samples and the two-sided check (when checkSamplesPerFace > 0) are within the
// tolerance. CheckFailed: the samples are, the check is not, and no level is left. MemoryLimit:
// the next level would pass maxControlPoints.
enum class StopReason { Converged, Stagnated, MaxLevel, CheckFailed, Cancelled, MemoryLimit };

// "converged", "stagnated", "max_level", "check_failed", "cancelled" or "memory_limit".
const char* stopReasonName(StopReason reason);

struct FitSummary {
  StopReason reason = StopReason::MaxLevel;
  double tolerance = 0.0;  // the absolute tolerance used
  // Which distance is above the tolerance, by how much and where; empty when converged.
  std::string detail;
  std::vector<PassRecord> history;
};

// The summary's detail for a fit that stopped for `reason` in the state `last` records.
std::string stopDetail(StopReason reason, double tolerance, const PassRecord& last);

using ProgressCallback = std::function<void(const PassRecord&)>;

class SurfaceFitter {
public:
  // Throws InvalidInputError when the feature map does not fit the mesh or the target.
  SurfaceFitter(std::shared_ptr<const target::Target> target, ControlMesh mesh, FeatureMap features = {},
                FitOptions options = {});
  ~SurfaceFitter();
  SurfaceFitter(SurfaceFitter&&) noexcept;
  SurfaceFitter& operator=(SurfaceFitter&&) noexcept;

  const ControlMesh& mesh() const;
  // The control mesh as the fit left `level` (0 .. level()): the fit stopped there, as a run with
  // maxLevel `level` ends (the volume stage marches a fine wall's layers from a lower level).
  const ControlMesh& meshAtLevel(int level) const;
  const FeatureMap& features() const;
  const FitOptions& options() const;
  // Replaces the options (e.g. a tighter tolerance or more levels before run()); the sample
  // operators and the factorization are rebuilt on next use.
  void setOptions(FitOptions options);
  int level() const;
  double absoluteTolerance() const;
  // Moves the control points (same topology), e.g. after a user edit.
  void setVertices(const RowMatrixX3d& vertices);

  // Step 1: one subdivision level; features follow the children. Throws InvalidInputError past
  // maxLevel or maxControlPoints.
  void subdivide();
  // Why the next level may not be made within maxControlPoints ("level 4 would have ..."), or "".
  std::string overBudget() const;
  // Step 2: limit samples of the current mesh (operators built once per level).
  const LimitSamples& computeLimitSamples();
  // Step 3: projection of the current limit samples onto the target, by sample kind.
  const target::ProjectionResult& project();
  // Step 4: least squares on the last projections (factorization reused within the level).
  void approximate();
  // Steps 2-4 again at the same level, `passes` times.
  void correctParameters(int passes);
  // Taubin smoothing of the control points, crease-, corner-, boundary- and plane-aware.
  void smooth(const TaubinOptions& options);

  // Current limit sample positions (#S x 3) and their projections.
  const RowMatrixX3d& limitPositions();
  // Measures the current state (projecting if needed) and appends it to the history.
  const PassRecord& record(bool withCheck);
  // The check with checkTargetSubdivisions of the options unless targetSubdivisions > 0.
  TwoSidedDistance twoSidedDistance(int samplesPerFace, int targetSubdivisions = 0) const;
  const std::vector<PassRecord>& history() const;

  // Drives the steps until the tolerance, stagnation, maxLevel or a cancel request. Each
  // record is reported through `progress`. Cancelling leaves the fitter in the consistent state
  // after the last finished step.
  FitSummary run(const ProgressCallback& progress = {}, const std::atomic<bool>* cancel = nullptr);

private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace bvmesh::fit

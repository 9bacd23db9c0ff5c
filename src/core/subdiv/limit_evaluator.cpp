#include "core/subdiv/limit_evaluator.h"

#include <Eigen/Geometry>

#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>

#include <algorithm>
#include <atomic>
#include <string>

#include "core/common/errors.h"
#include "core/common/parallel.h"
#include "core/common/input_checks.h"
#include "core/subdiv/osd_refiner.h"

namespace bvmesh {

namespace Far = OpenSubdiv::Far;

struct LimitEvaluator::Impl {
  int numControlPoints = 0;
  int numPtexFaces = 0;
  std::unique_ptr<Far::PatchTable> patchTable;
  std::unique_ptr<Far::PatchMap> patchMap;
  // #P x #V: every patch point (control, refined and end-cap points) from the control points.
  RowSparseMatrix patchPoints;
};

LimitEvaluator::LimitEvaluator(const ControlMesh& mesh, const SubdivisionOptions& options,
                               int isolationLevel)
    : impl_(std::make_unique<Impl>()) {
  if (isolationLevel < 1 || isolationLevel > 10) {
    throw InvalidInputError("isolation level " + std::to_string(isolationLevel) +
                            " is outside 1..10");
  }
  impl_->numControlPoints = mesh.numVertices();
  impl_->numPtexFaces = ptexFaceOffsets(mesh).back();
  auto refiner = osd::createRefiner(mesh, options);

  Far::PatchTableFactory::Options patchOptions(static_cast<unsigned int>(isolationLevel));
  patchOptions.SetPatchPrecision<double>();
  patchOptions.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
  patchOptions.useInfSharpPatch = true;
  patchOptions.generateVaryingTables = false;
  patchOptions.generateVaryingLocalPoints = false;
  refiner->RefineAdaptive(patchOptions.GetRefineAdaptiveOptions());
  impl_->patchTable.reset(Far::PatchTableFactory::Create(*refiner, patchOptions));
  impl_->patchMap = std::make_unique<Far::PatchMap>(*impl_->patchTable);

  using StencilFactory = Far::StencilTableFactoryReal<double>;
  StencilFactory::Options stencilOptions;
  stencilOptions.generateOffsets = true;
  stencilOptions.generateControlVerts = true;
  stencilOptions.generateIntermediateLevels = true;
  stencilOptions.maxLevel = static_cast<unsigned int>(refiner->GetMaxLevel());
  std::unique_ptr<const Far::StencilTableReal<double>> stencils(
      StencilFactory::Create(*refiner, stencilOptions));
  const Far::StencilTableReal<double>* local =
      impl_->patchTable->GetLocalPointStencilTable<double>();
  if (local != nullptr && local->GetNumStencils() > 0) {
    stencils.reset(StencilFactory::AppendLocalPointStencilTable(*refiner, stencils.get(), local));
  }

  const auto& sizes = stencils->GetSizes();
  const auto& offsets = stencils->GetOffsets();
  const auto& indices = stencils->GetControlIndices();
  const auto& weights = stencils->GetWeights();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(weights.size());
  for (size_t s = 0; s < sizes.size(); ++s) {
    for (int k = offsets[s]; k < offsets[s] + sizes[s]; ++k) {
      triplets.emplace_back(static_cast<int>(s), indices[static_cast<size_t>(k)],
                            weights[static_cast<size_t>(k)]);
    }
  }
  impl_->patchPoints.resize(static_cast<Eigen::Index>(sizes.size()), mesh.numVertices());
  impl_->patchPoints.setFromTriplets(triplets.begin(), triplets.end());
}

LimitEvaluator::~LimitEvaluator() = default;
LimitEvaluator::LimitEvaluator(LimitEvaluator&&) noexcept = default;
LimitEvaluator& LimitEvaluator::operator=(LimitEvaluator&&) noexcept = default;

int LimitEvaluator::numControlPoints() const { return impl_->numControlPoints; }
int LimitEvaluator::numPtexFaces() const { return impl_->numPtexFaces; }

LimitEvaluation LimitEvaluator::evaluate(const RowMatrixX3d& controlPoints,
                                         const std::vector<SurfaceLocation>& locations) const {
  checkPointCount(controlPoints, impl_->numControlPoints);
  const auto count = static_cast<Eigen::Index>(locations.size());
  for (Eigen::Index q = 0; q < count; ++q) {
    const SurfaceLocation& location = locations[static_cast<size_t>(q)];
    if (location.face < 0 || location.face >= impl_->numPtexFaces) {
      throw InvalidInputError("location " + std::to_string(q) + ": ptex face " + std::to_string(location.face) +
                              " is outside 0.." + std::to_string(impl_->numPtexFaces - 1));
    }
    if (!(location.u >= 0.0 && location.u <= 1.0 && location.v >= 0.0 && location.v <= 1.0)) {
      throw InvalidInputError("location " + std::to_string(q) + ": (u, v) = (" + std::to_string(location.u) +
                              ", " + std::to_string(location.v) + ") is outside [0, 1]^2");
    }
  }
  const RowMatrixX3d points = impl_->patchPoints * controlPoints;
  LimitEvaluation result{RowMatrixX3d(count, 3), RowMatrixX3d(count, 3), RowMatrixX3d(count, 3),
                         RowMatrixX3d(count, 3)};
  // Each location reads the patch table and writes its own rows: large batches are split over
  // the hardware threads.
  std::atomic<Eigen::Index> missing{-1};
  const auto evaluateRange = [&](Eigen::Index begin, Eigen::Index end) {
    double wP[20], wDu[20], wDv[20];  // Gregory basis patches have the most points: 20
    for (Eigen::Index q = begin; q < end; ++q) {
      const SurfaceLocation& location = locations[static_cast<size_t>(q)];
      const Far::PatchTable::PatchHandle* handle = impl_->patchMap->FindPatch(location.face, location.u, location.v);
      if (handle == nullptr) {
        missing = q;
        return;
      }
      impl_->patchTable->EvaluateBasis(*handle, location.u, location.v, wP, wDu, wDv);
      const Far::ConstIndexArray cvs = impl_->patchTable->GetPatchVertices(*handle);
      Eigen::RowVector3d p = Eigen::RowVector3d::Zero(), du = p, dv = p;
      for (int k = 0; k < cvs.size(); ++k) {
        const auto row = points.row(cvs[k]);
        p += wP[k] * row;
        du += wDu[k] * row;
        dv += wDv[k] * row;
      }
      result.positions.row(q) = p;
      result.derivativesU.row(q) = du;
      result.derivativesV.row(q) = dv;
      const Eigen::RowVector3d n = du.cross(dv);
      const double length = n.norm();
      result.normals.row(q) = length > 0.0 ? Eigen::RowVector3d(n / length) : Eigen::RowVector3d::Zero();
    }
  };
  // Small batches on the calling thread alone: starting threads would cost more than they save.
  parallelChunks(count, count < 20000 ? count : 4096,
                 [&](std::int64_t begin, std::int64_t end) { evaluateRange(begin, end); });
  if (missing >= 0) {
    throw SolverError("location " + std::to_string(missing.load()) + ": OpenSubdiv has no patch at ptex face " +
                      std::to_string(locations[static_cast<size_t>(missing.load())].face));
  }
  return result;
}

}  // namespace bvmesh

#include "core/surface/limit_evaluator.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <mutex>
#include <string>
#include <thread>

#include "core/common/errors.h"

namespace bvmesh::surface {
namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

// OpenSubdiv reports errors through a callback that prints; the core turns them into exceptions.
void throwOpenSubdivError(Far::ErrorType, const char* message) {
  throw SolverError(std::string("OpenSubdiv: ") + (message != nullptr ? message : "unknown error"));
}

void installErrorCallback() {
  static std::once_flag once;
  std::call_once(once, [] { Far::SetErrorCallback(throwOpenSubdivError); });
}

// The point type OpenSubdiv's primvar refinement and stencils accumulate into.
struct Point3 {
  double x[3];
  void Clear() { x[0] = x[1] = x[2] = 0.0; }
  void AddWithWeight(const Point3& src, double weight) {
    x[0] += weight * src.x[0];
    x[1] += weight * src.x[1];
    x[2] += weight * src.x[2];
  }
};

}  // namespace

struct SubdivisionLimitSurface::Impl {
  std::unique_ptr<Far::TopologyRefiner> refiner;
  std::unique_ptr<Far::PatchTable> patches;
  std::unique_ptr<Far::PatchMap> patchMap;
  std::vector<int> ptexOfFace;
  std::vector<Point3> points;  // refined vertices of all levels, then the patch table's local points

  void evaluateRange(const std::vector<FaceLocation>& locations, size_t begin, size_t end, RowMatrixX3d& out,
                     RowMatrixX3d* du, RowMatrixX3d* dv) const {
    double w[20];
    double wu[20];
    double wv[20];
    for (size_t i = begin; i < end; ++i) {
      const FaceLocation& loc = locations[i];
      const double u = std::clamp(loc.u, 0.0, 1.0);
      const double v = std::clamp(loc.v, 0.0, 1.0);
      const Far::PatchTable::PatchHandle* handle =
          patchMap->FindPatch(ptexOfFace[static_cast<size_t>(loc.face)], u, v);
      if (handle == nullptr) {
        throw SolverError("no limit patch at face " + std::to_string(loc.face) + " (" + std::to_string(u) +
                          ", " + std::to_string(v) + ")");
      }
      patches->EvaluateBasis(*handle, u, v, w, wu, wv);
      const Far::ConstIndexArray cvs = patches->GetPatchVertices(*handle);
      double p[3] = {0, 0, 0};
      double pu[3] = {0, 0, 0};
      double pv[3] = {0, 0, 0};
      for (int k = 0; k < cvs.size(); ++k) {
        const Point3& c = points[static_cast<size_t>(cvs[k])];
        for (int d = 0; d < 3; ++d) {
          p[d] += w[k] * c.x[d];
          pu[d] += wu[k] * c.x[d];
          pv[d] += wv[k] * c.x[d];
        }
      }
      const auto row = static_cast<Eigen::Index>(i);
      out.row(row) << p[0], p[1], p[2];
      if (du != nullptr) {
        du->row(row) << pu[0], pu[1], pu[2];
        dv->row(row) << pv[0], pv[1], pv[2];
      }
    }
  }

  void evaluateAll(const std::vector<FaceLocation>& locations, RowMatrixX3d& out, RowMatrixX3d* du,
                   RowMatrixX3d* dv) const {
    const auto count = static_cast<Eigen::Index>(locations.size());
    const int faceCount = static_cast<int>(ptexOfFace.size());
    for (const FaceLocation& loc : locations) {
      if (loc.face < 0 || loc.face >= faceCount) {
        throw InvalidInputError("limit evaluation at face " + std::to_string(loc.face) + ", outside 0.." +
                                std::to_string(faceCount - 1));
      }
    }
    out.resize(count, 3);
    if (du != nullptr) {
      du->resize(count, 3);
      dv->resize(count, 3);
    }
    // Patch lookup and evaluation only read shared data: split large batches over threads.
    const size_t threadCount =
        locations.size() < 20000 ? 1 : std::max(1u, std::thread::hardware_concurrency());
    if (threadCount == 1) {
      evaluateRange(locations, 0, locations.size(), out, du, dv);
      return;
    }
    std::vector<std::thread> threads;
    std::vector<std::exception_ptr> errors(threadCount);
    const size_t chunk = (locations.size() + threadCount - 1) / threadCount;
    for (size_t t = 0; t < threadCount; ++t) {
      threads.emplace_back([&, t] {
        try {
          evaluateRange(locations, t * chunk, std::min(locations.size(), (t + 1) * chunk), out, du, dv);
        } catch (...) {
          errors[t] = std::current_exception();
        }
      });
    }
    for (auto& thread : threads) thread.join();
    for (auto& error : errors) {
      if (error) std::rethrow_exception(error);
    }
  }
};

SubdivisionLimitSurface::SubdivisionLimitSurface(const QuadControlMesh& mesh,
                                                 const SubdivisionLimitOptions& options)
    : impl_(std::make_unique<Impl>()) {
  validateQuadControlMesh(mesh);
  if (options.maxIsolationLevel < 1 || options.maxIsolationLevel > 10) {
    throw InvalidInputError("maxIsolationLevel " + std::to_string(options.maxIsolationLevel) +
                            " is outside 1..10");
  }
  installErrorCallback();
  const int faceCount = static_cast<int>(mesh.faces.rows());
  const int vertexCount = static_cast<int>(mesh.vertices.rows());
  std::vector<int> sizes(static_cast<size_t>(faceCount), 4);
  std::vector<Far::Index> indices(mesh.faces.data(), mesh.faces.data() + 4 * faceCount);
  std::vector<Far::Index> creasePairs(mesh.creases.data(), mesh.creases.data() + mesh.creases.size());
  std::vector<float> creaseWeights(static_cast<size_t>(mesh.creases.rows()), Sdc::Crease::SHARPNESS_INFINITE);
  std::vector<Far::Index> corners(mesh.corners.begin(), mesh.corners.end());
  std::vector<float> cornerWeights(corners.size(), Sdc::Crease::SHARPNESS_INFINITE);

  Far::TopologyDescriptor descriptor;
  descriptor.numVertices = vertexCount;
  descriptor.numFaces = faceCount;
  descriptor.numVertsPerFace = sizes.data();
  descriptor.vertIndicesPerFace = indices.data();
  descriptor.numCreases = static_cast<int>(mesh.creases.rows());
  descriptor.creaseVertexIndexPairs = creasePairs.data();
  descriptor.creaseWeights = creaseWeights.data();
  descriptor.numCorners = static_cast<int>(corners.size());
  descriptor.cornerVertexIndices = corners.data();
  descriptor.cornerWeights = cornerWeights.data();

  Sdc::Options sdcOptions;
  sdcOptions.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  sdcOptions.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  impl_->refiner.reset(Factory::Create(descriptor, Factory::Options(Sdc::SCHEME_CATMARK, sdcOptions)));
  if (!impl_->refiner) throw SolverError("OpenSubdiv could not build the topology of the control mesh");

  Far::PatchTableFactory::Options patchOptions(static_cast<unsigned>(options.maxIsolationLevel));
  patchOptions.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
  patchOptions.useInfSharpPatch = true;
  patchOptions.generateVaryingTables = false;
  patchOptions.SetPatchPrecision<double>();
  impl_->refiner->RefineAdaptive(patchOptions.GetRefineAdaptiveOptions());
  impl_->patches.reset(Far::PatchTableFactory::Create(*impl_->refiner, patchOptions));
  impl_->patchMap = std::make_unique<Far::PatchMap>(*impl_->patches);

  const Far::PtexIndices ptex(*impl_->refiner);
  impl_->ptexOfFace.resize(static_cast<size_t>(faceCount));
  for (int f = 0; f < faceCount; ++f) impl_->ptexOfFace[static_cast<size_t>(f)] = ptex.GetFaceId(f);

  const int refinedCount = impl_->refiner->GetNumVerticesTotal();
  const int localCount = impl_->patches->GetNumLocalPoints();
  impl_->points.resize(static_cast<size_t>(refinedCount + localCount));
  for (int v = 0; v < vertexCount; ++v) {
    for (int d = 0; d < 3; ++d) impl_->points[static_cast<size_t>(v)].x[d] = mesh.vertices(v, d);
  }
  Far::PrimvarRefinerReal<double> primvars(*impl_->refiner);
  Point3* source = impl_->points.data();
  for (int level = 1; level < impl_->refiner->GetNumLevels(); ++level) {
    Point3* destination = source + impl_->refiner->GetLevel(level - 1).GetNumVertices();
    primvars.Interpolate(level, source, destination);
    source = destination;
  }
  if (localCount > 0) {
    // PatchTable::ComputeLocalPointValues assumes single precision; use the double table directly.
    impl_->patches->GetLocalPointStencilTable<double>()->UpdateValues(impl_->points.data(),
                                                                      impl_->points.data() + refinedCount);
  }
}

SubdivisionLimitSurface::~SubdivisionLimitSurface() = default;

void SubdivisionLimitSurface::evaluate(const std::vector<FaceLocation>& locations,
                                       RowMatrixX3d& points) const {
  impl_->evaluateAll(locations, points, nullptr, nullptr);
}

void SubdivisionLimitSurface::evaluate(const std::vector<FaceLocation>& locations, RowMatrixX3d& points,
                                       RowMatrixX3d& du, RowMatrixX3d& dv) const {
  impl_->evaluateAll(locations, points, &du, &dv);
}

LimitEvaluator SubdivisionLimitSurface::evaluator() const {
  return [this](const std::vector<FaceLocation>& locations, RowMatrixX3d& points) {
    evaluate(locations, points);
  };
}

}  // namespace bvmesh::surface

#include "core/subdiv/osd_refiner.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/sdc/crease.h>

#include <mutex>
#include <string>

#include "core/common/errors.h"

namespace bvmesh::osd {
namespace {

void throwOsdError(Far::ErrorType /*type*/, const char* message) {
  throw TopologyError(std::string("OpenSubdiv: ") + message);
}

OpenSubdiv::Sdc::Options sdcOptions(const SubdivisionOptions& options) {
  using Sdc = OpenSubdiv::Sdc::Options;
  Sdc result;
  result.SetVtxBoundaryInterpolation(options.boundary == SubdivisionOptions::Boundary::EdgeOnly
                                         ? Sdc::VTX_BOUNDARY_EDGE_ONLY
                                         : Sdc::VTX_BOUNDARY_EDGE_AND_CORNER);
  result.SetCreasingMethod(options.creaseMethod == SubdivisionOptions::CreaseMethod::Chaikin
                               ? Sdc::CREASE_CHAIKIN
                               : Sdc::CREASE_UNIFORM);
  result.SetTriangleSubdivision(options.triangleRule == SubdivisionOptions::TriangleRule::Smooth
                                    ? Sdc::TRI_SUB_SMOOTH
                                    : Sdc::TRI_SUB_CATMARK);
  return result;
}

}  // namespace

void installErrorHandler() {
  static std::once_flag once;
  std::call_once(once, [] { Far::SetErrorCallback(&throwOsdError); });
}

float toOsdSharpness(double sharpness) {
  return sharpness >= OpenSubdiv::Sdc::Crease::SHARPNESS_INFINITE
             ? OpenSubdiv::Sdc::Crease::SHARPNESS_INFINITE
             : static_cast<float>(sharpness);
}

double fromOsdSharpness(float sharpness) {
  return OpenSubdiv::Sdc::Crease::IsInfinite(sharpness) ? kInfiniteSharpness
                                                        : static_cast<double>(sharpness);
}

std::unique_ptr<Far::TopologyRefiner> createRefiner(const ControlMesh& mesh,
                                                    const SubdivisionOptions& options) {
  installErrorHandler();
  std::vector<float> creaseWeights(static_cast<size_t>(mesh.creases().rows()));
  for (size_t c = 0; c < creaseWeights.size(); ++c) {
    creaseWeights[c] = toOsdSharpness(mesh.creaseSharpness()(static_cast<Eigen::Index>(c)));
  }
  std::vector<float> cornerWeights(mesh.corners().size());
  for (size_t c = 0; c < cornerWeights.size(); ++c) {
    cornerWeights[c] = toOsdSharpness(mesh.cornerSharpness()(static_cast<Eigen::Index>(c)));
  }
  Far::TopologyDescriptor descriptor;
  descriptor.numVertices = mesh.numVertices();
  descriptor.numFaces = mesh.numFaces();
  descriptor.numVertsPerFace = mesh.faceSizes().data();
  descriptor.vertIndicesPerFace = mesh.faceIndices().data();
  descriptor.numCreases = static_cast<int>(mesh.creases().rows());
  descriptor.creaseVertexIndexPairs = mesh.creases().data();
  descriptor.creaseWeights = creaseWeights.data();
  descriptor.numCorners = static_cast<int>(mesh.corners().size());
  descriptor.cornerVertexIndices = mesh.corners().data();
  descriptor.cornerWeights = cornerWeights.data();

  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  std::unique_ptr<Far::TopologyRefiner> refiner(Factory::Create(
      descriptor, Factory::Options(OpenSubdiv::Sdc::SCHEME_CATMARK, sdcOptions(options))));
  if (!refiner) throw TopologyError("OpenSubdiv could not build the control mesh topology");
  return refiner;
}

std::unique_ptr<Far::TopologyRefiner> createRefinedOnce(const ControlMesh& mesh,
                                                        const SubdivisionOptions& options) {
  auto refiner = createRefiner(mesh, options);
  Far::TopologyRefiner::UniformOptions uniform(1);
  uniform.fullTopologyInLastLevel = true;
  refiner->RefineUniform(uniform);
  return refiner;
}

std::vector<int> childVertexOrder(const Far::TopologyRefiner& refiner, const ControlMesh& mesh) {
  const Far::TopologyLevel& base = refiner.GetLevel(0);
  std::vector<int> order(static_cast<size_t>(refiner.GetLevel(1).GetNumVertices()), -1);
  for (int v = 0; v < mesh.numVertices(); ++v) {
    order[static_cast<size_t>(base.GetVertexChildVertex(v))] = v;
  }
  for (int e = 0; e < mesh.numEdges(); ++e) {
    const int osdEdge = base.FindEdge(mesh.edges()(e, 0), mesh.edges()(e, 1));
    order[static_cast<size_t>(base.GetEdgeChildVertex(osdEdge))] = mesh.numVertices() + e;
  }
  for (int f = 0; f < mesh.numFaces(); ++f) {
    order[static_cast<size_t>(base.GetFaceChildVertex(f))] =
        mesh.numVertices() + mesh.numEdges() + f;
  }
  return order;
}

RowSparseMatrix subdivisionOperator(const Far::TopologyRefiner& refiner,
                                    const std::vector<int>& childOrder) {
  using Factory = Far::StencilTableFactoryReal<double>;
  Factory::Options options;
  options.generateIntermediateLevels = false;
  options.generateOffsets = true;
  options.maxLevel = 1;
  std::unique_ptr<const Far::StencilTableReal<double>> table(Factory::Create(refiner, options));

  const auto& sizes = table->GetSizes();
  const auto& offsets = table->GetOffsets();
  const auto& indices = table->GetControlIndices();
  const auto& weights = table->GetWeights();
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(weights.size());
  for (size_t s = 0; s < sizes.size(); ++s) {
    const int row = childOrder[s];
    for (int k = offsets[s]; k < offsets[s] + sizes[s]; ++k) {
      triplets.emplace_back(row, indices[static_cast<size_t>(k)], weights[static_cast<size_t>(k)]);
    }
  }
  RowSparseMatrix result(static_cast<Eigen::Index>(sizes.size()),
                         refiner.GetLevel(0).GetNumVertices());
  result.setFromTriplets(triplets.begin(), triplets.end());
  return result;
}

}  // namespace bvmesh::osd

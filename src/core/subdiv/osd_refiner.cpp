#include "core/subdiv/osd_refiner.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/sdc/crease.h>

#include <algorithm>
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

RowBuilder::RowBuilder(int numRows, int numColumns, int expectedRowSize)
    : start_(static_cast<size_t>(numRows), 0),
      count_(static_cast<size_t>(numRows), 0),
      dense_(static_cast<size_t>(numColumns), 0.0),
      marked_(static_cast<size_t>(numColumns), false) {
  columns_.reserve(static_cast<size_t>(numRows) * static_cast<size_t>(expectedRowSize));
  weights_.reserve(static_cast<size_t>(numRows) * static_cast<size_t>(expectedRowSize));
}

void RowBuilder::begin(int row) {
  finish();
  current_ = row;
}

void RowBuilder::addRow(const RowBuilder& source, int row, double weight) {
  const auto r = static_cast<size_t>(row);
  for (int k = source.start_[r]; k < source.start_[r] + source.count_[r]; ++k) {
    add(source.columns_[static_cast<size_t>(k)], weight * source.weights_[static_cast<size_t>(k)]);
  }
}

void RowBuilder::finish() {
  if (current_ < 0) return;
  std::sort(touched_.begin(), touched_.end());
  start_[static_cast<size_t>(current_)] = static_cast<int>(columns_.size());
  count_[static_cast<size_t>(current_)] = static_cast<int>(touched_.size());
  for (int column : touched_) {
    columns_.push_back(column);
    weights_.push_back(dense_[static_cast<size_t>(column)]);
    dense_[static_cast<size_t>(column)] = 0.0;
    marked_[static_cast<size_t>(column)] = false;
  }
  touched_.clear();
  current_ = -1;
}

RowSparseMatrix RowBuilder::takeMatrix(const std::vector<int>& rowOrder) {
  const size_t rows = start_.size();
  std::vector<int> source(rows);
  for (size_t r = 0; r < rows; ++r) source[static_cast<size_t>(rowOrder[r])] = static_cast<int>(r);
  RowSparseMatrix result(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(dense_.size()));
  int* outer = result.outerIndexPtr();
  outer[0] = 0;
  for (size_t out = 0; out < rows; ++out) {
    outer[out + 1] = outer[out] + count_[static_cast<size_t>(source[out])];
  }
  // Rows that were built twice (replaced) leave unused entries behind; only the listed ones count.
  result.resizeNonZeros(outer[rows]);
  int* inner = result.innerIndexPtr();
  double* values = result.valuePtr();
  for (size_t out = 0; out < rows; ++out) {
    const auto r = static_cast<size_t>(source[out]);
    const auto first = static_cast<std::ptrdiff_t>(start_[r]);
    std::copy_n(columns_.begin() + first, count_[r], inner + outer[out]);
    std::copy_n(weights_.begin() + first, count_[r], values + outer[out]);
  }
  *this = RowBuilder(0, 0, 0);
  return result;
}

RowBuilder firstRefinementRows(const Far::TopologyRefiner& refiner) {
  const int numBase = refiner.GetLevel(0).GetNumVertices();
  const int numChildren = refiner.GetLevel(1).GetNumVertices();
  RowBuilder builder(numChildren, numBase, 7);  // quads: 4, 6 or 9 entries
  BuilderRows rows{&builder};
  Far::PrimvarRefinerReal<double>(refiner).Interpolate(1, VertexRefs{}, rows);
  builder.finish();
  return builder;
}

RowSparseMatrix subdivisionOperator(const Far::TopologyRefiner& refiner,
                                    const std::vector<int>& childOrder) {
  return firstRefinementRows(refiner).takeMatrix(childOrder);
}

}  // namespace bvmesh::osd

#include "core/subdiv/limit_samples.h"

#include <Eigen/Geometry>

#include <opensubdiv/far/primvarRefiner.h>

#include <string>

#include "core/common/errors.h"
#include "core/subdiv/osd_refiner.h"

namespace bvmesh {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Primvar types that make OpenSubdiv's PrimvarRefiner::Limit write its masks as matrix rows:
// a source "value" is a refined vertex index, a destination records weighted indices.
struct VertexRef {
  int index;
};

class MaskRow {
public:
  MaskRow(Triplets* out, const std::vector<int>* order, int row)
      : out_(out), order_(order), row_(row) {}
  void Clear() {}
  void AddWithWeight(const VertexRef& source, double weight) {
    out_->emplace_back(row_, (*order_)[static_cast<size_t>(source.index)], weight);
  }

private:
  Triplets* out_;
  const std::vector<int>* order_;
  int row_;
};

RowSparseMatrix fromTriplets(const Triplets& triplets, Eigen::Index size) {
  RowSparseMatrix result(size, size);
  result.setFromTriplets(triplets.begin(), triplets.end());
  return result;
}

}  // namespace

LimitSamples::LimitSamples(const ControlMesh& mesh, const SubdivisionOptions& options) {
  const auto refiner = osd::createRefinedOnce(mesh, options);
  const std::vector<int> order = osd::childVertexOrder(*refiner, mesh);
  const RowSparseMatrix subdivision = osd::subdivisionOperator(*refiner, order);

  // Limit masks of the refined vertices, rows and columns in our child order (which is also the
  // sample order: vertices, edges, faces).
  const size_t count = order.size();
  std::vector<VertexRef> sources(count);
  for (size_t i = 0; i < count; ++i) sources[i].index = static_cast<int>(i);
  Triplets position, tangent1, tangent2;
  position.reserve(10 * count);
  tangent1.reserve(10 * count);
  tangent2.reserve(10 * count);
  std::vector<MaskRow> rowsP, rowsT1, rowsT2;
  rowsP.reserve(count);
  rowsT1.reserve(count);
  rowsT2.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    rowsP.emplace_back(&position, &order, order[i]);
    rowsT1.emplace_back(&tangent1, &order, order[i]);
    rowsT2.emplace_back(&tangent2, &order, order[i]);
  }
  OpenSubdiv::Far::PrimvarRefinerReal<double>(*refiner).Limit(sources, rowsP, rowsT1, rowsT2);

  const auto size = static_cast<Eigen::Index>(count);
  positionOperator_ = fromTriplets(position, size) * subdivision;
  tangentU_ = fromTriplets(tangent1, size) * subdivision;
  tangentV_ = fromTriplets(tangent2, size) * subdivision;

  // Sample descriptions in the same order.
  const std::vector<int> ptex = ptexFaceOffsets(mesh);
  const osd::Far::TopologyLevel& base = refiner->GetLevel(0);
  elements_.reserve(count);
  features_.reserve(count);
  locations_.reserve(count);
  sourceIds_.resize(size);
  sourceVertices_.resize(size, 2);
  Eigen::Index s = 0;
  for (int v = 0; v < mesh.numVertices(); ++v, ++s) {
    SampleFeature feature = SampleFeature::Smooth;
    switch (base.GetVertexRule(v)) {
      case OpenSubdiv::Sdc::Crease::RULE_CORNER:
        feature = SampleFeature::Corner;
        break;
      case OpenSubdiv::Sdc::Crease::RULE_CREASE:
        feature = base.IsVertexBoundary(v) ? SampleFeature::Boundary : SampleFeature::Crease;
        break;
      default:
        break;
    }
    elements_.push_back(SampleElement::Vertex);
    features_.push_back(feature);
    sourceIds_(s) = v;
    sourceVertices_.row(s) << v, -1;
    locations_.push_back(cornerLocation(mesh, ptex, mesh.vertexFirstCorner()(v, 0),
                                        mesh.vertexFirstCorner()(v, 1)));
  }
  // The corner of its first face at which each edge starts.
  std::vector<int> edgeCorner(static_cast<size_t>(mesh.numEdges()), -1);
  for (int f = 0; f < mesh.numFaces(); ++f) {
    for (int i = 0; i < mesh.faceSize(f); ++i) {
      const int e = mesh.faceEdge(f, i);
      if (mesh.edgeFaces()(e, 0) == f) edgeCorner[static_cast<size_t>(e)] = i;
    }
  }
  for (int e = 0; e < mesh.numEdges(); ++e, ++s) {
    elements_.push_back(SampleElement::Edge);
    features_.push_back(mesh.isBoundaryEdge(e)         ? SampleFeature::Boundary
                        : mesh.edgeSharpness()(e) > 0.0 ? SampleFeature::Crease
                                                        : SampleFeature::Smooth);
    sourceIds_(s) = e;
    sourceVertices_.row(s) = mesh.edges().row(e);
    locations_.push_back(
        edgeMidpointLocation(mesh, ptex, mesh.edgeFaces()(e, 0), edgeCorner[static_cast<size_t>(e)]));
  }
  for (int f = 0; f < mesh.numFaces(); ++f, ++s) {
    elements_.push_back(SampleElement::Face);
    features_.push_back(SampleFeature::Smooth);
    sourceIds_(s) = f;
    sourceVertices_.row(s) << -1, -1;
    locations_.push_back(faceCentreLocation(mesh, ptex, f));
  }
}

void LimitSamples::checkControlPoints(const RowMatrixX3d& controlPoints) const {
  if (controlPoints.rows() != numControlPoints()) {
    throw InvalidInputError("expected " + std::to_string(numControlPoints()) +
                            " x 3 control points, got " + std::to_string(controlPoints.rows()) +
                            " x 3");
  }
}

RowMatrixX3d LimitSamples::positions(const RowMatrixX3d& controlPoints) const {
  checkControlPoints(controlPoints);
  return positionOperator_ * controlPoints;
}

RowMatrixX3d LimitSamples::normals(const RowMatrixX3d& controlPoints) const {
  checkControlPoints(controlPoints);
  const RowMatrixX3d du = tangentU_ * controlPoints;
  const RowMatrixX3d dv = tangentV_ * controlPoints;
  RowMatrixX3d result(du.rows(), 3);
  for (Eigen::Index i = 0; i < du.rows(); ++i) {
    const Eigen::Vector3d n = du.row(i).transpose().cross(dv.row(i).transpose());
    const double length = n.norm();
    result.row(i) = length > 0.0 ? Eigen::RowVector3d((n / length).transpose()) : Eigen::RowVector3d::Zero();
  }
  return result;
}

}  // namespace bvmesh

#include "core/subdiv/limit_samples.h"

#include <Eigen/Geometry>

#include <opensubdiv/far/primvarRefiner.h>

#include <string>

#include "core/common/errors.h"
#include "core/subdiv/osd_refiner.h"

namespace bvmesh {

LimitSamples::LimitSamples(const ControlMesh& mesh, const SubdivisionOptions& options) {
  const auto refiner = osd::createRefinedOnce(mesh, options);
  const std::vector<int> order = osd::childVertexOrder(*refiner, mesh);
  const osd::RowBuilder subdivision = osd::firstRefinementRows(*refiner);

  // Limit masks of the refined vertices composed with the refinement rows: sample i (in our
  // child order, which is also the sample order: vertices, edges, faces) is the limit of
  // refined vertex i.
  const size_t count = order.size();
  const auto numRows = static_cast<int>(count);
  const int numBase = mesh.numVertices();
  // A regular sample depends on 16 control points (one bicubic patch).
  osd::RowBuilder position(numRows, numBase, 16), tangent1(numRows, numBase, 16),
      tangent2(numRows, numBase, 16);
  osd::ComposedRows rowsP{&position, &subdivision}, rowsT1{&tangent1, &subdivision},
      rowsT2{&tangent2, &subdivision};
  OpenSubdiv::Far::PrimvarRefinerReal<double>(*refiner).Limit(osd::VertexRefs{}, rowsP, rowsT1, rowsT2);
  position.finish();
  tangent1.finish();
  tangent2.finish();
  positionOperator_ = position.takeMatrix(order);
  tangentU_ = tangent1.takeMatrix(order);
  tangentV_ = tangent2.takeMatrix(order);

  // Sample descriptions in the same order.
  const std::vector<int> ptex = ptexFaceOffsets(mesh);
  const osd::Far::TopologyLevel& base = refiner->GetLevel(0);
  elements_.reserve(count);
  features_.reserve(count);
  locations_.reserve(count);
  sourceIds_.resize(numRows);
  sourceVertices_.resize(numRows, 2);
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

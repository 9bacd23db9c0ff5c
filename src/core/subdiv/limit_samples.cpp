#include "core/subdiv/limit_samples.h"

#include <Eigen/Geometry>

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>

#include <memory>
#include <string>
#include <utility>

#include "core/common/errors.h"
#include "core/common/input_checks.h"
#include "core/subdiv/osd_refiner.h"

namespace bvmesh {
namespace {

namespace Far = OpenSubdiv::Far;

// OpenSubdiv's limit masks assume that a vertex and its incident edges keep their rules at every
// level. That fails at darts (a smooth vertex on one crease edge, whose edge point follows the
// crease rule) and wherever sharpness is semi-sharp. The rows of those refined vertices are
// replaced by limit stencils of the adaptively refined patch table at the samples' locations.
void replaceInexactRows(const ControlMesh& mesh, const SubdivisionOptions& options,
                        const Far::TopologyRefiner& refined, const std::vector<int>& order,
                        const std::vector<SurfaceLocation>& locations, osd::RowBuilder& position,
                        osd::RowBuilder& tangentU, osd::RowBuilder& tangentV) {
  const Far::TopologyLevel& level = refined.GetLevel(1);
  std::vector<int> inexact;
  for (int v = 0; v < level.GetNumVertices(); ++v) {
    bool semiSharp = level.IsVertexSemiSharp(v);
    for (const int e : level.GetVertexEdges(v)) semiSharp = semiSharp || level.IsEdgeSemiSharp(e);
    if (semiSharp || level.GetVertexRule(v) == OpenSubdiv::Sdc::Crease::RULE_DART) {
      inexact.push_back(v);
    }
  }
  if (inexact.empty()) return;

  const auto adaptive = osd::createRefiner(mesh, options);
  Far::TopologyRefiner::AdaptiveOptions adaptiveOptions(10);
  adaptiveOptions.useInfSharpPatch = true;
  adaptive->RefineAdaptive(adaptiveOptions);
  std::vector<double> u, v;
  u.reserve(inexact.size());
  v.reserve(inexact.size());
  for (const int vertex : inexact) {
    const SurfaceLocation& at = locations[static_cast<size_t>(order[static_cast<size_t>(vertex)])];
    u.push_back(at.u);
    v.push_back(at.v);
  }
  using Factory = Far::LimitStencilTableFactoryReal<double>;
  Factory::LocationArrayVec arrays(inexact.size());
  for (size_t i = 0; i < inexact.size(); ++i) {
    arrays[i].ptexIdx = locations[static_cast<size_t>(order[static_cast<size_t>(inexact[i])])].face;
    arrays[i].numLocations = 1;
    arrays[i].s = &u[i];
    arrays[i].t = &v[i];
  }
  const std::unique_ptr<const Far::LimitStencilTableReal<double>> table(
      Factory::Create(*adaptive, arrays));
  const auto& sizes = table->GetSizes();
  const auto& offsets = table->GetOffsets();
  const auto& indices = table->GetControlIndices();
  for (size_t i = 0; i < inexact.size(); ++i) {
    for (auto [builder, weights] :
         {std::pair{&position, &table->GetWeights()}, std::pair{&tangentU, &table->GetDuWeights()},
          std::pair{&tangentV, &table->GetDvWeights()}}) {
      builder->begin(inexact[i]);
      for (int k = offsets[i]; k < offsets[i] + sizes[i]; ++k) {
        builder->add(indices[static_cast<size_t>(k)], (*weights)[static_cast<size_t>(k)]);
      }
    }
  }
}

}  // namespace

LimitSamples::LimitSamples(const ControlMesh& mesh, const SubdivisionOptions& options) {
  const auto refiner = osd::createRefinedOnce(mesh, options);
  const std::vector<int> order = osd::childVertexOrder(*refiner, mesh);
  const size_t count = order.size();
  const auto numRows = static_cast<int>(count);

  // Sample descriptions: vertices, edges, faces.
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
    locations_.push_back(
        cornerLocation(mesh, ptex, mesh.vertexFirstCorner()(v, 0), mesh.vertexFirstCorner()(v, 1)));
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
    features_.push_back(mesh.isBoundaryEdge(e)          ? SampleFeature::Boundary
                        : mesh.edgeSharpness()(e) > 0.0 ? SampleFeature::Crease
                                                        : SampleFeature::Smooth);
    sourceIds_(s) = e;
    sourceVertices_.row(s) = mesh.edges().row(e);
    locations_.push_back(edgeMidpointLocation(mesh, ptex, mesh.edgeFaces()(e, 0),
                                              edgeCorner[static_cast<size_t>(e)]));
  }
  for (int f = 0; f < mesh.numFaces(); ++f, ++s) {
    elements_.push_back(SampleElement::Face);
    features_.push_back(SampleFeature::Smooth);
    sourceIds_(s) = f;
    sourceVertices_.row(s) << -1, -1;
    locations_.push_back(faceCentreLocation(mesh, ptex, f));
  }

  const osd::RowBuilder subdivision = osd::firstRefinementRows(*refiner);

  // Limit masks of the refined vertices composed with the refinement rows: sample i (in our
  // child order, which is also the sample order: vertices, edges, faces) is the limit of
  // refined vertex i.
  const int numBase = mesh.numVertices();
  // A regular sample depends on 16 control points (one bicubic patch).
  osd::RowBuilder position(numRows, numBase, 16), tangent1(numRows, numBase, 16),
      tangent2(numRows, numBase, 16);
  osd::ComposedRows rowsP{&position, &subdivision}, rowsT1{&tangent1, &subdivision},
      rowsT2{&tangent2, &subdivision};
  OpenSubdiv::Far::PrimvarRefinerReal<double>(*refiner).Limit(osd::VertexRefs{}, rowsP, rowsT1,
                                                              rowsT2);
  replaceInexactRows(mesh, options, *refiner, order, locations_, position, tangent1, tangent2);
  position.finish();
  tangent1.finish();
  tangent2.finish();
  positionOperator_ = position.takeMatrix(order);
  tangentU_ = tangent1.takeMatrix(order);
  tangentV_ = tangent2.takeMatrix(order);
}

RowMatrixX3d LimitSamples::positions(const RowMatrixX3d& controlPoints) const {
  checkPointCount(controlPoints, numControlPoints());
  return positionOperator_ * controlPoints;
}

RowMatrixX3d LimitSamples::normals(const RowMatrixX3d& controlPoints) const {
  checkPointCount(controlPoints, numControlPoints());
  const RowMatrixX3d du = tangentU_ * controlPoints;
  const RowMatrixX3d dv = tangentV_ * controlPoints;
  RowMatrixX3d result(du.rows(), 3);
  for (Eigen::Index i = 0; i < du.rows(); ++i) {
    const Eigen::Vector3d n = du.row(i).transpose().cross(dv.row(i).transpose());
    const double length = n.norm();
    result.row(i) =
        length > 0.0 ? Eigen::RowVector3d((n / length).transpose()) : Eigen::RowVector3d::Zero();
  }
  return result;
}

}  // namespace bvmesh

#include "core/subdiv/subdivision.h"

#include <array>
#include <utility>
#include <vector>

#include "core/subdiv/osd_refiner.h"

namespace bvmesh {

SubdivisionResult subdivide(const ControlMesh& mesh, const SubdivisionOptions& options) {
  const auto refiner = osd::createRefinedOnce(mesh, options);
  const std::vector<int> order = osd::childVertexOrder(*refiner, mesh);
  std::vector<int> osdIndex(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    osdIndex[static_cast<size_t>(order[i])] = static_cast<int>(i);
  }

  RowSparseMatrix op = osd::subdivisionOperator(*refiner, order);
  RowMatrixX3d vertices = op * mesh.vertices();

  const int edgeBase = mesh.numVertices();
  const int faceBase = mesh.numVertices() + mesh.numEdges();
  const size_t numChildren = mesh.faceIndices().size();
  std::vector<int> faceSizes(numChildren, 4);
  std::vector<int> faceIndices;
  faceIndices.reserve(4 * numChildren);
  for (int f = 0; f < mesh.numFaces(); ++f) {
    const int size = mesh.faceSize(f);
    for (int i = 0; i < size; ++i) {
      faceIndices.push_back(mesh.faceVertex(f, i));
      faceIndices.push_back(edgeBase + mesh.faceEdge(f, i));
      faceIndices.push_back(faceBase + f);
      faceIndices.push_back(edgeBase + mesh.faceEdge(f, (i + size - 1) % size));
    }
  }

  // Sharpness of the children as OpenSubdiv decays it; children that became smooth are dropped.
  const osd::Far::TopologyLevel& child = refiner->GetLevel(1);
  std::vector<std::pair<std::array<int, 2>, double>> creases;
  for (int e : mesh.creaseEdges()) {
    const int mid = edgeBase + e;
    for (int end = 0; end < 2; ++end) {
      const int v = mesh.edges()(e, end);
      const int osdEdge =
          child.FindEdge(osdIndex[static_cast<size_t>(v)], osdIndex[static_cast<size_t>(mid)]);
      const double sharpness = osd::fromOsdSharpness(child.GetEdgeSharpness(osdEdge));
      if (sharpness > 0.0) {
        creases.push_back(
            {end == 0 ? std::array<int, 2>{v, mid} : std::array<int, 2>{mid, v}, sharpness});
      }
    }
  }
  RowMatrixX2i creasePairs(static_cast<Eigen::Index>(creases.size()), 2);
  Eigen::VectorXd creaseSharpness(static_cast<Eigen::Index>(creases.size()));
  for (size_t c = 0; c < creases.size(); ++c) {
    const auto row = static_cast<Eigen::Index>(c);
    creasePairs.row(row) << creases[c].first[0], creases[c].first[1];
    creaseSharpness(row) = creases[c].second;
  }
  std::vector<int> corners;
  std::vector<double> cornerSharpness;
  for (int v : mesh.corners()) {
    const double sharpness =
        osd::fromOsdSharpness(child.GetVertexSharpness(osdIndex[static_cast<size_t>(v)]));
    if (sharpness > 0.0) {
      corners.push_back(v);
      cornerSharpness.push_back(sharpness);
    }
  }

  ControlMesh refined(
      std::move(vertices), std::move(faceSizes), std::move(faceIndices), std::move(creasePairs),
      std::move(creaseSharpness), std::move(corners),
      Eigen::Map<const Eigen::VectorXd>(cornerSharpness.data(),
                                        static_cast<Eigen::Index>(cornerSharpness.size())));
  return {std::move(refined), std::move(op)};
}

}  // namespace bvmesh

// Iteration step 2: samples of the Catmull-Clark limit surface of a control mesh at every
// vertex, every edge midpoint and every face centre, as fixed linear operators of the control
// points (l = A p), built once per topology and reused for any positions p.
//
// The samples are the limit positions of the vertices of the once more subdivided mesh. They
// are computed with OpenSubdiv: one uniform refinement (the subdivision operator S) composed
// with OpenSubdiv's vertex limit masks on the refined mesh (L), A = L S; the tangent operators
// likewise. The limit masks are exact for smooth surfaces, extraordinary vertices, boundaries,
// corners and infinitely sharp creases. They are not exact at darts (a vertex ending a single
// crease edge inside the surface) and around semi-sharp creases; the rows of those samples come
// from OpenSubdiv's limit stencils on the adaptively refined patch table instead (isolation
// level 10, Gregory end patches).
#pragma once

#include <cstdint>
#include <vector>

#include "core/mesh/control_mesh.h"
#include "core/subdiv/subdivision.h"
#include "core/subdiv/surface_location.h"

namespace bvmesh {

// Which mesh element a sample belongs to.
enum class SampleElement : std::uint8_t { Vertex = 0, Edge = 1, Face = 2 };
// What the limit surface does at the sample: smooth, on a crease curve, on a boundary curve, or
// at a corner (explicit corner, boundary vertex with one face, or meeting point of more than two
// crease/boundary edges). Face samples are always smooth; dart vertices (one crease edge) too.
enum class SampleFeature : std::uint8_t { Smooth = 0, Crease = 1, Boundary = 2, Corner = 3 };

class LimitSamples {
public:
  // Builds the operators for the mesh's topology (the positions are not used).
  explicit LimitSamples(const ControlMesh& mesh, const SubdivisionOptions& options = {});

  // #S = #V + #E + #F samples, always in this order: vertex 0..#V-1, edge 0..#E-1 (midpoints),
  // face 0..#F-1 (centres).
  int size() const { return static_cast<int>(elements_.size()); }
  int numControlPoints() const { return static_cast<int>(positionOperator_.cols()); }

  // #S x #V: limit positions = positionOperator() * control points.
  const RowSparseMatrix& positionOperator() const { return positionOperator_; }
  // #S x #V each: two limit tangents (not normalized, not orthogonal) whose cross product points
  // to the side the faces are oriented to.
  const RowSparseMatrix& tangentOperatorU() const { return tangentU_; }
  const RowSparseMatrix& tangentOperatorV() const { return tangentV_; }

  // #S x 3 limit positions for #V x 3 control points.
  RowMatrixX3d positions(const RowMatrixX3d& controlPoints) const;
  // #S x 3 unit limit normals for #V x 3 control points (zero where the tangents are parallel).
  // On a crease the normal is one-sided: OpenSubdiv's crease tangent masks run the first tangent
  // along the crease and the second into one of the two sides (seen to be the side of the
  // vertex's first face), so for the normals on both sides evaluate each face with LimitEvaluator.
  RowMatrixX3d normals(const RowMatrixX3d& controlPoints) const;

  const std::vector<SampleElement>& elements() const { return elements_; }
  const std::vector<SampleFeature>& features() const { return features_; }
  // #S ids of the source element: vertex id, edge id or face id according to elements().
  const Eigen::VectorXi& sourceIds() const { return sourceIds_; }
  // #S x 2 vertex ids of the source: (v, -1) for vertex samples, the edge's two end points for
  // edge samples, (-1, -1) for face samples.
  const RowMatrixX2i& sourceVertices() const { return sourceVertices_; }
  // #S locations (ptex face, u, v) of the samples on the limit surface, see surface_location.h.
  const std::vector<SurfaceLocation>& locations() const { return locations_; }

private:
  RowSparseMatrix positionOperator_;
  RowSparseMatrix tangentU_;
  RowSparseMatrix tangentV_;
  std::vector<SampleElement> elements_;
  std::vector<SampleFeature> features_;
  Eigen::VectorXi sourceIds_;
  RowMatrixX2i sourceVertices_;
  std::vector<SurfaceLocation> locations_;
};

}  // namespace bvmesh

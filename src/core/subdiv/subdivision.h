// Iteration step 1: one level of Catmull-Clark subdivision, modified for sharp creases and
// boundaries (thesis rules 3.1-3.5), computed with OpenSubdiv's Catmark scheme.
#pragma once

#include <Eigen/SparseCore>

#include "core/mesh/control_mesh.h"

namespace bvmesh {


// The OpenSubdiv options that change the subdivided mesh or its limit surface. The defaults are
// the thesis' rules: boundaries are cubic B-spline curves and their corners stay fixed
// (Sdc VTX_BOUNDARY_EDGE_AND_CORNER), semi-sharp creases decay uniformly, triangles use the
// plain Catmull-Clark rules.
struct SubdivisionOptions {
  enum class Boundary {
    EdgeOnly,       // boundary edges are sharp; a vertex with one face is smoothed along the curve
    EdgeAndCorner,  // boundary edges are sharp and vertices with one face are corners
  };
  enum class CreaseMethod {
    Uniform,  // semi-sharp edges lose 1 sharpness per level
    Chaikin,  // sharpness of child edges averaged with their neighbours along the crease
  };
  enum class TriangleRule {
    CatmullClark,  // the standard rules (3.1)-(3.3) for every face
    Smooth,        // OpenSubdiv's modified weights for triangles
  };
  Boundary boundary = Boundary::EdgeAndCorner;
  CreaseMethod creaseMethod = CreaseMethod::Uniform;
  TriangleRule triangleRule = TriangleRule::CatmullClark;
};

struct SubdivisionResult {
  // The refined control mesh, all quads. Its vertices come in a fixed order: the #V moved old
  // vertices (same ids), then one edge point per old edge (old edge order), then one face point
  // per old face. The children of old face f are the faceSize(f) consecutive faces starting at
  // sum of the sizes of faces 0..f-1; child i starts at the point of corner i and runs
  // (vertex point i, edge point of edge i, face point, edge point of edge i-1), so orientation is
  // kept. Every crease edge becomes its two halves (sharpness decayed as OpenSubdiv decays it;
  // edges whose sharpness reaches 0 stop being creases), every corner stays a corner.
  ControlMesh mesh;
  // #V' x #V subdivision operator: mesh.vertices() == subdivisionOperator * old vertices.
  RowSparseMatrix subdivisionOperator;
};

// One subdivision step.
SubdivisionResult subdivide(const ControlMesh& mesh, const SubdivisionOptions& options = {});

}  // namespace bvmesh

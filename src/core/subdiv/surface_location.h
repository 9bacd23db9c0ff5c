// Locations on the limit surface: (ptex face, u, v), OpenSubdiv's convention.
//
// A quad face is one ptex face: u runs from corner 0 to corner 1, v from corner 0 to corner 3,
// so corners 0, 1, 2, 3 are (0,0), (1,0), (1,1), (0,1). A face with n != 4 corners is split
// into n ptex faces (one per corner, numbered consecutively in corner order); ptex face i of it
// has (0,0) at corner i, (1,0) at the midpoint of edge i (corner i to i+1), (1,1) at the face
// centre and (0,1) at the midpoint of edge i-1. Ptex faces are numbered face by face. After one
// subdivision every face is a quad and the ptex face index is the face index.
#pragma once

#include <vector>

#include "core/mesh/control_mesh.h"

namespace bvmesh {

struct SurfaceLocation {
  int face = 0;  // ptex face index
  double u = 0.0;
  double v = 0.0;
};

// #F + 1 offsets: the ptex faces of face f are ptexFaceOffsets[f] .. ptexFaceOffsets[f+1]-1.
std::vector<int> ptexFaceOffsets(const ControlMesh& mesh);

// Location of corner `corner` of face `face` (the limit point of that vertex).
SurfaceLocation cornerLocation(const ControlMesh& mesh, const std::vector<int>& ptexOffsets,
                               int face, int corner);
// Location of the parametric midpoint of edge `corner` (corner to corner+1) of face `face`.
SurfaceLocation edgeMidpointLocation(const ControlMesh& mesh, const std::vector<int>& ptexOffsets,
                                     int face, int corner);
// Location of the parametric centre of face `face`.
SurfaceLocation faceCentreLocation(const ControlMesh& mesh, const std::vector<int>& ptexOffsets,
                                   int face);

}  // namespace bvmesh

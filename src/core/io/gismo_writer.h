// The B-spline block mesh as a G+Smo XML file, for isogeometric analysis on the exact volume
// mesh (G+Smo's gsReadFile / gsFileData load it as a gsMultiPatch):
//  - per block a <Geometry type="TensorBSpline3" id="b"> (b = block number): a
//    TensorBSplineBasis3 of three BSplineBasis with the full knot vectors, and <coefs geoDim="3">
//    with the poles, first parametric index fastest (as the blocks store them), 17 digits;
//  - a <MultiPatch parDim="3"> with <patches type="id_range">, <interfaces> and <boundary>.
//    Sides are G+Smo's 1..6 = u_min, u_max, v_min, v_max, w_min, w_max. Each interface is listed
//    once, "p1 s1 p2 s2 dirMap[3] dirOrientation[3]": direction d of p1 continues along
//    direction dirMap[d] of p2, the same way when dirOrientation[d] is 1 (gsBoundary.h's
//    boundaryInterface; its mapCorner applies exactly this). For the normal direction the entry
//    is written geometrically, as gismo's own filedata/volumes/fichera.xml does; G+Smo's reader
//    recomputes that entry from the two sides in any case.
// Boundary conditions: G+Smo's topology knows only "boundary", with no labels. So the first
// <boundary> lists every side that is not an interface (what every G+Smo version reads), and one
// <boundary name="wall">, <boundary name="farfield">, ... per condition used lists its sides
// again for the set-up of the analysis. Readers that take every <boundary> element (current
// G+Smo) merge them into the same set, older ones read only the first; the name attribute is
// ignored by both.
#pragma once

#include <string>

#include "core/volume/block_mesh.h"

namespace bvmesh::io {

// Writes through "<path>.partial" renamed into place. Throws InvalidInputError naming the path
// when it cannot be written.
void writeGismo(const volume::BlockMesh& mesh, const std::string& path);

}  // namespace bvmesh::io

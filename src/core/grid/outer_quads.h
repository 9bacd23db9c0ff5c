// The outer faces of a box or cylinder domain, quad by quad. The volume stage tags each far-field
// block face inlet, outlet or side by where its middle lies; an O-block around a wing bends over
// the box's edges, so one block face can lie on the inlet, a side and the outlet at once, and a
// solver needs each quad on the patch it really lies on.
#pragma once

#include <vector>

#include "core/grid/structured_grid.h"
#include "core/volume/domain.h"

namespace bvmesh::grid {

// For every inlet, outlet or side face of `blocks`, the condition of each quad by where its centre
// lies on the domain's boundary (volume::Domain::conditionAt of the centre's boundary point along
// the ray from the domain's centre), kept in quadConditions when some quad differs from the face's
// own. Returns the number of faces so split. A sphere domain is left as it is: its boundary is
// far field all round, and its outlet faces are those of an outflow plane a wall runs into.
int tagOuterQuads(std::vector<GridBlock>& blocks, const volume::Domain& domain);

}  // namespace bvmesh::grid

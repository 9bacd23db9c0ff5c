// A grid's point budget: a count beyond the machine's memory is refused before anything is
// allocated for it, instead of exhausting the memory of the process (a FreeCAD session).
#pragma once

namespace bvmesh::grid {

// Throws InvalidInputError when `points` (a count in floating point, so that one far beyond any
// machine cannot overflow) exceeds maxPoints > 0; maxPoints 0 is no limit.
void checkPointBudget(double points, long long maxPoints);

}  // namespace bvmesh::grid

#include "core/grid/point_budget.h"

#include <string>

#include "core/common/errors.h"
#include "core/common/number_text.h"

namespace bvmesh::grid {

void checkPointBudget(double points, long long maxPoints) {
  if (maxPoints > 0 && points > static_cast<double>(maxPoints)) {
    throw InvalidInputError("the grid would have " + numberText(points) + " points, more than max_points (" +
                            std::to_string(maxPoints) +
                            ", the memory budget): ask for fewer cells, edge points or normal points, or "
                            "allow more points");
  }
}

}  // namespace bvmesh::grid

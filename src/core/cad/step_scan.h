// A pass over a STEP file's text before OCCT parses it, refusing what its parser cannot survive
// in reasonable time: OCCT's STEP parser takes time growing with the square of a list's length
// (measured with OCCT 7.6: 0.1 s for a list of 10 000 items, 0.9 s for 30 000, 9.6 s for
// 100 000; a list of two million would take about an hour) and crashes (stack overflow) on lists
// nested 100 000 deep. The limits lie far above real files (a closed shell of a hundred thousand
// faces is one list of 100 000 items; lists nest a few levels), and the pass is linear: it reads
// the file once, tens of MB per second.
#pragma once

#include <cstdint>
#include <string>

namespace bvmesh::cad {

struct StepListLimits {
  std::int64_t maxItems = 1000000;  // items of one list
  int maxDepth = 1000;              // lists within lists
};

// Throws InvalidInputError naming the file, the entity (#N), its line, the count and the limit
// when a list has more items or lists nest deeper than `limits` allow. Strings ('...', with ''
// for a quote) and comments (/* ... */) are skipped.
void checkStepLists(const std::string& path, const StepListLimits& limits = {});

}  // namespace bvmesh::cad

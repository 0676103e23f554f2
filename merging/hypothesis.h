#pragma once
// What a merge method proposes: a candidate transform of b's cells into a's cells.
#include <string>

#include "core/transform2.h"

namespace fleetmap::merging {

struct Hypothesis {
  core::Transform2 b_to_a;  // fine cell coordinates of b into fine cell coordinates of a
  double score = 0.0;       // the method's own ranking (comparable within one method only)
  int level = 0;            // pyramid level at which it is accurate to about a cell: refinement starts there
  std::string method;       // the method that proposed it
};

}  // namespace fleetmap::merging

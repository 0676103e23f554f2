#pragma once
// Shared by the merging tests: the built-in maps as sources of crop pairs, and grid builders.
#include <string>
#include <vector>

#include "maps/builtin_maps.h"
#include "mapping/occupancy_grid.h"
#include "merging/evaluation.h"

namespace fleetmap::merging::testing {

inline const std::vector<std::string>& builtin_map_names_for_tests() {
  static const std::vector<std::string> kNames = {"empty", "unstructured", "office", "corridor",
                                                  "cave",  "maze",         "warehouse", "campus"};
  return kNames;
}

// A built-in map as a crop source. The 1200 x 1200 campus is cut to 500 x 500 (two buildings,
// trees) to keep the suite fast; the rest are used whole.
inline mapping::OccupancyGrid source_map(const std::string& name) {
  const auto grid = maps::load_map_source(name);
  if (name == "campus") return crop_grid(grid, 300, 300, 500, 500);
  return grid;
}

// Crops of 70% of the source's shorter side: at 50% overlap the common part is a third of a
// 200-cell map, enough to hold some of its structure.
inline CropPairOptions half_overlap_crops(const mapping::OccupancyGrid& source) {
  CropPairOptions o;
  o.width = o.height = int(0.7 * std::min(source.width(), source.height()));
  o.overlap = 0.5;
  return o;
}

// A grid from rows of characters, top row first (as drawn): '#' occupied, '.' free, ' ' unknown.
inline mapping::OccupancyGrid grid_from_text(const std::vector<std::string>& rows) {
  const int h = int(rows.size()), w = h > 0 ? int(rows[0].size()) : 0;
  mapping::OccupancyGrid g(core::GridGeometry(0.05, w, h));
  for (int r = 0; r < h; ++r) {
    for (int x = 0; x < w; ++x) {
      const char c = rows[std::size_t(r)][std::size_t(x)];
      const core::Cell cell{x, h - 1 - r};
      if (c == '#') g.set_state(cell, mapping::CellState::Occupied);
      else if (c == '.') g.set_state(cell, mapping::CellState::Free);
    }
  }
  return g;
}

}  // namespace fleetmap::merging::testing

#pragma once
// Small hand-made worlds for the simulator tests.
#include "mapping/occupancy_grid.h"
#include "core/random.h"

namespace fleetmap::sim::testing {

// A w x h room of 0.1 m cells whose outer ring of cells is wall.
inline mapping::OccupancyGrid walled_room(int w, int h) {
  mapping::OccupancyGrid g(core::GridGeometry(0.1, w, h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      g.set_state({x, y}, (x == 0 || y == 0 || x == w - 1 || y == h - 1) ? mapping::CellState::Occupied
                                                                          : mapping::CellState::Free);
  return g;
}

// A walled room with random rectangular obstacles.
inline mapping::OccupancyGrid random_room(core::Random& rng, int w, int h, int obstacles) {
  auto g = walled_room(w, h);
  for (int k = 0; k < obstacles; ++k) {
    const int x0 = rng.uniform_int(1, w - 2), y0 = rng.uniform_int(1, h - 2);
    const int x1 = std::min(w - 2, x0 + rng.uniform_int(0, 8)), y1 = std::min(h - 2, y0 + rng.uniform_int(0, 8));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) g.set_state({x, y}, mapping::CellState::Occupied);
  }
  return g;
}

}  // namespace fleetmap::sim::testing

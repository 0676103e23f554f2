#pragma once
// Distance fields on a grid: how far every cell is from the nearest blocked cell. Written once for
// robot clearance (inflating obstacles by the robot's radius), planning and scoring maps.
#include <cstdint>
#include <vector>

namespace fleetmap::mapping {

// The exact Euclidean distance, in cells, from every cell's centre to the centre of the nearest
// cell with blocked[i] != 0 (cells indexed y * width + x). With `outside_blocked`, the ring of
// cells just outside the grid counts as blocked too, so the map's edge is a wall; without it, a
// grid with no blocked cell is infinitely far from everything.
std::vector<float> distance_to_blocked(int width, int height, const std::vector<std::uint8_t>& blocked,
                                       bool outside_blocked = true);

}  // namespace fleetmap::mapping

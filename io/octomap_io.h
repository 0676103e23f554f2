#pragma once
// OctoMap export: the grid as one layer of an OcTree, readable by octomap's own tools.
#include <filesystem>

#include "mapping/occupancy_grid.h"

namespace fleetmap::io {

// Writes a binary OctoMap (.bt): an OcTree at the grid's resolution holding one voxel per known
// cell, at the cell centre in world coordinates, z in [0, resolution). Occupied cells are occupied
// voxels, free cells free voxels; unknown cells are absent.
void save_octomap(const mapping::OccupancyGrid& grid, const std::filesystem::path& path);

}  // namespace fleetmap::io

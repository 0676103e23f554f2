#pragma once
// Merging any number of maps: every pair is aligned, then a maximum-confidence spanning tree
// rooted at the first map puts every map it reaches in the first map's frame.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/transform2.h"
#include "mapping/occupancy_grid.h"
#include "merging/fusion.h"
#include "merging/merge.h"

namespace fleetmap::merging {

// Maps of different resolutions are aligned pair by pair through the coarser map's cells
// (align_across_resolutions), and every transform is given between the maps seen through the first
// map's cells (mapping::resample(grid, first.resolution()): a map's own cells when it has the first's
// resolution).
struct PairAlignment {
  int a = 0, b = 0;     // b's cells into a's cells (a < b)
  MergeResult result;
};

struct MultiMergeResult {
  // Per input: its cells into the first input's cells; nullopt when no chain of reliable pairs
  // links it to the first. The first's is the identity.
  std::vector<std::optional<core::Transform2>> to_first;
  std::vector<int> parent;          // the tree: input i was placed through input parent[i] (-1: root or not placed)
  std::vector<double> confidence;   // of the pair that placed input i (1 for the first, 0 if not placed)
  std::vector<std::string> method;  // method of that pair
  std::vector<std::string> reason;  // why input i was not placed; empty when placed
  std::vector<int> reason_pair;     // the index in `pairs` of the refusal that gave the reason; -1 for none
  std::vector<PairAlignment> pairs; // every pairwise result
  // Reliable pairs outside the tree check it: the largest gap, at the overlap centre, between the
  // pair's own transform and the one the tree implies (cells). 0 without such pairs.
  double max_loop_gap = 0.0;
};

// Aligns all pairs (each grid prepared once) and builds the tree. `progress(done, total)` is
// called after each pair when given.
MultiMergeResult merge_maps(const std::vector<const mapping::OccupancyGrid*>& grids, const MergeOptions& options = {},
                            const std::function<void(int, int)>& progress = {});

// The fused map of the inputs that were placed (others are left out).
FusedMap fuse_merged(const std::vector<const mapping::OccupancyGrid*>& grids, const MultiMergeResult& merged);

}  // namespace fleetmap::merging

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
  // Per input: the covariance of to_first's (tx, ty, theta) (first's cells, radians), the pairs'
  // covariances (MergeResult::covariance) composed along the chain to the first, taken as
  // independent; zero for the first, nullopt when not placed or a pair of the chain has none.
  std::vector<std::optional<Eigen::Matrix3d>> covariance;
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

// Where an input lies in the first input's frame, in the two forms `fleetmap merge` and Python's
// merge_maps report.
struct Placement {
  // The input's map frame into the first's, in metres (a frame as its map_server origin defines it;
  // a bare image's has the lower-left corner at (0, 0)): p_first = R(theta) p + t.
  core::Transform2 metres;
  // Pixel (u, v) of the input (u = column, v = row from the top) lies at
  // scale R(theta) (u, v) + t in the first input's pixel grid.
  core::Transform2 pixels;
  double scale = 1.0;  // the input's metres per cell / the first's
  // The covariance of metres' (tx, ty, theta): metres, metres, radians; nullopt when not known.
  std::optional<Eigen::Matrix3d> covariance;
};

// A covariance of a transform's (tx, ty, theta) (metres and radians) in the words a user reads:
// the standard deviations, and at `at` (a point of the first map, metres: where the maps overlap)
// the largest and smallest standard deviation of where a point of b lands and the direction of the
// largest (degrees from the x axis, in [0, 180)).
struct Uncertainty {
  double std_tx = 0.0, std_ty = 0.0, std_theta_deg = 0.0;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  double std_major = 0.0, std_minor = 0.0, major_deg = 0.0;
};
Uncertainty describe_uncertainty(const Eigen::Matrix3d& covariance, const core::Transform2& transform,
                                 const Eigen::Vector2d& at);

// The placement of an input whose cells seen through the first's cells (mapping::resample(input,
// first.resolution()), the input's own cells at one resolution) `cells` takes into the first's
// cells, as MultiMergeResult::to_first and its pairs' transforms do.
// With `covariance` (of cells' parameters, cells and radians), Placement::covariance too.
Placement placement(const core::GridGeometry& first, const core::GridGeometry& input, const core::Transform2& cells,
                    const std::optional<Eigen::Matrix3d>& covariance = std::nullopt);

// The margin kept around the known cells of a merged map (metres): what `fleetmap merge --out
// merged.yaml` writes and its picture shows.
inline constexpr double kMergedMarginM = 0.5;

// Maps merged and fused as `fleetmap merge` and Python's merge_maps do it.
struct MergedMaps {
  MultiMergeResult merge;
  std::vector<std::optional<Placement>> placements;  // per input; nullopt when not placed
  // The placed inputs fused in the first's cells (maps of other resolutions resampled to them).
  FusedMap fused;
  // fused.grid cut to its known cells and kMergedMarginM around them, at the same place in the world.
  mapping::OccupancyGrid map;
};

// Aligns every pair of `grids` (the first is the reference; any resolutions), places them, and
// fuses the placed ones. Throws as merge_maps.
MergedMaps merge_and_fuse(const std::vector<const mapping::OccupancyGrid*>& grids, const MergeOptions& options = {},
                          const std::function<void(int, int)>& progress = {});
// The same from merge_maps(grids)'s result.
MergedMaps fuse_placed(const std::vector<const mapping::OccupancyGrid*>& grids, MultiMergeResult merge);

}  // namespace fleetmap::merging

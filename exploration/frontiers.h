#pragma once
// Frontiers (Yamauchi 1997): known-free cells next to unknown cells, grouped into regions, and the
// targets robots drive to: each region split into pieces no wider than a sensor footprint, each
// with a reachable goal cell.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "mapping/occupancy_grid.h"

namespace fleetmap::exploration {

using core::Cell;

struct FrontierOptions {
  int min_region_cells = 3;  // smaller regions are sensor noise, not worth a trip
  // Unknown space narrower than this is not space to explore (the inside of a wall, a rack or a
  // pillar seen through a gap that a grazing beam left in its outline): a frontier must border
  // never-observed cells that survive a morphological opening by a square of this width.
  double min_unknown_width_m = 0.5;
  // Narrower never-observed space is still space to explore where no occupied cell touches it (its
  // 8 neighbours): the unseen wedges between the beams of a sparse or far-reaching scan, which
  // coverage counts, unlike the inside of a wall, which borders the wall's observed face.
  bool gaps_in_open_space = true;
  // Frontier cells this many cells apart (or fewer) belong to one region: the tips of a sparse
  // scan's beams make one frontier, not many single cells.
  int join_gap_cells = 1;
  // Narrower never-observed strips beside walls still count when they survive an opening by a square
  // this wide (at least 3 cells): the shadow a door jamb casts along the wall behind it. The inside
  // of a thin wall whose corner a beam clipped looks alike, so these are explored last.
  double min_narrow_width_m = 0.15;
};

// Frontier cells of a window of the map: free cells with a 4-neighbour in never-observed space that
// is at least min_unknown_width_m wide or touches no occupied cell (see FrontierOptions). Cells that
// were observed but are undecided (conflicting evidence, e.g. noisy hits on a wall face) are not
// unexplored: no robot could resolve them by driving there. Cells outside the map are not space to
// explore. The window gives the same answers as the whole map.
class FrontierMask {
 public:
  FrontierMask(const mapping::OccupancyGrid& map, const FrontierOptions& options);
  // The window [lo, hi) of cells, clipped to the map.
  FrontierMask(const mapping::OccupancyGrid& map, const FrontierOptions& options, const Cell& lo, const Cell& hi);
  static constexpr std::uint8_t kWide = 1;  // beside never-observed space at least min_unknown_width_m wide
  static constexpr std::uint8_t kGap = 2;   // beside a gap in open space only
  static constexpr std::uint8_t kNarrow = 3;  // beside a narrow strip only (min_narrow_width_m)
  bool operator()(const Cell& c) const { return kind(c) != 0; }  // false outside the window
  std::uint8_t kind(const Cell& c) const;                         // 0: not a frontier cell
  const Cell& lo() const { return lo_; }
  const Cell& hi() const { return hi_; }

 private:
  Cell lo_, hi_;
  std::vector<std::uint8_t> frontier_;  // (hi - lo) cells, row-major from lo
};

bool is_frontier(const mapping::OccupancyGrid& map, const Cell& c, const FrontierOptions& options = {});

struct FrontierRegion {
  std::vector<Cell> cells;
  Eigen::Vector2d centroid_m = Eigen::Vector2d::Zero();  // mean of the cell centres, metres
  // The most promising FrontierMask kind among its cells: kWide before kGap before kNarrow.
  std::uint8_t kind = FrontierMask::kWide;
  int size() const { return int(cells.size()); }
};

// Regions of frontier cells (8-connected, bridging gaps of join_gap_cells), in scan order of
// their first cell.
std::vector<FrontierRegion> find_frontier_regions(const mapping::OccupancyGrid& map, const FrontierOptions& options = {});

struct TargetOptions {
  FrontierOptions frontiers;
  double piece_radius_m = 1.5;     // a region wider than this is split into several targets
  // A goal with room to spare (a Clear cell) this close to the frontier cell is taken first ...
  double approach_radius_m = 0.6;
  // ... else the passable cell nearest to the unseen cell, no farther from it than this, in line of
  // sight of it over known-free cells: the pose to observe it from. Kept within the sensor range.
  double observe_range_m = 1.5;
  // Farther (up to this) only when no goal within observe_range_m will do: e.g. looking into a room
  // through a gap the robot cannot pass.
  double max_observe_range_m = 3.5;
};

// A place to explore: a piece of a frontier region, and the goal cell to drive to.
struct Target {
  Cell frontier;                   // the piece's representative frontier cell
  Cell unknown;                    // a never-observed neighbour of `frontier`: what the goal must see
  Cell goal;                       // passable, in line of sight of `unknown`
  Eigen::Vector2d goal_m = Eigen::Vector2d::Zero();
  int cells = 0;                   // frontier cells in the piece
  int region = 0;                  // index into the regions it came from
  std::uint8_t kind = FrontierMask::kWide;  // its region's kind
};

// Whether a cell may be a piece's goal: e.g. some robot's wave reaches it, and it is not an
// approach already tried and failed for that frontier.
using GoalFilter = std::function<bool(const Cell& frontier, const Cell& goal)>;

struct TargetSet {
  std::vector<Target> targets;
  std::vector<Cell> without_goal;  // frontier cells of the pieces with no usable goal
};

// Targets for the regions of the most promising kind that has any target: wide unknown space first,
// then gaps in open space, then narrow strips (looking into open space sees most gaps on the way,
// and a dotted outline of a pillar is not worth a trip while rooms are unseen). A piece's goal is searched among the known-free cells around its frontier
// cell: the nearest Clear cell within approach_radius_m that `usable` accepts and that sees the
// unseen cell, else the passable cell (Fits or Clear) nearest to the unseen cell within
// observe_range_m that does, else within max_observe_range_m. `passage` is passage_cells(map, ...).
TargetSet find_targets(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& passage,
                       const GoalFilter& usable, const TargetOptions& options);

// True when every cell on the segment between the two cell centres, before `to`, is known free.
bool sees_over_free(const mapping::OccupancyGrid& map, const Cell& from, const Cell& to);

// The number of frontier cells within `radius_m` of `c` (is the area around a target still open?),
// counting only kinds up to `up_to_kind` (a wide frontier's target is done when only narrow strips are left).
int frontier_cells_near(const mapping::OccupancyGrid& map, const Cell& c, double radius_m,
                        const FrontierOptions& options, std::uint8_t up_to_kind = FrontierMask::kNarrow);

}  // namespace fleetmap::exploration

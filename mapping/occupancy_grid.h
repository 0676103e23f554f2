#pragma once
// A log-odds occupancy grid (Moravec & Elfes; the clamped update of OctoMap).
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "core/grid_geometry.h"
#include "mapping/grid_traversal.h"

namespace fleetmap::mapping {

using core::Cell;
using core::GridGeometry;

enum class CellState : std::uint8_t { Unknown = 0, Free = 1, Occupied = 2 };

std::ostream& operator<<(std::ostream& os, CellState s);

// The inverse sensor model and the thresholds that turn a probability into a state.
// The defaults make one beam enough to call a cell free or occupied, and a single
// contradicting beam enough to make it unknown again.
struct OccupancyGridOptions {
  double hit_probability = 0.75;   // the cell a beam ends in
  double miss_probability = 0.30;  // the cells a beam crosses
  double min_probability = 0.12;   // clamping keeps the map able to change (as OctoMap)
  double max_probability = 0.97;
  double occupied_threshold = 0.65;  // Occupied when P(occ) > this (map_server occupied_thresh)
  double free_threshold = 0.35;      // Free when P(occ) < this

  bool operator==(const OccupancyGridOptions&) const = default;
};

double probability_to_log_odds(double p);
double log_odds_to_probability(double l);

class OccupancyGrid {
 public:
  OccupancyGrid() = default;
  // All cells Unknown (log-odds 0). Throws fleetmap::Error on inconsistent options.
  explicit OccupancyGrid(const GridGeometry& geometry, const OccupancyGridOptions& options = {});

  const GridGeometry& geometry() const { return geometry_; }
  const OccupancyGridOptions& options() const { return options_; }
  int width() const { return geometry_.width(); }
  int height() const { return geometry_.height(); }
  double resolution() const { return geometry_.resolution(); }
  bool contains(const Cell& c) const { return geometry_.contains(c); }

  // Cells outside the grid are Unknown.
  CellState state(const Cell& c) const { return contains(c) ? state_at(geometry_.index(c)) : CellState::Unknown; }
  CellState state_at(int index) const {
    const float l = log_odds_[static_cast<std::size_t>(index)];
    return l > occupied_log_odds_ ? CellState::Occupied
                                  : (l < free_log_odds_ ? CellState::Free : CellState::Unknown);
  }
  bool is_free(const Cell& c) const { return state(c) == CellState::Free; }
  // Ever touched by evidence. A cell can be observed and still Unknown when its evidence conflicts.
  bool observed(const Cell& c) const { return contains(c) && log_odds(c) != 0.0f; }
  float log_odds(const Cell& c) const { return log_odds_[static_cast<std::size_t>(geometry_.index(c))]; }
  float log_odds_at(int index) const { return log_odds_[static_cast<std::size_t>(index)]; }
  double probability(const Cell& c) const { return log_odds_to_probability(log_odds(c)); }

  // Sets a cell to a firm state: the clamping bound for Free/Occupied, 0 for Unknown.
  void set_state(const Cell& c, CellState s);
  // Inline: whole grids are copied cell by cell through it (crops, loaded images, merged maps).
  void set_log_odds(const Cell& c, float l) {
    if (!contains(c)) return;
    float& cell = log_odds_[static_cast<std::size_t>(geometry_.index(c))];
    observed_count_ += (cell == 0.0f) - (l == 0.0f);
    cell = l;
  }
  // Adds `delta` to a cell's log-odds, clamped to the bounds. Ignores cells outside the grid.
  void update(const Cell& c, float delta);
  void update_hit(const Cell& c) { update(c, hit_log_odds_); }
  void update_miss(const Cell& c) { update(c, miss_log_odds_); }

  // One range beam from `from` to `to` (metres): every cell the segment crosses before its end
  // cell gets a miss; the end cell gets a hit when `hit`, or a miss when the beam reached its
  // maximum range without a return. Each cell is updated once; the part outside the grid is
  // ignored. Returns the number of cells updated.
  int integrate_ray(const Eigen::Vector2d& from, const Eigen::Vector2d& to, bool hit) {
    return integrate_ray(from, to, hit, [](int, bool) {});
  }
  // The same, calling `on_cell(index, changed)` for every cell it updates; `changed` is false when
  // the cell was already at its clamping bound.
  template <typename OnCell>
  int integrate_ray(const Eigen::Vector2d& from, const Eigen::Vector2d& to, bool hit, OnCell&& on_cell);

  std::int64_t count(CellState s) const;
  // Cells ever touched by evidence, kept up to date on every write (cheap to ask every step).
  std::int64_t observed_count() const { return observed_count_; }
  std::int64_t known_count() const { return count(CellState::Free) + count(CellState::Occupied); }

  const std::vector<float>& log_odds_data() const { return log_odds_; }
  float hit_log_odds() const { return hit_log_odds_; }
  float miss_log_odds() const { return miss_log_odds_; }
  float min_log_odds() const { return min_log_odds_; }
  float max_log_odds() const { return max_log_odds_; }
  // The state thresholds: Occupied above the first, Free below the second (state_at).
  float occupied_log_odds() const { return occupied_log_odds_; }
  float free_log_odds() const { return free_log_odds_; }

  // Same geometry and the same state in every cell (log-odds may differ).
  bool same_states(const OccupancyGrid& other) const;

 private:
  GridGeometry geometry_;
  OccupancyGridOptions options_;
  std::vector<float> log_odds_;
  std::int64_t observed_count_ = 0;
  float hit_log_odds_ = 0, miss_log_odds_ = 0, min_log_odds_ = 0, max_log_odds_ = 0;
  float occupied_log_odds_ = 0, free_log_odds_ = 0;
};

std::ostream& operator<<(std::ostream& os, const OccupancyGrid& g);

// The grid seen through cells `factor` times larger (same origin; a partial block at the top or
// right edge becomes a whole coarse cell). A coarse cell is Occupied when any of its cells is (a
// wall never disappears; it takes the largest log-odds of the block), Free when at least half of
// its cells are Free and none Occupied (mean log-odds of those free cells: the unseen gaps between
// far beams do not turn free space into unknown), and Unknown otherwise. factor 1 returns a copy.
// Throws fleetmap::Error unless factor >= 1. (resample with resolution * factor.)
OccupancyGrid coarsen(const OccupancyGrid& fine, int factor);

// The grid seen through cells of another size (same origin and options; the extent rounded up to
// whole cells), as two robots with different map resolutions need before their maps can be
// compared cell by cell. A new cell takes the cells whose centres lie inside it, by coarsen's rule
// (Occupied when any is, Free when at least half are Free), or, when no centre lies inside it (a
// finer resolution), the cell it lies in. A whole number of times coarser is coarsen's result
// exactly. Throws fleetmap::Error unless resolution > 0.
OccupancyGrid resample(const OccupancyGrid& grid, double resolution);
// The cells resample(grid, resolution) would hold (width x height, as a double: it may exceed any
// int), to refuse one too large before making it. Throws as resample.
double resampled_cell_count(const OccupancyGrid& grid, double resolution);
// The geometry of resample(grid, resolution): the same origin, the extent rounded up to whole cells.
// Throws as resample.
GridGeometry resampled_geometry(const GridGeometry& geometry, double resolution);

// The grid cut to the box of its known (Free or Occupied) cells grown by `margin` cells on every
// side (within the grid), at the same place in the world: every cell keeps its world position and
// state. A grid with no known cell comes back whole.
OccupancyGrid crop_to_known(const OccupancyGrid& grid, int margin);

// `grid`'s cells pooled into a width x height grid of `resolution` cells (at least grid's) laid
// anywhere: `place` takes the cells of resample(grid, resolution) (same origin; a cell's centre at
// integer coordinates) into the new grid's cells, and each cell of `grid` goes to the new cell its
// centre lands in. A new cell is Occupied when any cell landing in it is, Free when at least half
// of them are Free, Unknown otherwise (as resample). The new grid has `origin` and grid's options.
// Two maps of different resolutions compare cell for cell only when the finer one is pooled
// through the coarser one's own cells, not a lattice of its own half a cell off.
// Throws fleetmap::Error for a resolution finer than grid's or a negative size.
OccupancyGrid pool(const OccupancyGrid& grid, double resolution, const core::Transform2& place, int width, int height,
                   const core::Pose2& origin = {});

template <typename OnCell>
int OccupancyGrid::integrate_ray(const Eigen::Vector2d& from, const Eigen::Vector2d& to, bool hit, OnCell&& on_cell) {
  const auto end_cell = geometry_.world_to_cell(to);
  int updated = 0;
  traverse_segment(geometry_, from, to, [&](const Cell& c, double) {
    const bool is_end = end_cell && c == *end_cell;
    const int i = geometry_.index(c);
    float& l = log_odds_[static_cast<std::size_t>(i)];
    const float before = l;
    l = std::clamp(l + (is_end && hit ? hit_log_odds_ : miss_log_odds_), min_log_odds_, max_log_odds_);
    observed_count_ += (before == 0.0f) - (l == 0.0f);
    on_cell(i, l != before);
    ++updated;
    return !is_end;
  });
  return updated;
}

}  // namespace fleetmap::mapping

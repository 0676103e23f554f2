#pragma once
// The wave: distance fields over passable cells from one or more source cells (the wave-algorithm paper's wave
// algorithm, Table 1; with occupancy weights, Burgard et al. 2005's value iteration). The hot loop
// of every exploration run: a flat-array BFS (4-connected, unit costs) or Dial's bucket queue over
// reused storage (8-connected, or occupancy-weighted). Step costs are whole units of 1/70 cell:
// 70 straight, 99 diagonal (99/70 is within 5e-5 of sqrt(2)), so every cost is exact in units.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "core/grid_geometry.h"

namespace fleetmap::exploration {

using core::Cell;

struct WaveOptions {
  // The wave-algorithm paper's pseudo code is 4-connected; 8-connected adds diagonal steps of cost sqrt(2).
  // A diagonal step needs both cells beside it passable, so waves never cut a corner.
  bool eight_connected = true;
  // Burgard's cost model: entering a cell costs its step length times (1 + occupancy_weight * P(occ)),
  // rounded to whole units (at most 0.5/70 of the step). 0 gives plain geometric distances.
  double occupancy_weight = 0.0;
};

// The grid a wave runs on: which cells may be entered, and optionally P(occ) per cell.
struct WaveGrid {
  int width = 0;
  int height = 0;
  std::span<const std::uint8_t> passable;  // width * height, non-zero = passable
  std::span<const float> occupancy;        // empty, or width * height probabilities
  // Empty, or width * height whole factors (0 is read as 1): entering a cell costs its step times
  // its factor, e.g. to make a wave prefer cells with room to spare.
  std::span<const std::uint8_t> step_factor;
};

class WaveField {
 public:
  static constexpr float kUnreached = std::numeric_limits<float>::infinity();
  static constexpr std::uint32_t kUnitsPerCell = 70;
  static constexpr std::uint32_t kDiagonalUnits = 99;
  static constexpr std::uint32_t kUnreachedUnits = std::numeric_limits<std::uint32_t>::max();

  int width() const { return width_; }
  int height() const { return height_; }
  bool contains(const Cell& c) const { return c.x >= 0 && c.y >= 0 && c.x < width_ && c.y < height_; }
  // Cost in cell lengths from the nearest source; kUnreached where the wave never came.
  float cost(const Cell& c) const { return contains(c) ? cost_[std::size_t(c.y * width_ + c.x)] : kUnreached; }
  float cost_at(int index) const { return cost_[std::size_t(index)]; }
  bool reached(const Cell& c) const { return cost(c) < kUnreached; }
  const std::vector<float>& costs() const { return cost_; }
  std::int64_t reached_count() const;
  // The exact cost in units of 1/kUnitsPerCell cell.
  std::uint32_t units_at(int index) const { return units_[std::size_t(index)]; }
  // After compute_labelled_wave: the index (into its sources) of the source whose wave reached the
  // cell first, i.e. the nearest source; -1 where the wave never came.
  int source_at(int index) const { return source_.empty() ? -1 : source_[std::size_t(index)]; }

  // The cells from the nearest source to `target` (both included), descending the wave; empty when
  // `target` was not reached.
  std::vector<Cell> path_to(const Cell& target) const;

 private:
  friend void compute_wave_into(const WaveGrid&, std::span<const Cell>, const WaveOptions&, WaveField&, bool);
  friend std::vector<float> pairwise_wave_costs(const WaveGrid&, std::span<const Cell>, const WaveOptions&, WaveField&);
  int width_ = 0;
  int height_ = 0;
  bool eight_connected_ = true;
  std::uint32_t step_units(int dir, int entered_index) const;
  std::vector<float> cost_;
  std::vector<std::uint32_t> units_;
  std::vector<std::uint8_t> passable_;  // copy kept for path extraction
  std::vector<std::uint32_t> step_units_;  // weighted: units to enter cell i straight [2i] and diagonally [2i+1]
  std::vector<std::int32_t> source_;       // labelled waves only: the nearest source per cell
};

// Fills `out` (its storage is reused between calls). Sources outside the grid are ignored; a source
// on an impassable cell still starts the wave (a robot may stand in inflated space).
void compute_wave(const WaveGrid& grid, std::span<const Cell> sources, const WaveOptions& options, WaveField& out);

// The same wave, also recording for every cell which source is nearest (WaveField::source_at): the
// sources' geodesic Voronoi regions.
void compute_labelled_wave(const WaveGrid& grid, std::span<const Cell> sources, const WaveOptions& options, WaveField& out);

// Wave costs in cells between every pair of `goals` (row-major, goals.size() squared; kUnreached
// between goals the grid does not connect), without a wave per goal: one labelled wave from all of
// them splits the grid into their geodesic Voronoi regions; two regions that touch are joined by the
// cheapest path through their border (the cost to the border from each side plus the step across),
// and shortest paths over these joins give the costs. Each cost is the length of a path of the wave,
// so never below the wave's cost between the two goals; it equals it when the cheapest path between
// them crosses no third goal's region, and is otherwise that path bent through the sources of the
// regions it crosses. Goals on one cell are 0 apart. `scratch` holds the labelled wave afterwards.
std::vector<float> pairwise_wave_costs(const WaveGrid& grid, std::span<const Cell> goals, const WaveOptions& options,
                                       WaveField& scratch);

inline WaveField compute_wave(const WaveGrid& grid, std::span<const Cell> sources, const WaveOptions& options = {}) {
  WaveField f;
  compute_wave(grid, sources, options, f);
  return f;
}

}  // namespace fleetmap::exploration

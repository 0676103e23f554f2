#include "mapping/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <string>

#include "core/error.h"

namespace fleetmap::mapping {

std::ostream& operator<<(std::ostream& os, CellState s) {
  switch (s) {
    case CellState::Unknown: return os << "Unknown";
    case CellState::Free: return os << "Free";
    case CellState::Occupied: return os << "Occupied";
  }
  return os << "CellState(?)";
}

double probability_to_log_odds(double p) { return std::log(p / (1.0 - p)); }
double log_odds_to_probability(double l) { return 1.0 - 1.0 / (1.0 + std::exp(l)); }

OccupancyGrid::OccupancyGrid(const GridGeometry& geometry, const OccupancyGridOptions& options)
    : geometry_(geometry), options_(options),
      log_odds_(static_cast<std::size_t>(geometry.cell_count()), 0.0f) {
  const auto in_open_unit = [](double p) { return p > 0.0 && p < 1.0; };
  if (!in_open_unit(options.hit_probability) || !in_open_unit(options.miss_probability) ||
      !in_open_unit(options.min_probability) || !in_open_unit(options.max_probability) ||
      !(options.miss_probability < 0.5 && options.hit_probability > 0.5) ||
      !(options.min_probability < options.free_threshold &&
        options.free_threshold <= 0.5 && 0.5 <= options.occupied_threshold &&
        options.occupied_threshold < options.max_probability)) {
    throw Error(
        "occupancy grid options: need 0 < min < free_threshold <= 0.5 <= occupied_threshold < max < 1 "
        "and miss < 0.5 < hit");
  }
  hit_log_odds_ = static_cast<float>(probability_to_log_odds(options.hit_probability));
  miss_log_odds_ = static_cast<float>(probability_to_log_odds(options.miss_probability));
  min_log_odds_ = static_cast<float>(probability_to_log_odds(options.min_probability));
  max_log_odds_ = static_cast<float>(probability_to_log_odds(options.max_probability));
  occupied_log_odds_ = static_cast<float>(probability_to_log_odds(options.occupied_threshold));
  free_log_odds_ = static_cast<float>(probability_to_log_odds(options.free_threshold));
}

void OccupancyGrid::set_state(const Cell& c, CellState s) {
  const float l = s == CellState::Free ? min_log_odds_ : (s == CellState::Occupied ? max_log_odds_ : 0.0f);
  set_log_odds(c, l);
}

void OccupancyGrid::update(const Cell& c, float delta) {
  if (!contains(c)) return;
  float& l = log_odds_[static_cast<std::size_t>(geometry_.index(c))];
  const float before = l;
  l = std::clamp(l + delta, min_log_odds_, max_log_odds_);
  observed_count_ += (before == 0.0f) - (l == 0.0f);
}

std::int64_t OccupancyGrid::count(CellState s) const {
  std::int64_t n = 0;
  for (std::size_t i = 0; i < log_odds_.size(); ++i) n += state_at(static_cast<int>(i)) == s;
  return n;
}

bool OccupancyGrid::same_states(const OccupancyGrid& other) const {
  if (!(geometry_ == other.geometry_)) return false;
  for (std::size_t i = 0; i < log_odds_.size(); ++i) {
    if (state_at(static_cast<int>(i)) != other.state_at(static_cast<int>(i))) return false;
  }
  return true;
}

std::ostream& operator<<(std::ostream& os, const OccupancyGrid& g) {
  return os << "OccupancyGrid(" << g.geometry() << ", " << g.count(CellState::Free) << " free, "
            << g.count(CellState::Occupied) << " occupied)";
}

OccupancyGrid coarsen(const OccupancyGrid& fine, int factor) {
  if (factor < 1) throw Error("coarsen: factor must be at least 1, got " + std::to_string(factor));
  if (factor == 1) return fine;
  const int w = fine.width(), h = fine.height();
  const int cw = (w + factor - 1) / factor, ch = (h + factor - 1) / factor;
  OccupancyGrid coarse(GridGeometry(fine.resolution() * factor, cw, ch, fine.geometry().origin()), fine.options());
  const float occupied = float(probability_to_log_odds(fine.options().occupied_threshold));
  const float free = float(probability_to_log_odds(fine.options().free_threshold));
  // Per coarse column of the current band of rows: free cells, their log-odds sum, the largest log-odds.
  std::vector<int> free_cells(static_cast<std::size_t>(cw));
  std::vector<float> free_sum(static_cast<std::size_t>(cw)), most(static_cast<std::size_t>(cw));
  const auto& l = fine.log_odds_data();
  for (int cy = 0; cy < ch; ++cy) {
    std::fill(free_cells.begin(), free_cells.end(), 0);
    std::fill(free_sum.begin(), free_sum.end(), 0.0f);
    std::fill(most.begin(), most.end(), -std::numeric_limits<float>::infinity());
    const int y_end = std::min(h, (cy + 1) * factor);
    for (int y = cy * factor; y < y_end; ++y) {
      const float* row = l.data() + std::size_t(y) * std::size_t(w);
      for (int x = 0; x < w; ++x) {
        const float v = row[x];
        const auto cx = std::size_t(x / factor);
        most[cx] = std::max(most[cx], v);
        if (v < free) {
          ++free_cells[cx];
          free_sum[cx] += v;
        }
      }
    }
    const int rows = y_end - cy * factor;
    for (int cx = 0; cx < cw; ++cx) {
      const int cells = rows * (std::min(w, (cx + 1) * factor) - cx * factor);
      const auto k = std::size_t(cx);
      float v = 0.0f;
      if (most[k] > occupied) v = most[k];
      else if (2 * free_cells[k] >= cells) v = free_sum[k] / float(free_cells[k]);
      if (v != 0.0f) coarse.set_log_odds({cx, cy}, v);
    }
  }
  return coarse;
}

}  // namespace fleetmap::mapping

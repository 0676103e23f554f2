#include "mapping/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

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
  return resample(fine, fine.resolution() * factor);
}

namespace {

// The cells pooled into one larger cell, and the rule that makes them one (coarsen, resample,
// pool): Occupied when any is (their largest log-odds), Free when at least half are Free (the mean
// log-odds of those), Unknown (0) otherwise. Cells are added in the order of the old grid's rows.
struct Pooled {
  int cells = 0, free_cells = 0;
  float free_sum = 0.0f, most = -std::numeric_limits<float>::infinity();

  void add(float v, float free) {
    ++cells;
    most = std::max(most, v);
    if (v < free) {
      ++free_cells;
      free_sum += v;
    }
  }
  float log_odds(float occupied) const {
    if (most > occupied) return most;
    return cells > 0 && 2 * free_cells >= cells ? free_sum / float(free_cells) : 0.0f;
  }
};

// For each new cell along one axis, the old cells whose centres lie inside it, [first, end); the
// old cell holding its centre when none does. `ratio` = new cell size / old cell size.
std::vector<std::pair<int, int>> covered_cells(int old_count, int new_count, double ratio) {
  std::vector<std::pair<int, int>> ranges(static_cast<std::size_t>(new_count));
  for (int k = 0; k < new_count; ++k) {
    // Old cell i's centre is at i + 0.5 old cells; it lies in [k, k + 1) new cells when
    // k * ratio - 0.5 <= i < (k + 1) * ratio - 0.5.
    int first = std::max(0, int(std::ceil(k * ratio - 0.5)));
    int end = std::min(old_count, int(std::ceil((k + 1) * ratio - 0.5)));
    if (first >= end) {
      first = std::clamp(int(std::floor((k + 0.5) * ratio)), 0, old_count - 1);
      end = first + 1;
    }
    ranges[static_cast<std::size_t>(k)] = {first, end};
  }
  return ranges;
}

// resample's new extent along one axis of `old_count` cells: rounded up to whole cells; a sliver of
// a millionth of a cell (the ratio's rounding) is none.
double resampled_count(int old_count, double ratio) { return std::max(0.0, std::ceil(old_count / ratio - 1e-6)); }

void check_resolution(double resolution) {
  if (!(resolution > 0.0) || !std::isfinite(resolution)) {
    throw Error("resample: resolution must be positive, got " + std::to_string(resolution));
  }
}

}  // namespace

double resampled_cell_count(const OccupancyGrid& grid, double resolution) {
  check_resolution(resolution);
  const double ratio = resolution / grid.resolution();
  return resampled_count(grid.width(), ratio) * resampled_count(grid.height(), ratio);
}

GridGeometry resampled_geometry(const GridGeometry& geometry, double resolution) {
  check_resolution(resolution);
  const double ratio = resolution / geometry.resolution();
  return GridGeometry(resolution, int(resampled_count(geometry.width(), ratio)),
                      int(resampled_count(geometry.height(), ratio)), geometry.origin());
}

OccupancyGrid resample(const OccupancyGrid& grid, double resolution) {
  const GridGeometry geometry = resampled_geometry(grid.geometry(), resolution);
  const double ratio = resolution / grid.resolution();
  const int w = grid.width(), h = grid.height();
  const int nw = geometry.width(), nh = geometry.height();
  OccupancyGrid out(geometry, grid.options());
  if (w == 0 || h == 0) return out;
  const float occupied = float(probability_to_log_odds(grid.options().occupied_threshold));
  const float free = float(probability_to_log_odds(grid.options().free_threshold));
  const auto columns = covered_cells(w, nw, ratio), rows = covered_cells(h, nh, ratio);
  const auto& l = grid.log_odds_data();
  for (int ny = 0; ny < nh; ++ny) {
    const auto [y0, y1] = rows[static_cast<std::size_t>(ny)];
    for (int nx = 0; nx < nw; ++nx) {
      const auto [x0, x1] = columns[static_cast<std::size_t>(nx)];
      Pooled cell;
      for (int y = y0; y < y1; ++y) {
        const float* row = l.data() + std::size_t(y) * std::size_t(w);
        for (int x = x0; x < x1; ++x) cell.add(row[x], free);
      }
      const float v = cell.log_odds(occupied);
      if (v != 0.0f) out.set_log_odds({nx, ny}, v);
    }
  }
  return out;
}

OccupancyGrid pool(const OccupancyGrid& grid, double resolution, const core::Transform2& place, int width, int height,
                   const core::Pose2& origin) {
  if (!(resolution >= grid.resolution() * (1.0 - 1e-9)) || !std::isfinite(resolution)) {
    throw Error("pool: resolution " + std::to_string(resolution) + " m is finer than the grid's " +
                std::to_string(grid.resolution()) + " m");
  }
  OccupancyGrid out(GridGeometry(resolution, width, height, origin), grid.options());
  const float occupied = float(probability_to_log_odds(grid.options().occupied_threshold));
  const float free = float(probability_to_log_odds(grid.options().free_threshold));
  std::vector<Pooled> cells(std::size_t(width) * std::size_t(height));
  // A cell p of grid has its centre at s p + c in resample(grid, resolution)'s cells.
  const double s = grid.resolution() / resolution, c = (s - 1.0) / 2.0;
  const Eigen::Matrix2d r = place.rotation_matrix() * s;
  const Eigen::Vector2d t = place.rotation_matrix() * Eigen::Vector2d(c, c) + place.translation();
  const auto& l = grid.log_odds_data();
  for (int y = 0; y < grid.height(); ++y) {
    const float* row = l.data() + std::size_t(y) * std::size_t(grid.width());
    for (int x = 0; x < grid.width(); ++x) {
      const Eigen::Vector2d q = r * Eigen::Vector2d(x, y) + t;
      const int nx = int(std::floor(q.x() + 0.5)), ny = int(std::floor(q.y() + 0.5));
      if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
      cells[std::size_t(ny) * std::size_t(width) + std::size_t(nx)].add(row[x], free);
    }
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float v = cells[std::size_t(y) * std::size_t(width) + std::size_t(x)].log_odds(occupied);
      if (v != 0.0f) out.set_log_odds({x, y}, v);
    }
  }
  return out;
}

OccupancyGrid crop_to_known(const OccupancyGrid& grid, int margin) {
  int x0 = grid.width(), y0 = grid.height(), x1 = -1, y1 = -1;
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      if (grid.state_at(y * grid.width() + x) == CellState::Unknown) continue;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  if (x1 < 0) return grid;
  x0 = std::max(0, x0 - margin), y0 = std::max(0, y0 - margin);
  x1 = std::min(grid.width() - 1, x1 + margin), y1 = std::min(grid.height() - 1, y1 + margin);
  const double res = grid.resolution();
  const core::Pose2 origin = grid.geometry().origin().compose(core::Pose2(x0 * res, y0 * res, 0.0));
  OccupancyGrid out(GridGeometry(res, x1 - x0 + 1, y1 - y0 + 1, origin), grid.options());
  const std::vector<float>& from = grid.log_odds_data();
  for (int y = y0; y <= y1; ++y) {
    const float* row = from.data() + std::size_t(y) * std::size_t(grid.width());
    for (int x = x0; x <= x1; ++x) {
      if (row[x] != 0.0f) out.set_log_odds({x - x0, y - y0}, row[x]);
    }
  }
  return out;
}

}  // namespace fleetmap::mapping

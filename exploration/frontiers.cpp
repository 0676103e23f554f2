#include "exploration/frontiers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <opencv2/imgproc.hpp>

#include "exploration/traversability.h"
#include "mapping/grid_traversal.h"

namespace fleetmap::exploration {

using mapping::CellState;

FrontierMask::FrontierMask(const mapping::OccupancyGrid& map, const FrontierOptions& options)
    : FrontierMask(map, options, {0, 0}, {map.width(), map.height()}) {}

FrontierMask::FrontierMask(const mapping::OccupancyGrid& map, const FrontierOptions& options, const Cell& lo,
                           const Cell& hi)
    : lo_{std::max(0, lo.x), std::max(0, lo.y)}, hi_{std::min(map.width(), hi.x), std::min(map.height(), hi.y)} {
  if (hi_.x <= lo_.x || hi_.y <= lo_.y) {
    hi_ = lo_;
    return;
  }
  // The widest odd square not wider than min_unknown_width_m: 2k + 1 cells.
  const int k = std::max(0, (int(std::floor(options.min_unknown_width_m / map.resolution() + 1e-9)) - 1) / 2);
  // The opening's result k cells from the padded window's edge can differ from the whole map's;
  // padding by 2k + 1 (the +1 for the neighbour test) keeps the window exact.
  // One more for the gap test of a cell beside the window, whose lines reach 2k + 1 cells.
  const int pad = 2 * k + 2;
  const Cell plo{std::max(0, lo_.x - pad), std::max(0, lo_.y - pad)};
  const Cell phi{std::min(map.width(), hi_.x + pad), std::min(map.height(), hi_.y + pad)};
  cv::Mat unknown(phi.y - plo.y, phi.x - plo.x, CV_8UC1);
  for (int y = plo.y; y < phi.y; ++y) {
    auto* row = unknown.ptr<std::uint8_t>(y - plo.y);
    for (int x = plo.x; x < phi.x; ++x) row[x - plo.x] = map.observed({x, y}) ? 0 : 255;
  }
  const cv::Mat never_observed = options.gaps_in_open_space ? unknown.clone() : cv::Mat();
  // The narrow strips: an opening by a smaller square (3 cells at least), when narrower than k's.
  const int k_narrow = std::max(1, (int(std::floor(options.min_narrow_width_m / map.resolution() + 1e-9)) - 1) / 2);
  cv::Mat narrow;
  if (options.min_narrow_width_m > 0.0 && k_narrow < k) {
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * k_narrow + 1, 2 * k_narrow + 1));
    cv::morphologyEx(unknown, narrow, cv::MORPH_OPEN, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  }
  if (k > 0) {
    // A border of 0: beyond the map there is nothing to explore; inside it, the padding makes the
    // window's border harmless.
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * k + 1, 2 * k + 1));
    cv::morphologyEx(unknown, unknown, cv::MORPH_OPEN, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  }
  const int w = hi_.x - lo_.x;
  frontier_.assign(std::size_t(w) * std::size_t(hi_.y - lo_.y), 0);
  const auto inside = [&](int x, int y) { return x >= plo.x && y >= plo.y && x < phi.x && y < phi.y; };
  const auto never = [&](int x, int y) { return inside(x, y) && never_observed.at<std::uint8_t>(y - plo.y, x - plo.x) != 0; };
  // Free within `width` never-observed cells from (x, y) along (dx, dy).
  const int width = 2 * k + 1;
  const auto free_along = [&](int x, int y, int dx, int dy) {
    for (int s = 1; s <= width; ++s) {
      const int nx = x + s * dx, ny = y + s * dy;
      if (map.state({nx, ny}) == CellState::Free) return true;
      if (!never(nx, ny)) return false;
    }
    return false;
  };
  const auto wide_unknown = [&](int x, int y) {
    return inside(x, y) && unknown.at<std::uint8_t>(y - plo.y, x - plo.x) != 0;
  };
  const auto narrow_unknown = [&](int x, int y) {
    return !narrow.empty() && inside(x, y) && narrow.at<std::uint8_t>(y - plo.y, x - plo.x) != 0;
  };
  const auto gap = [&](int x, int y) {
    if (never_observed.empty() || !never(x, y)) return false;
    // A gap: no occupied cell touches it, and free space lies on both sides of it along some line
    // (the unseen face of a wall has the wall's inside behind it, not free space).
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (map.state({x + dx, y + dy}) == CellState::Occupied) return false;
    for (const auto& [dx, dy] : {std::pair{1, 0}, {0, 1}, {1, 1}, {1, -1}})
      if (free_along(x, y, dx, dy) && free_along(x, y, -dx, -dy)) return true;
    return false;
  };
  for (int y = lo_.y; y < hi_.y; ++y) {
    for (int x = lo_.x; x < hi_.x; ++x) {
      if (map.state({x, y}) != CellState::Free) continue;
      auto& f = frontier_[std::size_t((y - lo_.y) * w + (x - lo_.x))];
      if (wide_unknown(x + 1, y) || wide_unknown(x - 1, y) || wide_unknown(x, y + 1) || wide_unknown(x, y - 1)) f = kWide;
      else if (gap(x + 1, y) || gap(x - 1, y) || gap(x, y + 1) || gap(x, y - 1)) f = kGap;
      else if (narrow_unknown(x + 1, y) || narrow_unknown(x - 1, y) || narrow_unknown(x, y + 1) || narrow_unknown(x, y - 1))
        f = kNarrow;
    }
  }
}

std::uint8_t FrontierMask::kind(const Cell& c) const {
  if (c.x < lo_.x || c.y < lo_.y || c.x >= hi_.x || c.y >= hi_.y) return 0;
  return frontier_[std::size_t((c.y - lo_.y) * (hi_.x - lo_.x) + (c.x - lo_.x))];
}

bool is_frontier(const mapping::OccupancyGrid& map, const Cell& c, const FrontierOptions& options) {
  return FrontierMask(map, options, c, {c.x + 1, c.y + 1})(c);
}

std::vector<FrontierRegion> find_frontier_regions(const mapping::OccupancyGrid& map, const FrontierOptions& options) {
  const int w = map.width(), h = map.height();
  const FrontierMask mask(map, options);
  // Per cell: 0 none, else its FrontierMask kind; kDone once in a region.
  constexpr std::uint8_t kDone = 255;
  std::vector<std::uint8_t> frontier(std::size_t(w) * std::size_t(h), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) frontier[std::size_t(y * w + x)] = mask.kind({x, y});

  std::vector<FrontierRegion> regions;
  std::vector<int> stack;
  const int reach = 1 + std::max(0, options.join_gap_cells);
  for (int i = 0; i < w * h; ++i) {
    if (frontier[std::size_t(i)] == 0 || frontier[std::size_t(i)] == kDone) continue;
    FrontierRegion region;
    region.kind = frontier[std::size_t(i)];
    const bool narrow = region.kind == FrontierMask::kNarrow;
    frontier[std::size_t(i)] = kDone;
    stack.assign(1, i);
    while (!stack.empty()) {
      const int j = stack.back();
      stack.pop_back();
      const Cell c{j % w, j / w};
      region.cells.push_back(c);
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dx = -reach; dx <= reach; ++dx) {
          const int nx = c.x + dx, ny = c.y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const int k = ny * w + nx;
          // Narrow strips make regions of their own: a room's frontier is not to reach along a wall.
          if (frontier[std::size_t(k)] != 0 && frontier[std::size_t(k)] != kDone &&
              (frontier[std::size_t(k)] == FrontierMask::kNarrow) == narrow) {
            region.kind = std::min(region.kind, frontier[std::size_t(k)]);
            frontier[std::size_t(k)] = kDone;
            stack.push_back(k);
          }
        }
    }
    if (region.size() < options.min_region_cells) continue;
    std::sort(region.cells.begin(), region.cells.end(),
              [](const Cell& a, const Cell& b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
    for (const Cell& c : region.cells) region.centroid_m += map.geometry().cell_center(c);
    region.centroid_m /= double(region.size());
    regions.push_back(std::move(region));
  }
  return regions;
}

bool sees_over_free(const mapping::OccupancyGrid& map, const Cell& from, const Cell& to) {
  const auto& g = map.geometry();
  return mapping::traverse_segment(g, g.cell_center(from), g.cell_center(to),
                                   [&](const Cell& c, double) { return c == to || map.state(c) == CellState::Free; });
}

namespace {

// A never-observed 4-neighbour of a frontier cell (one exists by definition).
Cell unseen_neighbour(const mapping::OccupancyGrid& map, const Cell& f) {
  for (const Cell& n : {Cell{f.x + 1, f.y}, Cell{f.x - 1, f.y}, Cell{f.x, f.y + 1}, Cell{f.x, f.y - 1}})
    if (map.contains(n) && !map.observed(n)) return n;
  return f;
}

// The known-free cells within `range` cells of the unseen cell, connected to the frontier cell `f`,
// in breadth-first order.
const std::vector<Cell>& cells_around(const mapping::OccupancyGrid& map, const Cell& f, const Cell& unknown,
                                      double range) {
  thread_local std::vector<Cell> queue;
  thread_local std::vector<std::uint8_t> seen;  // a window around the unseen cell
  const int half = int(std::ceil(range)) + 1, side = 2 * half + 1;
  seen.assign(std::size_t(side) * std::size_t(side), 0);
  const auto mark = [&](const Cell& c) {
    auto& m = seen[std::size_t((c.y - unknown.y + half) * side + (c.x - unknown.x + half))];
    const bool was = m != 0;
    m = 1;
    return !was;
  };
  queue.assign(1, f);
  mark(f);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const Cell c = queue[head];
    for (const Cell& m : {Cell{c.x + 1, c.y}, Cell{c.x - 1, c.y}, Cell{c.x, c.y + 1}, Cell{c.x, c.y - 1}}) {
      if (!map.contains(m) || map.state(m) != CellState::Free) continue;
      const double dx = m.x - unknown.x, dy = m.y - unknown.y;
      if (dx * dx + dy * dy > range * range) continue;
      if (mark(m)) queue.push_back(m);
    }
  }
  return queue;
}

// The goal from which to observe `unknown`, beside frontier cell `f` (see find_targets).
std::optional<Cell> observation_goal(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& passage,
                                     const Cell& f, const Cell& unknown, const GoalFilter& usable,
                                     const TargetOptions& options) {
  const int w = map.width();
  const double res = map.resolution();
  const double approach = options.approach_radius_m / res;
  const auto d2 = [](const Cell& a, const Cell& b) { return double(a.x - b.x) * (a.x - b.x) + double(a.y - b.y) * (a.y - b.y); };
  const auto passage_of = [&](const Cell& c) { return Passage(passage[std::size_t(c.y * w + c.x)]); };
  const auto good = [&](const Cell& c) { return usable(f, c) && sees_over_free(map, c, unknown); };
  std::vector<std::pair<double, Cell>> by_distance;
  // Near first; the far range (through a gap the robot cannot pass) only when nothing near will do.
  const double near = options.observe_range_m / res, far = std::max(near, options.max_observe_range_m / res);
  for (const double range : {near, far}) {
    const bool first = range == near;
    if (!first && far <= near) break;
    const auto& cells = cells_around(map, f, unknown, range);
    if (first) {
      for (const Cell& c : cells)
        if (d2(c, f) <= approach * approach && passage_of(c) == Passage::Clear && good(c)) return c;
    }
    by_distance.clear();
    for (const Cell& c : cells) {
      const double d = d2(c, unknown);
      if (passage_of(c) != Passage::Blocked && (first || d > near * near)) by_distance.push_back({d, c});
    }
    std::stable_sort(by_distance.begin(), by_distance.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [d, c] : by_distance)
      if (good(c)) return c;
  }
  // No cell sees it yet: the usable cell nearest to it, to look from closer (the map around a
  // doorway seen from afar may still hold a stray hit that narrows it).
  by_distance.clear();
  for (const Cell& c : cells_around(map, f, unknown, far))
    if (passage_of(c) != Passage::Blocked) by_distance.push_back({d2(c, unknown), c});
  std::stable_sort(by_distance.begin(), by_distance.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [d, c] : by_distance)
    if (usable(f, c)) return c;
  return std::nullopt;
}

}  // namespace

TargetSet find_targets(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& passage,
                       const GoalFilter& usable, const TargetOptions& options) {
  const auto regions = find_frontier_regions(map, options.frontiers);
  const double piece_cells = std::max(1.0, options.piece_radius_m / map.resolution());
  TargetSet out;
  for (const std::uint8_t kind : {FrontierMask::kWide, FrontierMask::kGap, FrontierMask::kNarrow}) {
    if (!out.targets.empty()) break;  // a more promising kind has targets
    for (std::size_t r = 0; r < regions.size(); ++r) {
      if (regions[r].kind != kind) continue;
      const auto& cells = regions[r].cells;
      // Farthest-point sampling: seeds until every cell is within a piece radius of one.
      std::vector<Cell> seeds;
      std::vector<double> d2(cells.size(), std::numeric_limits<double>::infinity());
      std::size_t next = 0;
      {
        // Start from the cell nearest the centroid so a small region's target is its middle.
        const Eigen::Vector2d c = regions[r].centroid_m;
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < cells.size(); ++i) {
          const double d = (map.geometry().cell_center(cells[i]) - c).squaredNorm();
          if (d < best) best = d, next = i;
        }
      }
      while (true) {
        seeds.push_back(cells[next]);
        double far = -1.0;
        for (std::size_t i = 0; i < cells.size(); ++i) {
          const double dx = cells[i].x - cells[next].x, dy = cells[i].y - cells[next].y;
          d2[i] = std::min(d2[i], dx * dx + dy * dy);
        }
        for (std::size_t i = 0; i < cells.size(); ++i) {
          if (d2[i] > far) far = d2[i], next = i;
        }
        if (far <= piece_cells * piece_cells) break;
      }
      // Each cell belongs to its nearest seed; the piece size is its cell count.
      std::vector<int> counts(seeds.size(), 0);
      for (const Cell& c : cells) {
        std::size_t best = 0;
        double best_d = std::numeric_limits<double>::infinity();
        for (std::size_t s = 0; s < seeds.size(); ++s) {
          const double dx = c.x - seeds[s].x, dy = c.y - seeds[s].y, d = dx * dx + dy * dy;
          if (d < best_d) best_d = d, best = s;
        }
        ++counts[best];
      }
      for (std::size_t s = 0; s < seeds.size(); ++s) {
        const Cell unknown = unseen_neighbour(map, seeds[s]);
        const auto goal = observation_goal(map, passage, seeds[s], unknown, usable, options);
        if (!goal) {
          out.without_goal.push_back(seeds[s]);
          continue;
        }
        out.targets.push_back({seeds[s], unknown, *goal, map.geometry().cell_center(*goal), counts[s], int(r), kind});
      }
    }
  }
  return out;
}

int frontier_cells_near(const mapping::OccupancyGrid& map, const Cell& c, double radius_m,
                        const FrontierOptions& options, std::uint8_t up_to_kind) {
  const int r = int(std::ceil(radius_m / map.resolution()));
  const double r2 = double(r) * r;
  const FrontierMask mask(map, options, {c.x - r, c.y - r}, {c.x + r + 1, c.y + r + 1});
  int n = 0;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (double(dx * dx + dy * dy) <= r2) {
        const std::uint8_t kind = mask.kind({c.x + dx, c.y + dy});
        n += kind != 0 && kind <= up_to_kind;
      }
  return n;
}

}  // namespace fleetmap::exploration

#include "exploration/frontiers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <opencv2/imgproc.hpp>

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
  const int pad = 2 * k + 1;
  const Cell plo{std::max(0, lo_.x - pad), std::max(0, lo_.y - pad)};
  const Cell phi{std::min(map.width(), hi_.x + pad), std::min(map.height(), hi_.y + pad)};
  cv::Mat unknown(phi.y - plo.y, phi.x - plo.x, CV_8UC1);
  for (int y = plo.y; y < phi.y; ++y) {
    auto* row = unknown.ptr<std::uint8_t>(y - plo.y);
    for (int x = plo.x; x < phi.x; ++x) row[x - plo.x] = map.observed({x, y}) ? 0 : 255;
  }
  if (k > 0) {
    // A border of 0: beyond the map there is nothing to explore; inside it, the padding makes the
    // window's border harmless.
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * k + 1, 2 * k + 1));
    cv::morphologyEx(unknown, unknown, cv::MORPH_OPEN, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  }
  const int w = hi_.x - lo_.x;
  frontier_.assign(std::size_t(w) * std::size_t(hi_.y - lo_.y), 0);
  const auto wide_unknown = [&](int x, int y) {
    return x >= plo.x && y >= plo.y && x < phi.x && y < phi.y && unknown.at<std::uint8_t>(y - plo.y, x - plo.x) != 0;
  };
  for (int y = lo_.y; y < hi_.y; ++y) {
    for (int x = lo_.x; x < hi_.x; ++x) {
      if (map.state({x, y}) != CellState::Free) continue;
      frontier_[std::size_t((y - lo_.y) * w + (x - lo_.x))] =
          wide_unknown(x + 1, y) || wide_unknown(x - 1, y) || wide_unknown(x, y + 1) || wide_unknown(x, y - 1);
    }
  }
}

bool FrontierMask::operator()(const Cell& c) const {
  if (c.x < lo_.x || c.y < lo_.y || c.x >= hi_.x || c.y >= hi_.y) return false;
  return frontier_[std::size_t((c.y - lo_.y) * (hi_.x - lo_.x) + (c.x - lo_.x))] != 0;
}

bool is_frontier(const mapping::OccupancyGrid& map, const Cell& c, const FrontierOptions& options) {
  return FrontierMask(map, options, c, {c.x + 1, c.y + 1})(c);
}

std::vector<FrontierRegion> find_frontier_regions(const mapping::OccupancyGrid& map, const FrontierOptions& options) {
  const int w = map.width(), h = map.height();
  const FrontierMask mask(map, options);
  std::vector<std::uint8_t> frontier(std::size_t(w) * std::size_t(h), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) frontier[std::size_t(y * w + x)] = mask({x, y});

  std::vector<FrontierRegion> regions;
  std::vector<int> stack;
  for (int i = 0; i < w * h; ++i) {
    if (frontier[std::size_t(i)] != 1) continue;
    FrontierRegion region;
    frontier[std::size_t(i)] = 2;
    stack.assign(1, i);
    while (!stack.empty()) {
      const int j = stack.back();
      stack.pop_back();
      const Cell c{j % w, j / w};
      region.cells.push_back(c);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = c.x + dx, ny = c.y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const int k = ny * w + nx;
          if (frontier[std::size_t(k)] == 1) {
            frontier[std::size_t(k)] = 2;
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

namespace {

// Nearest traversable cell to `from` by a BFS over known-free cells, up to `max_steps` steps.
std::optional<Cell> approach_cell(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& traversable,
                                  const Cell& from, int max_steps) {
  const int w = map.width();
  if (traversable[std::size_t(from.y * w + from.x)]) return from;
  thread_local std::vector<std::pair<Cell, int>> queue;
  thread_local std::vector<int> seen;
  queue.assign(1, {from, 0});
  seen.assign(1, from.y * w + from.x);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const auto [c, d] = queue[head];
    if (d >= max_steps) continue;
    const Cell n[4] = {{c.x + 1, c.y}, {c.x - 1, c.y}, {c.x, c.y + 1}, {c.x, c.y - 1}};
    for (const Cell& m : n) {
      if (!map.contains(m) || map.state(m) != CellState::Free) continue;
      const int k = m.y * w + m.x;
      if (std::find(seen.begin(), seen.end(), k) != seen.end()) continue;
      if (traversable[std::size_t(k)]) return m;
      seen.push_back(k);
      queue.push_back({m, d + 1});
    }
  }
  return std::nullopt;
}

}  // namespace

std::vector<Target> make_targets(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& traversable,
                                 const TargetOptions& options) {
  const auto regions = find_frontier_regions(map, options.frontiers);
  const double piece_cells = std::max(1.0, options.piece_radius_m / map.resolution());
  const int approach_steps = std::max(1, int(std::ceil(options.approach_radius_m / map.resolution())));
  std::vector<Target> targets;
  for (std::size_t r = 0; r < regions.size(); ++r) {
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
      const auto goal = approach_cell(map, traversable, seeds[s], approach_steps);
      if (!goal) continue;
      targets.push_back({seeds[s], *goal, map.geometry().cell_center(*goal), counts[s], int(r)});
    }
  }
  return targets;
}

int frontier_cells_near(const mapping::OccupancyGrid& map, const Cell& c, double radius_m,
                        const FrontierOptions& options) {
  const int r = int(std::ceil(radius_m / map.resolution()));
  const double r2 = double(r) * r;
  const FrontierMask mask(map, options, {c.x - r, c.y - r}, {c.x + r + 1, c.y + r + 1});
  int n = 0;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (double(dx * dx + dy * dy) <= r2 && mask({c.x + dx, c.y + dy})) ++n;
  return n;
}

}  // namespace fleetmap::exploration

#include "sim/world.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "exploration/traversability.h"
#include "mapping/distance_field.h"
#include "mapping/ray_cast.h"

namespace fleetmap::sim {

World::World(mapping::OccupancyGrid truth, std::vector<Eigen::Vector2d> landmarks)
    : truth_(std::move(truth)), landmarks_(std::move(landmarks)) {
  const int w = truth_.width(), h = truth_.height();
  // Outside the map is blocked too (a map with no wall is not an empty plain).
  std::vector<std::uint8_t> blocked_cells(std::size_t(w) * std::size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) blocked_cells[std::size_t(y * w + x)] = blocked({x, y});
  centre_clearance_m_ = mapping::distance_to_blocked(w, h, blocked_cells, true);
  for (float& d : centre_clearance_m_) d *= float(truth_.resolution());
}

double World::clearance(const Eigen::Vector2d& p, double horizon_m) const {
  const auto& g = geometry();
  const Eigen::Vector2d q = g.world_to_grid(p);  // continuous cell coordinates
  const Cell c{int(std::floor(q.x())), int(std::floor(q.y()))};
  if (!g.contains(c) || blocked(c)) return 0.0;
  const double res = g.resolution();
  // Fast path: the centre clearance bounds the true one from below by one cell diagonal.
  const double centre = centre_clearance_m_[std::size_t(g.index(c))];
  const double lower = centre - 1.4143 * res;
  if (lower >= horizon_m) return horizon_m;
  // The blocked cell nearest to the cell's centre is `centre` away from it, so the nearest blocked
  // square to p lies within centre + one cell of c: no need to look farther than that.
  const int r = int(std::ceil(std::min(horizon_m, centre) / res)) + 1;
  double best2 = horizon_m * horizon_m;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const Cell n{c.x + dx, c.y + dy};
      if (!blocked(n)) continue;
      // Distance from q to the square [n.x, n.x+1] x [n.y, n.y+1], in cells.
      const double ex = std::max({double(n.x) - q.x(), 0.0, q.x() - double(n.x + 1)});
      const double ey = std::max({double(n.y) - q.y(), 0.0, q.y() - double(n.y + 1)});
      best2 = std::min(best2, (ex * ex + ey * ey) * res * res);
    }
  }
  return std::sqrt(best2);
}

std::optional<Eigen::Vector2d> World::nearest_blocked_point(const Eigen::Vector2d& p, double horizon_m) const {
  const auto& g = geometry();
  const Eigen::Vector2d q = g.world_to_grid(p);
  const Cell c{int(std::floor(q.x())), int(std::floor(q.y()))};
  const int r = int(std::ceil(horizon_m / g.resolution())) + 1;
  double best2 = (horizon_m / g.resolution()) * (horizon_m / g.resolution()) + 1e-9;
  std::optional<Eigen::Vector2d> best;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const Cell n{c.x + dx, c.y + dy};
      if (!blocked(n)) continue;
      // The point of the square [n.x, n.x+1] x [n.y, n.y+1] nearest to q, in cells.
      const Eigen::Vector2d near(std::clamp(q.x(), double(n.x), double(n.x + 1)), std::clamp(q.y(), double(n.y), double(n.y + 1)));
      const double d2 = (near - q).squaredNorm();
      if (d2 < best2) best2 = d2, best = g.grid_to_world(near);
    }
  }
  return best;
}

bool World::disc_free(const Eigen::Vector2d& p, double radius_m) const {
  return clearance(p, radius_m + 1e-9) > radius_m;
}

namespace {

// The 4-connected components of the cells flagged in `fits` (w x h, row-major).
ReachableRegions label_regions(const std::vector<std::uint8_t>& fits, int w, int h) {
  const std::size_t n = fits.size();
  ReachableRegions out;
  out.label.assign(n, -1);
  std::vector<int> stack;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (!fits[seed] || out.label[seed] >= 0) continue;
    const int region = int(out.cells.size());
    std::int64_t size = 0;
    out.label[seed] = region;
    stack.push_back(int(seed));
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      ++size;
      const int x = i % w, y = i / w;
      for (const auto& [nx, ny] : {std::pair{x + 1, y}, {x - 1, y}, {x, y + 1}, {x, y - 1}}) {
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const std::size_t j = std::size_t(ny) * std::size_t(w) + std::size_t(nx);
        if (!fits[j] || out.label[j] >= 0) continue;
        out.label[j] = region;
        stack.push_back(int(j));
      }
    }
    out.cells.push_back(size);
    if (out.largest < 0 || size > out.cells[std::size_t(out.largest)]) out.largest = region;
  }
  return out;
}

}  // namespace

ReachableRegions World::reachable_regions(double robot_radius_m) const {
  const auto& g = geometry();
  const std::size_t n = std::size_t(g.cell_count());
  std::vector<std::uint8_t> blocking(n);
  for (std::size_t i = 0; i < n; ++i) blocking[i] = truth_.state_at(int(i)) != mapping::CellState::Free;
  return label_regions(exploration::fitting_cells(g, blocking, robot_radius_m), g.width(), g.height());
}

ObservableSpace World::observable_space(const std::vector<Eigen::Vector2d>& starts, double robot_radius_m,
                                       double sensor_range_m) const {
  const auto& g = geometry();
  const int w = g.width(), h = g.height();
  const std::size_t n = std::size_t(g.cell_count());
  const double res = g.resolution();
  ObservableSpace out;
  out.cell_area_m2 = res * res;
  std::vector<std::uint8_t> blocking(n);
  for (std::size_t i = 0; i < n; ++i) {
    blocking[i] = truth_.state_at(int(i)) != mapping::CellState::Free;
    out.free_cells += !blocking[i];
  }
  const std::vector<std::uint8_t> fits = exploration::fitting_cells(g, blocking, robot_radius_m);
  const ReachableRegions regions = label_regions(fits, w, h);
  if (regions.largest >= 0) out.largest_region_poses = regions.cells[std::size_t(regions.largest)];

  // Poses: from the fitting cell nearest to each start (a start need not be a cell centre), through
  // 4-connected fitting cells.
  std::vector<std::uint8_t> pose(n, 0);
  std::vector<int> stack;
  const int seek = int(std::ceil(robot_radius_m / res)) + 2;
  for (const auto& s : starts) {
    const auto c = g.world_to_cell(s);
    if (!c || blocking[std::size_t(g.index(*c))]) continue;
    // Breadth-first over free cells to the nearest fitting one.
    std::vector<std::pair<int, int>> queue = {{g.index(*c), 0}};
    std::vector<int> seen = {g.index(*c)};
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const auto [i, depth] = queue[head];
      if (fits[std::size_t(i)]) {
        if (!pose[std::size_t(i)]) pose[std::size_t(i)] = 1, stack.push_back(i);
        break;
      }
      if (depth >= seek) continue;
      const int x = i % w, y = i / w;
      for (const auto& [nx, ny] : {std::pair{x + 1, y}, {x - 1, y}, {x, y + 1}, {x, y - 1}}) {
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const int j = ny * w + nx;
        if (blocking[std::size_t(j)] || std::find(seen.begin(), seen.end(), j) != seen.end()) continue;
        seen.push_back(j);
        queue.push_back({j, depth + 1});
      }
    }
  }
  const auto flood = [&](std::vector<std::uint8_t>& mark, const auto& allowed) {
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const int x = i % w, y = i / w;
      for (const auto& [nx, ny] : {std::pair{x + 1, y}, {x - 1, y}, {x, y + 1}, {x, y - 1}}) {
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const int j = ny * w + nx;
        if (mark[std::size_t(j)] || !allowed(j)) continue;
        mark[std::size_t(j)] = 1;
        stack.push_back(j);
      }
    }
  };
  {
    std::vector<int> start_regions;
    for (int i : stack) start_regions.push_back(regions.at(i));
    std::sort(start_regions.begin(), start_regions.end());
    out.start_regions = int(std::unique(start_regions.begin(), start_regions.end()) - start_regions.begin());
  }
  flood(pose, [&](int j) { return fits[std::size_t(j)] != 0; });
  std::vector<int> boundary;  // poses beside a cell that is not one
  for (int i = 0; i < int(n); ++i) {
    if (!pose[std::size_t(i)]) continue;
    ++out.poses;
    const int x = i % w, y = i / w;
    if (x == 0 || y == 0 || x == w - 1 || y == h - 1 || !pose[std::size_t(i - 1)] || !pose[std::size_t(i + 1)] ||
        !pose[std::size_t(i - w)] || !pose[std::size_t(i + w)])
      boundary.push_back(i);
  }
  if (out.poses == 0) return out;

  // A line of sight runs through 4-connected free cells: only the free cells connected to the poses
  // can be observed.
  std::vector<std::uint8_t> connected = pose;
  for (int i = 0; i < int(n); ++i)
    if (pose[std::size_t(i)]) stack.push_back(i);
  flood(connected, [&](int j) { return blocking[std::size_t(j)] == 0; });

  // Distance from every cell to the nearest pose (exact), and a nearby pose (the labelled
  // transform's nearest, with a 5x5 mask: close to the nearest).
  cv::Mat not_pose(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y) {
    auto* row = not_pose.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) row[x] = pose[std::size_t(y * w + x)] ? 0 : 255;
  }
  const std::vector<float> dist = mapping::distance_to_blocked(w, h, pose, false);
  cv::Mat approx, labels;
  cv::distanceTransform(not_pose, approx, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  std::vector<int> pose_of_label(std::size_t(out.poses) + 1, -1);
  for (int i = 0; i < int(n); ++i) {
    if (!pose[std::size_t(i)]) continue;
    const int label = labels.at<int>(i / w, i % w);
    if (label >= 0 && label < int(pose_of_label.size())) pose_of_label[std::size_t(label)] = i;
  }

  // Boundary poses in square buckets at least a sensor range wide: the poses within range of a
  // cell lie in the 3 x 3 buckets around it.
  const double range_cells = sensor_range_m / res, radius_cells = robot_radius_m / res;
  const int bucket = std::max(8, int(std::ceil(range_cells)));
  const int bw = (w + bucket - 1) / bucket, bh = (h + bucket - 1) / bucket;
  std::vector<std::vector<int>> buckets(std::size_t(bw) * std::size_t(bh));
  for (int i : boundary) buckets[std::size_t((i / w) / bucket * bw + (i % w) / bucket)].push_back(i);

  const auto sees = [&](int from, int to) {
    return mapping::line_of_sight(truth_, g.cell_center(g.cell_of_index(from)), g.cell_center(g.cell_of_index(to)));
  };
  const auto within_range = [&](int a, int b) {
    const double dx = a % w - b % w, dy = a / w - b / w;
    return dx * dx + dy * dy <= range_cells * range_cells + 1e-9;
  };
  std::vector<std::pair<double, int>> candidates;
  for (int i = 0; i < int(n); ++i) {
    if (!connected[std::size_t(i)]) continue;
    const double d = dist[std::size_t(i)];
    if (d > range_cells + 1e-6) continue;
    // Within the robot's own disc at a pose (no wall inside it), a cell is in sight.
    bool seen = pose[std::size_t(i)] || d <= std::min(radius_cells, range_cells) + 1e-6;
    if (!seen) {
      const int near = pose_of_label[std::size_t(std::max(0, labels.at<int>(i / w, i % w)))];
      seen = near >= 0 && within_range(near, i) && sees(near, i);
    }
    if (!seen) {
      // Any line of sight from a pose leaves the poses at a boundary pose no farther away.
      candidates.clear();
      const int bx = (i % w) / bucket, by = (i / w) / bucket;
      for (int y = std::max(0, by - 1); y <= std::min(bh - 1, by + 1); ++y)
        for (int x = std::max(0, bx - 1); x <= std::min(bw - 1, bx + 1); ++x)
          for (int p : buckets[std::size_t(y * bw + x)]) {
            const double dx = p % w - i % w, dy = p / w - i / w;
            const double d2 = dx * dx + dy * dy;
            if (d2 <= range_cells * range_cells + 1e-9) candidates.push_back({d2, p});
          }
      std::sort(candidates.begin(), candidates.end());
      for (const auto& [d2, p] : candidates)
        if (sees(p, i)) {
          seen = true;
          break;
        }
    }
    if (!seen) continue;
    out.observable.push_back(i);
    if (d > radius_cells + 1e-6) out.unreachable.push_back(i);
  }
  return out;
}

std::vector<Eigen::Vector2d> landmarks_along_walls(const mapping::OccupancyGrid& truth, double per_metre,
                                                   core::Random& rng) {
  std::vector<Eigen::Vector2d> out;
  if (per_metre <= 0.0) return out;
  // Free cells with a blocked 4-neighbour: each stands for one cell length of wall.
  const double p = std::min(1.0, per_metre * truth.resolution());
  for (int y = 0; y < truth.height(); ++y) {
    for (int x = 0; x < truth.width(); ++x) {
      if (truth.state({x, y}) != mapping::CellState::Free) continue;
      const Cell n[4] = {{x + 1, y}, {x - 1, y}, {x, y + 1}, {x, y - 1}};
      const bool by_wall = std::any_of(std::begin(n), std::end(n),
                                       [&](const Cell& c) { return truth.state(c) != mapping::CellState::Free; });
      if (by_wall && rng.bernoulli(p)) out.push_back(truth.geometry().cell_center({x, y}));
    }
  }
  return out;
}

}  // namespace fleetmap::sim

#include "sim/world.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace fleetmap::sim {

World::World(mapping::OccupancyGrid truth, std::vector<Eigen::Vector2d> landmarks)
    : truth_(std::move(truth)), landmarks_(std::move(landmarks)) {
  const int w = truth_.width(), h = truth_.height();
  // A ring of blocked cells around the map: outside the map is blocked too (distanceTransform
  // would otherwise take the image border for open space, and a map with no wall for empty plains).
  cv::Mat free(h + 2, w + 2, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) free.at<std::uint8_t>(y + 1, x + 1) = blocked({x, y}) ? 0 : 255;
  cv::Mat dist;
  cv::distanceTransform(free, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  centre_clearance_m_.resize(std::size_t(w) * std::size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      centre_clearance_m_[std::size_t(y * w + x)] = dist.at<float>(y + 1, x + 1) * float(truth_.resolution());
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

bool World::disc_free(const Eigen::Vector2d& p, double radius_m) const {
  return clearance(p, radius_m + 1e-9) > radius_m;
}

std::vector<int> World::reachable_free_cells(const std::vector<Eigen::Vector2d>& starts) const {
  const int w = truth_.width(), h = truth_.height();
  std::vector<std::uint8_t> seen(std::size_t(w) * std::size_t(h), 0);
  std::vector<int> out, stack;
  for (const auto& s : starts) {
    const auto c = geometry().world_to_cell(s);
    if (!c || blocked(*c) || seen[std::size_t(geometry().index(*c))]) continue;
    stack.push_back(geometry().index(*c));
    seen[std::size_t(stack.back())] = 1;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      out.push_back(i);
      const int x = i % w, y = i / w;
      const int n[4][2] = {{x + 1, y}, {x - 1, y}, {x, y + 1}, {x, y - 1}};
      for (const auto& m : n) {
        if (m[0] < 0 || m[1] < 0 || m[0] >= w || m[1] >= h) continue;
        const int j = m[1] * w + m[0];
        if (seen[std::size_t(j)] || blocked({m[0], m[1]})) continue;
        seen[std::size_t(j)] = 1;
        stack.push_back(j);
      }
    }
  }
  std::sort(out.begin(), out.end());
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

#include "merging/prepared_grid.h"

#include "merging/grid_level.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "mapping/state_mask.h"

namespace fleetmap::merging {

namespace {

// Obstacles standing alone: for each of `sizes`, the occupied cells of components (joined across
// gaps of `gap` cells) whose bounding box is at most that many cells on its longer side.
std::vector<cv::Mat> find_standing(const cv::Mat& occupied, int gap, const std::vector<int>& sizes) {
  cv::Mat joined;  // a new matrix: dilating into a header of `occupied` would write into it
  if (gap > 0) cv::dilate(occupied, joined, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * gap + 1, 2 * gap + 1}));
  else joined = occupied;
  cv::Mat labels;
  // Labels only: OpenCV's statistics cost ten times the labelling on a large map; the boxes come
  // from the occupied cells alone (below).
  const int n = cv::connectedComponents(joined, labels, 8, CV_32S);
  // The box of each joined component: its occupied cells' box grown by `gap` (the ellipse reaches
  // `gap` cells along both axes), clipped to the map as the dilation is.
  std::vector<cv::Rect> boxes(std::size_t(std::max(n, 1)), cv::Rect());
  std::vector<int> x0(boxes.size(), occupied.cols), y0(boxes.size(), occupied.rows), x1(boxes.size(), -1),
      y1(boxes.size(), -1);
  for (int y = 0; y < occupied.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const auto* o = occupied.ptr<std::uint8_t>(y);
    for (int x = 0; x < occupied.cols; ++x) {
      if (!o[x]) continue;
      const auto i = std::size_t(l[x]);
      x0[i] = std::min(x0[i], x), x1[i] = std::max(x1[i], x), y0[i] = std::min(y0[i], y), y1[i] = std::max(y1[i], y);
    }
  }
  std::vector<int> extent(boxes.size(), 0);
  for (std::size_t i = 1; i < boxes.size(); ++i) {
    if (x1[i] < 0) continue;
    const int width = std::min(x1[i] + gap, occupied.cols - 1) - std::max(x0[i] - gap, 0) + 1;
    const int height = std::min(y1[i] + gap, occupied.rows - 1) - std::max(y0[i] - gap, 0) + 1;
    // The dilation grew the box by `gap` on each side.
    extent[i] = std::max(width, height) - 2 * gap;
  }
  std::vector<cv::Mat> masks;
  for (const int size : sizes) {
    std::vector<std::uint8_t> small(boxes.size(), 0);
    bool any = false;
    for (std::size_t i = 1; i < boxes.size(); ++i)
      if (x1[i] >= 0 && extent[i] <= size) small[i] = 255, any = true;
    cv::Mat mask = cv::Mat::zeros(occupied.size(), CV_8U);
    for (int y = 0; any && y < occupied.rows; ++y) {
      const int* l = labels.ptr<int>(y);
      const auto* o = occupied.ptr<std::uint8_t>(y);
      auto* c = mask.ptr<std::uint8_t>(y);
      for (int x = 0; x < occupied.cols; ++x) c[x] = o[x] ? small[std::size_t(l[x])] : 0;
    }
    masks.push_back(std::move(mask));
  }
  return masks;
}

// Marks free the unknown cells that touch both a free and an occupied cell (8-neighbourhood);
// returns how many. See PrepareOptions::close_seams.
int close_seams(const cv::Mat& occupied, cv::Mat& free) {
  cv::Mat free_near, occupied_near;
  cv::dilate(free, free_near, cv::Mat::ones(3, 3, CV_8U));
  cv::dilate(occupied, occupied_near, cv::Mat::ones(3, 3, CV_8U));
  const cv::Mat seam = free_near & occupied_near & ~(free | occupied);
  free |= seam;
  return cv::countNonZero(seam);
}

// Clears the occupied components (8-connected) of fewer than `min_cells` cells; returns how many
// cells it cleared. Components of one or two cells are told by their neighbours alone (no occupied
// neighbour; or one, which has no other), without labelling every component of a large map.
int remove_specks(cv::Mat& occupied, int min_cells) {
  if (min_cells <= 1) return 0;
  int removed = 0;
  if (min_cells <= 3) {
    const int w = occupied.cols, h = occupied.rows;
    // The occupied 8-neighbours of (x, y) but `skip`, and the last one seen.
    const auto neighbours = [&](int x, int y, cv::Point skip, cv::Point& last) {
      int n = 0;
      for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy) {
        const auto* row = occupied.ptr<std::uint8_t>(yy);
        for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
          if (!row[xx] || (xx == x && yy == y) || (xx == skip.x && yy == skip.y)) continue;
          ++n, last = {xx, yy};
        }
      }
      return n;
    };
    for (int y = 0; y < h; ++y) {
      auto* o = occupied.ptr<std::uint8_t>(y);
      for (int x = 0; x < w; ++x) {
        if (!o[x]) continue;
        cv::Point q, unused;
        const int n = neighbours(x, y, cv::Point(-2, -2), q);
        // A lone cell; or one of two neighbours (the other is cleared when the scan reaches it: it
        // has no occupied neighbour left).
        if (n == 0 || (n == 1 && min_cells == 3 && neighbours(q.x, q.y, {x, y}, unused) == 0)) o[x] = 0, ++removed;
      }
    }
    return removed;
  }
  // Component sizes counted here: OpenCV's statistics cost ten times the labelling on a large map.
  cv::Mat labels;
  const int n = cv::connectedComponents(occupied, labels, 8, CV_32S);
  std::vector<int> area(std::size_t(std::max(n, 1)), 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) ++area[std::size_t(l[x])];
  }
  std::vector<std::uint8_t> speck(area.size(), 0);
  bool any = false;
  for (std::size_t i = 1; i < area.size(); ++i) {
    if (area[i] < min_cells) speck[i] = 1, any = true;
  }
  if (!any) return 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    auto* o = occupied.ptr<std::uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (speck[std::size_t(l[x])]) o[x] = 0, ++removed;
    }
  }
  return removed;
}

// Max pooling of a mask by 2 into `out` ((rows + 1) / 2 x (cols + 1) / 2), one output cell at a time.
void pool_into(const cv::Mat& m, cv::Mat& out) {
  const int w = (m.cols + 1) / 2, h = (m.rows + 1) / 2, pairs = m.cols / 2;
  out.create(h, w, CV_8U);
  for (int y = 0; y < h; ++y) {
    const auto* r0 = m.ptr<std::uint8_t>(2 * y);
    const auto* r1 = 2 * y + 1 < m.rows ? m.ptr<std::uint8_t>(2 * y + 1) : r0;
    auto* o = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < pairs; ++x) o[x] = std::uint8_t(r0[2 * x] | r0[2 * x + 1] | r1[2 * x] | r1[2 * x + 1]);
    if (pairs < w) o[pairs] = std::uint8_t(r0[2 * pairs] | r1[2 * pairs]);
  }
}

// Max pooling by 2: occupied if any fine cell is; free if any is free and none is occupied.
void downsample(const cv::Mat& occ, const cv::Mat& fre, cv::Mat& occ_out, cv::Mat& free_out) {
  pool_into(occ, occ_out);
  pool_into(fre, free_out);
  free_out.setTo(0, occ_out);
}

// The unit direction toward the free cells within 2 cells of (x, y) (the mean of their directions,
// each weighted 1 / distance), zero where free space lies on opposite sides or nowhere near.
Eigen::Vector2f free_direction(const cv::Mat& free, int x, int y) {
  constexpr int kR = 2, kSide = 2 * kR + 1;
  // Each neighbour's direction / distance^2 and 1 / distance, computed once.
  struct Offsets {
    Eigen::Vector2f direction[kSide * kSide];
    float weight[kSide * kSide];
  };
  static const Offsets offsets = [] {
    Offsets o{};
    for (int dy = -kR; dy <= kR; ++dy) {
      for (int dx = -kR; dx <= kR; ++dx) {
        const float d2 = float(dx * dx + dy * dy);
        const int i = (dy + kR) * kSide + dx + kR;
        o.direction[i] = d2 > 0.0f ? Eigen::Vector2f(Eigen::Vector2f(float(dx), float(dy)) / d2) : Eigen::Vector2f::Zero();
        o.weight[i] = d2 > 0.0f ? 1.0f / std::sqrt(d2) : 0.0f;
      }
    }
    return o;
  }();
  Eigen::Vector2f sum = Eigen::Vector2f::Zero();
  float weight = 0.0f;
  for (int dy = -kR; dy <= kR; ++dy) {
    const int yy = y + dy;
    if (yy < 0 || yy >= free.rows) continue;
    const auto* row = free.ptr<std::uint8_t>(yy);
    for (int dx = -kR; dx <= kR; ++dx) {
      const int xx = x + dx;
      if (xx < 0 || xx >= free.cols || (dx == 0 && dy == 0) || row[xx] == 0) continue;
      const int i = (dy + kR) * kSide + dx + kR;
      sum += offsets.direction[i];
      weight += offsets.weight[i];
    }
  }
  // Free space on one side only gives |sum| near weight; on two opposite sides, near 0.
  const float n = sum.norm();
  return weight > 0.0f && n >= 0.5f * weight ? Eigen::Vector2f(sum / n) : Eigen::Vector2f::Zero();
}

// The Euclidean distance from each cell to the nearest nonzero cell of `walls`, exact below `cap`
// and `cap` elsewhere: each wall cell stamps the disc of radius `cap` around it, row by row.
cv::Mat capped_wall_distance(const cv::Mat& walls, float cap) {
  cv::Mat d(walls.size(), CV_32F, cv::Scalar(cap));
  const int r = int(std::ceil(cap));
  // Row dy of the disc: distances at dx = -half[dy] .. half[dy], from `start[dy]` in `values`.
  std::vector<int> half(std::size_t(2 * r + 1), -1), start(half.size(), 0);
  std::vector<float> values;
  for (int dy = -r; dy <= r; ++dy) {
    const auto i = std::size_t(dy + r);
    start[i] = int(values.size());
    while (half[i] + 1 <= r && float((half[i] + 1) * (half[i] + 1) + dy * dy) < cap * cap) ++half[i];
    for (int dx = -half[i]; dx <= half[i]; ++dx) values.push_back(std::sqrt(float(dx * dx + dy * dy)));
  }
  for (int y = 0; y < walls.rows; ++y) {
    const auto* w = walls.ptr<std::uint8_t>(y);
    for (int x = 0; x < walls.cols; ++x) {
      if (!w[x]) continue;
      for (int dy = std::max(-r, -y); dy <= std::min(r, walls.rows - 1 - y); ++dy) {
        const auto i = std::size_t(dy + r);
        const int x0 = std::max(x - half[i], 0), x1 = std::min(x + half[i], walls.cols - 1);
        float* row = d.ptr<float>(y + dy);
        const float* v = values.data() + start[i] + (x0 - (x - half[i]));
        for (int xx = x0; xx <= x1; ++xx, ++v) row[xx] = std::min(row[xx], *v);
      }
    }
  }
  return d;
}

// Sets GridLevel::cells from the level's masks; returns its free cells dilated by a 3 x 3 block.
cv::Mat set_cells(GridLevel& level) {
  cv::Mat free_near;
  cv::dilate(level.free, free_near, cv::Mat::ones(3, 3, CV_8U));
  level.cells = ((level.occupied | level.free) & GridLevel::kKnown) | (level.free & GridLevel::kFree) |
                (free_near & GridLevel::kFreeNear);
  return free_near;
}

// `level.clutter` must be set (or empty: none). `wall_cells` gets every wall cell, row by row.
void finish_level(GridLevel& level, const PrepareOptions& options, std::vector<cv::Point>& wall_cells) {
  if (level.clutter.empty()) level.clutter = cv::Mat::zeros(level.occupied.size(), CV_8U);
  // Walls: occupied cells touching free space (8-neighbourhood).
  const cv::Mat free_near = set_cells(level);
  level.walls = level.occupied & free_near;
  level.wall_distance = capped_wall_distance(level.walls, float(options.max_wall_distance));
  // At most `cap` points, chosen by a hash of the cell: spread evenly in space without following
  // the raster order (taking every k-th point of a row scan would leave rows, and the Hough
  // spectrum would see horizontal lines).
  const std::size_t cap = static_cast<std::size_t>(std::max(1, options.max_refine_points));
  const auto sample = [cap](const std::vector<cv::Point>& pts, std::vector<Eigen::Vector2f>& out) {
    out.clear();
    const std::uint32_t keep = pts.size() > cap ? std::uint32_t((std::uint64_t(cap) << 16) / pts.size()) : 1u << 16;
    for (const auto& p : pts) {
      std::uint32_t h = std::uint32_t(p.x) * 73856093u ^ std::uint32_t(p.y) * 19349663u;
      h ^= h >> 13, h *= 0x5bd1e995u, h ^= h >> 15;
      if ((h & 0xffffu) < keep) out.emplace_back(float(p.x), float(p.y));
    }
  };
  std::vector<cv::Point>& pts = wall_cells;
  pts.clear();
  cv::findNonZero(level.walls, pts);
  sample(pts, level.wall_points);
  cv::Mat occupied_near;
  cv::dilate(level.occupied, occupied_near, cv::Mat::ones(3, 3, CV_8U));
  level.free_band = level.free & occupied_near;
  level.wall_normals.clear();
  level.wall_clutter.clear();
  for (const auto& p : level.wall_points) {
    level.wall_normals.push_back(free_direction(level.free, int(p.x()), int(p.y())));
    level.wall_clutter.push_back(level.clutter.at<std::uint8_t>(int(p.y()), int(p.x())) != 0);
  }
  // Interior: occupied, not a wall, not clutter; even rows and columns only.
  std::vector<cv::Point> even;
  for (int y = 0; y < level.occupied.rows; y += 2) {
    const auto* o = level.occupied.ptr<std::uint8_t>(y);
    const auto* w = level.walls.ptr<std::uint8_t>(y);
    const auto* c = level.clutter.ptr<std::uint8_t>(y);
    for (int x = 0; x < level.occupied.cols; x += 2) {
      if (o[x] && !w[x] && !c[x]) even.emplace_back(x, y);
    }
  }
  sample(even, level.interior_points);
}

}  // namespace

PreparedGrid::PreparedGrid(const mapping::OccupancyGrid& grid, const PrepareOptions& options)
    : grid_(&grid), max_wall_distance_(options.max_wall_distance) {
  if (!(options.max_wall_distance >= 1.0 && options.max_wall_distance <= 1000.0))
    throw InputError(fmt::format("merge options: max_wall_distance {} is not 1 to 1000 cells", options.max_wall_distance));
  GridLevel base;
  base.factor = 1;
  if (grid.width() > 0 && grid.height() > 0) {
    base.occupied = mapping::state_mask(grid, {mapping::CellState::Occupied});
    base.free = mapping::state_mask(grid, {mapping::CellState::Free});
  } else {  // one empty cell
    base.occupied = cv::Mat::zeros(1, 1, CV_8U);
    base.free = cv::Mat::zeros(1, 1, CV_8U);
  }
  known_cells_ = cv::countNonZero(base.occupied) + cv::countNonZero(base.free);
  known_cells_ -= remove_specks(base.occupied, options.min_obstacle_cells);
  if (options.close_seams) known_cells_ += close_seams(base.occupied, base.free);
  const double resolution = grid.resolution() > 0.0 ? grid.resolution() : 0.05;
  // Gaps of two cells at least: a thin wall turned and resampled on another grid breaks every few cells.
  std::vector<cv::Mat> standing =
      find_standing(base.occupied, std::max(2, int(std::lround(options.clutter_gap_m / resolution))),
                    {int(std::lround(options.clutter_size_m / resolution)), int(std::lround(options.furniture_size_m / resolution))});
  base.clutter = std::move(standing[0]);
  const cv::Mat furniture = std::move(standing[1]);
  std::vector<cv::Point> pts;  // level 0's wall cells
  finish_level(base, options, pts);
  levels_.push_back(std::move(base));
  while (std::max(levels_.back().width(), levels_.back().height()) / 2 >= options.min_level_size) {
    GridLevel next;
    next.factor = levels_.back().factor * 2;
    const GridLevel& prev = levels_.back();
    downsample(prev.occupied, prev.free, next.occupied, next.free);
    // A coarse cell is clutter when its occupied fine cells all are.
    cv::Mat pooled_clutter, pooled_structure;
    pool_into(prev.clutter, pooled_clutter);
    pool_into(prev.occupied & ~prev.clutter, pooled_structure);
    next.clutter = pooled_clutter & ~pooled_structure;
    std::vector<cv::Point> unused;
    finish_level(next, options, unused);
    levels_.push_back(std::move(next));
  }

  // Every full-resolution wall cell with the covariance of its wall neighbours (radius 3).
  const GridLevel& l0 = levels_.front();
  walls_.reserve(pts.size());
  constexpr int kR = 3;
  for (const auto& p : pts) {
    // Sums of small integers: exact in int, and several times faster than in double.
    int ni = 0, sxi = 0, syi = 0, sxxi = 0, sxyi = 0, syyi = 0;
    const int dy0 = std::max(-kR, -p.y), dy1 = std::min(kR, l0.height() - 1 - p.y);
    const int dx0 = std::max(-kR, -p.x), dx1 = std::min(kR, l0.width() - 1 - p.x);
    for (int dy = dy0; dy <= dy1; ++dy) {
      const auto* row = l0.walls.ptr<std::uint8_t>(p.y + dy) + p.x;
      for (int dx = dx0; dx <= dx1; ++dx) {
        if (dx * dx + dy * dy > kR * kR || row[dx] == 0) continue;
        ++ni;
        sxi += dx, syi += dy, sxxi += dx * dx, sxyi += dx * dy, syyi += dy * dy;
      }
    }
    const double n = ni, sx = sxi, sy = syi, sxx = sxxi, sxy = sxyi, syy = syyi;
    WallPoint w;
    w.position = Eigen::Vector2f(float(p.x), float(p.y));
    Eigen::Matrix2d c;
    c << sxx / n - (sx / n) * (sx / n), sxy / n - (sx / n) * (sy / n), sxy / n - (sx / n) * (sy / n),
        syy / n - (sy / n) * (sy / n);
    const double trace = c.trace();
    if (trace > 1e-9) w.structure = (Eigen::Matrix2d::Identity() - c / trace).cast<float>();
    w.normal = free_direction(l0.free, p.x, p.y);
    w.clutter = l0.clutter.at<std::uint8_t>(p.y, p.x) != 0;
    w.furniture = furniture.at<std::uint8_t>(p.y, p.x) != 0;
    walls_.push_back(w);
  }
  set_sizes();
}

namespace {

// Max pooling of a mask by 2.
cv::Mat pool_mask(const cv::Mat& m) {
  cv::Mat out;
  pool_into(m, out);
  return out;
}

// The points of `from` inside `box` where `mask` (box's size) is set, moved to the box's cells;
// `keep` gets the kept indices.
std::vector<Eigen::Vector2f> points_inside(const std::vector<Eigen::Vector2f>& from, const cv::Rect& box,
                                           const cv::Mat& mask, std::vector<std::size_t>& keep) {
  std::vector<Eigen::Vector2f> out;
  keep.clear();
  const Eigen::Vector2f o(float(box.x), float(box.y));
  for (std::size_t i = 0; i < from.size(); ++i) {
    const int x = int(from[i].x()) - box.x, y = int(from[i].y()) - box.y;
    if (x < 0 || y < 0 || x >= box.width || y >= box.height || mask.at<std::uint8_t>(y, x) == 0) continue;
    out.push_back(from[i] - o);
    keep.push_back(i);
  }
  return out;
}

}  // namespace

PreparedGrid::PreparedGrid(const PreparedGrid& other) = default;
PreparedGrid::PreparedGrid(PreparedGrid&& other) noexcept = default;
PreparedGrid& PreparedGrid::operator=(const PreparedGrid& other) = default;
PreparedGrid& PreparedGrid::operator=(PreparedGrid&& other) noexcept = default;
PreparedGrid::~PreparedGrid() = default;
PreparedGrid::PreparedGrid(const mapping::OccupancyGrid* grid) : grid_(grid) {}

const GridLevel& PreparedGrid::level(int k) const { return levels_.at(static_cast<std::size_t>(k)); }

void PreparedGrid::set_sizes() {
  width_ = levels_.front().width();
  height_ = levels_.front().height();
  level_count_ = levels_.size();
}

struct PreparedGridParts {
  static PreparedGrid cut(const PreparedGrid& source, const cv::Mat& mask, const PrepareOptions& options,
                          Eigen::Vector2i& origin);
};

PreparedGrid prepared_part(const PreparedGrid& source, const cv::Mat& mask, const PrepareOptions& options,
                           Eigen::Vector2i& origin) {
  return PreparedGridParts::cut(source, mask, options, origin);
}

PreparedGrid PreparedGridParts::cut(const PreparedGrid& source, const cv::Mat& mask, const PrepareOptions& options,
                                    Eigen::Vector2i& origin) {
  PreparedGrid part(source.grid_);
  part.max_wall_distance_ = source.max_wall_distance_;
  const GridLevel& s0 = source.level(0);
  cv::Mat m0 = mask & (s0.occupied | s0.free);
  // The box of the mask's cells, without listing them.
  cv::Rect box = cv::boundingRect(m0);
  if (box.area() == 0) box = cv::Rect(0, 0, 1, 1);
  const int coarsest = source.level(source.level_count() - 1).factor;
  const int x0 = box.x / coarsest * coarsest, y0 = box.y / coarsest * coarsest;
  box = cv::Rect(x0, y0, box.x + box.width - x0, box.y + box.height - y0);
  origin = Eigen::Vector2i(x0, y0);
  cv::Mat level_mask = m0(box);
  std::vector<std::size_t> keep;
  for (int k = 0; k < source.level_count(); ++k) {
    const GridLevel& s = source.level(k);
    const int f = s.factor;
    // This level's cells under the box (the box's corner is on a cell boundary of every level).
    const cv::Rect cut(x0 / f, y0 / f, std::min(s.width() - x0 / f, (box.width + f - 1) / f),
                       std::min(s.height() - y0 / f, (box.height + f - 1) / f));
    if (k > 0) {
      if (std::max(part.levels_.back().width(), part.levels_.back().height()) / 2 < options.min_level_size) break;
      level_mask = pool_mask(level_mask)(cv::Rect(0, 0, cut.width, cut.height));
    }
    GridLevel l;
    l.factor = f;
    l.occupied = s.occupied(cut) & level_mask;
    l.free = s.free(cut) & level_mask;
    set_cells(l);
    l.walls = s.walls(cut) & level_mask;
    l.wall_distance = s.wall_distance(cut);
    l.free_band = s.free_band(cut) & level_mask;
    l.clutter = s.clutter(cut) & level_mask;
    l.wall_points = points_inside(s.wall_points, cut, level_mask, keep);
    for (std::size_t i : keep) l.wall_normals.push_back(s.wall_normals[i]), l.wall_clutter.push_back(s.wall_clutter[i]);
    l.interior_points = points_inside(s.interior_points, cut, level_mask, keep);
    part.levels_.push_back(std::move(l));
  }
  const Eigen::Vector2f o = origin.cast<float>();
  for (const auto& w : source.walls()) {
    const int x = int(w.position.x()) - x0, y = int(w.position.y()) - y0;
    if (x < 0 || y < 0 || x >= box.width || y >= box.height || m0.at<std::uint8_t>(y + y0, x + x0) == 0) continue;
    WallPoint moved = w;
    moved.position -= o;
    part.walls_.push_back(moved);
  }
  part.known_cells_ = cv::countNonZero(part.levels_.front().occupied | part.levels_.front().free);
  part.set_sizes();
  return part;
}

int PreparedGrid::level_for_size(int cells) const {
  for (int k = 0; k < level_count(); ++k) {
    if (std::max(levels_[std::size_t(k)].width(), levels_[std::size_t(k)].height()) <= cells) return k;
  }
  return level_count() - 1;
}

core::Transform2 to_level(const core::Transform2& fine, int factor) {
  const double s = factor, c = (s - 1.0) / 2.0;
  const Eigen::Vector2d cc(c, c);
  return {(fine.rotation_matrix() * cc + fine.translation() - cc) / s, fine.rotation()};
}

core::Transform2 from_level(const core::Transform2& coarse, int factor) {
  const double s = factor, c = (s - 1.0) / 2.0;
  const Eigen::Vector2d cc(c, c);
  return {s * coarse.translation() + cc - coarse.rotation_matrix() * cc, coarse.rotation()};
}

}  // namespace fleetmap::merging

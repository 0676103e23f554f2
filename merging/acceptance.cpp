#include "merging/acceptance.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <tuple>
#include <cmath>
#include <numbers>
#include <unordered_map>
#include <unordered_set>

#include "merging/grid_level.h"

namespace fleetmap::merging {

namespace {

// The agr / dis count over b's known cells moved into a; state_a / state_b give a cell's state
// (0 unknown, 1 free, 2 occupied, as mapping::CellState) for the two ways a map is held (a grid, or a prepared level).
template <class StateA, class StateB>
Acceptance count_agreement(int wa, int ha, int wb, int hb, StateA state_a, StateB state_b, const core::Transform2& b_to_a) {
  Acceptance acc;
  const Eigen::Matrix2d r = b_to_a.rotation_matrix();
  const Eigen::Vector2d t = b_to_a.translation();
  for (int y = 0; y < hb; ++y) {
    // The row's cells move along a line: start and step in a's coordinates.
    const Eigen::Vector2d start = r * Eigen::Vector2d(0.0, y) + t, step = r.col(0);
    for (int x = 0; x < wb; ++x) {
      const int sb = state_b(x, y);
      if (sb == 0) continue;
      const Eigen::Vector2d p = start + double(x) * step;
      const int ax = nearest_cell(p.x()), ay = nearest_cell(p.y());
      if (ax < 0 || ay < 0 || ax >= wa || ay >= ha) continue;
      const int sa = state_a(ax, ay);
      if (sa == 0) continue;
      if (sa == sb) ++acc.agree;
      else ++acc.disagree;
    }
  }
  return acc;
}

int state_of(const GridLevel& g, int x, int y) {
  return g.occupied.at<std::uint8_t>(y, x) != 0 ? 2 : g.free.at<std::uint8_t>(y, x) != 0 ? 1 : 0;
}

}  // namespace

Acceptance acceptance_index(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b,
                            const core::Transform2& b_to_a) {
  return count_agreement(
      a.width(), a.height(), b.width(), b.height(),
      [&](int x, int y) { return int(a.state_at(y * a.width() + x)); },
      [&](int x, int y) { return int(b.state_at(y * b.width() + x)); }, b_to_a);
}

Acceptance acceptance_index(const GridLevel& a, const GridLevel& b, const core::Transform2& b_to_a) {
  return count_agreement(
      a.width(), a.height(), b.width(), b.height(), [&](int x, int y) { return state_of(a, x, y); },
      [&](int x, int y) { return state_of(b, x, y); }, b_to_a);
}

namespace {

struct Tally {
  int tested = 0, matched = 0, near = 0, contradicted = 0, wall_ends = 0;
  double squared_residuals = 0.0;  // of the matched and the near walls
  std::unordered_set<std::int64_t> blocks;   // 4 x 4 blocks of the source map already counted
  std::unordered_set<std::int64_t> end_blocks;  // ... and those whose wall end is counted
  std::vector<Eigen::Vector2d> positions;    // matched walls, in a's frame
  std::vector<Eigen::Matrix2d> structures;   // their local structure, in a's frame
  std::vector<Eigen::Vector2d> structure_positions;  // the matched walls that are not clutter
  std::vector<Eigen::Vector2d> structure_normals;    // ... the side each was seen from, in a's frame (or zero)
  std::vector<Eigen::Vector2d> open_space;   // walls in the other map's open space, in a's frame
};

// Whether the cell nearest (x, y) is in the map and free.
template <typename Scalar>
bool free_cell(const GridLevel& g, Scalar x, Scalar y) {
  const int cx = nearest_cell(x), cy = nearest_cell(y);
  return cx >= 0 && cy >= 0 && cx < g.width() && cy < g.height() && g.is_free(cx, cy);
}

// Whether the wall cell `w` of `source` ends a straight wall there (a door jamb, the end of a
// free-standing wall): along the wall, an opening on one side and the wall going on on the other,
// and `target` shows the same at `p`, where r turns source's directions into target's. Two maps
// whose common walls are one corner fit any corner of a bare room; a matched opening in a wall
// pins the corner to one place along its walls.
bool matched_wall_end(const GridLevel& source, const GridLevel& target, const WallPoint& w, const Eigen::Matrix2f& r,
                      const Eigen::Vector2f& p) {
  const Eigen::Matrix2f c = Eigen::Matrix2f::Identity() - w.structure;  // the wall cells' spread (scaled)
  if (c.trace() < 0.5f) return false;  // an isolated cell: no direction
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2f> eig(c);
  const auto& ev = eig.eigenvalues();
  if (ev(1) < 4.0f * ev(0)) return false;  // not a straight piece of wall
  const Eigen::Vector2f u = eig.eigenvectors().col(1);
  const auto free_at = [](const GridLevel& g, const Eigen::Vector2f& q) { return free_cell(g, q.x(), q.y()); };
  const auto wall_at = [](const GridLevel& g, const Eigen::Vector2f& q) {
    const int x = nearest_cell(q.x()), y = nearest_cell(q.y());
    return x >= 0 && y >= 0 && x < g.width() && y < g.height() && g.distance_at(q.x(), q.y(), 1e4f) <= 1.0f;
  };
  // Beyond the end, free on the wall's line and on both sides of it: an opening one sees through
  // (the edge of what a robot saw, where grazing beams leave free cells on the line of a wall that
  // goes on unseen, has unknown behind the wall).
  const auto open_at = [&](const GridLevel& g, const Eigen::Vector2f& q, const Eigen::Vector2f& across) {
    return free_at(g, q) && free_at(g, q + 3.0f * across) && free_at(g, q - 3.0f * across);
  };
  const Eigen::Vector2f n(-u.y(), u.x()), ut = r * u, nt = r * n;
  for (const float s : {1.0f, -1.0f}) {
    bool end = wall_at(source, w.position - 3.0f * s * u) && wall_at(target, p - 3.0f * s * ut);
    for (float k = 2.0f; end && k <= 4.0f; k += 1.0f)
      end = open_at(source, w.position + k * s * u, n) && open_at(target, p + k * s * ut, nt);
    if (end) return true;
  }
  return false;
}

// Counts `from`'s wall cells moved into `to` by t.
void tally(const PreparedGrid& from, const PreparedGrid& to, const core::Transform2& t, const core::Transform2& to_a,
           bool from_b, const QualityOptions& options, Tally& out) {
  const GridLevel& target = to.level(0);
  const Eigen::Matrix2f r = t.rotation_matrix().cast<float>();
  const Eigen::Vector2f tr = t.translation().cast<float>();
  const Eigen::Matrix2d ra = to_a.rotation_matrix() * t.rotation_matrix();
  for (const auto& w : from.walls()) {
    const Eigen::Vector2f p = r * w.position + tr;
    const int x = nearest_cell(p.x()), y = nearest_cell(p.y());
    if (x < 0 || y < 0 || x >= target.width() || y >= target.height() || !target.known(x, y)) continue;
    const float d = target.distance_at(p.x(), p.y(), 1e4f);
    out.tested += !w.clutter;
    // Walls near the other map's walls but farther than a match (parallel walls a cell or two
    // apart) widen the residual: they are how a wrong answer that lines walls up only roughly
    // differs from a right one.
    if (!w.clutter && d > options.match_distance && d < options.contradiction_distance) {
      ++out.near;
      out.squared_residuals += double(d) * d;
    }
    if (d <= options.match_distance) {
      if (!seen_from_same_side(target, p, r * w.normal)) continue;
      ++out.matched;
      out.squared_residuals += double(d) * d;
      // Neighbouring wall cells say the same thing: one sample per 4 x 4 block of the source.
      const std::int64_t key = (std::int64_t(int(w.position.x()) / 4) << 32) ^ std::int64_t(int(w.position.y()) / 4) ^
                               (from_b ? std::int64_t(1) << 62 : 0);
      // A wall end counts once per block too, whichever of the block's cells ends the wall (the
      // block's first matched cell may lie a cell or two short of the end, where no opening is yet
      // in sight: seen on the benchmark, a free-standing wall's end seen by both maps not counted).
      if (options.shape && !w.clutter && !out.end_blocks.count(key) && matched_wall_end(from.level(0), target, w, r, p)) {
        out.end_blocks.insert(key);
        ++out.wall_ends;
      }
      if (!out.blocks.insert(key).second) continue;
      out.positions.push_back(to_a.apply(p.cast<double>()));
      if (!w.clutter) {
        out.structure_positions.push_back(out.positions.back());
        out.structure_normals.push_back(ra * w.normal.cast<double>());
      }
      out.structures.push_back(ra * w.structure.cast<double>() * ra.transpose());
    } else if (!w.clutter && d >= options.contradiction_distance && target.is_free(x, y)) {
      ++out.contradicted;
      // (The distances stop at the prepared maximum, at least open_space_distance: an interpolation
      // between four capped cells may round a hair below it.)
      if (!w.furniture && d >= float(options.open_space_distance) - 1e-3f) out.open_space.push_back(to_a.apply(p.cast<double>()));
    }
  }
  for (const auto& w : from.level(0).interior_points) {
    const Eigen::Vector2f p = r * w + tr;
    const int x = nearest_cell(p.x()), y = nearest_cell(p.y());
    if (x < 0 || y < 0 || x >= target.width() || y >= target.height() || !target.is_free(x, y)) continue;
    if (target.distance_at(p.x(), p.y(), 1e4f) >= options.contradiction_distance) ++out.contradicted;
  }
}

// The most points in one group of `points` whose nearest cells (rounded) are 8-neighbours, a chain
// of them counting as one group, and the mean of that group's points.
std::pair<int, Eigen::Vector2d> largest_group(const std::vector<Eigen::Vector2d>& points) {
  std::unordered_map<std::int64_t, std::pair<int, Eigen::Vector2d>> cells;  // points per cell and their sum
  const auto key = [](long x, long y) { return (std::int64_t(x) << 32) ^ std::int64_t(std::uint32_t(y)); };
  for (const auto& p : points) {
    auto& c = cells.try_emplace(key(std::lround(p.x()), std::lround(p.y())), 0, Eigen::Vector2d::Zero()).first->second;
    ++c.first;
    c.second += p;
  }
  int largest = 0;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  std::vector<std::pair<long, long>> stack;
  while (!cells.empty()) {
    const std::int64_t start = cells.begin()->first;
    int size = cells.begin()->second.first;
    Eigen::Vector2d sum = cells.begin()->second.second;
    cells.erase(cells.begin());
    stack.assign(1, {long(start >> 32), long(std::int32_t(std::uint32_t(start & 0xffffffff)))});
    while (!stack.empty()) {
      const auto [x, y] = stack.back();
      stack.pop_back();
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto n = cells.find(key(x + dx, y + dy));
          if (n == cells.end()) continue;
          size += n->second.first;
          sum += n->second.second;
          cells.erase(n);
          stack.push_back({x + dx, y + dy});
        }
    }
    if (size > largest) largest = size, centre = sum / double(size);
  }
  return {largest, centre};
}

// The points farther than `tolerance` from the straight lines that hold the most points, taken one
// after another: element l after l + 1 lines. A Hough transform (1 degree, 1 cell) picks each line,
// a total least squares fit to the points within 2 tolerances of it places it. With `normals` (the
// side each point was seen from), a line that is one face of a wall (its points seen from one
// side) also holds the points within `face_band` of it but those seen from the other side: a
// wall's face spreads across its line by the laser's noise and the wall's roughness, while its
// other face, seen from the other side, is a detail beyond it.
struct Line {
  Eigen::Vector2d normal, on;
};

std::vector<int> beyond_lines(std::vector<Eigen::Vector2d> points, int lines, double tolerance,
                              std::vector<Line>* fitted = nullptr, std::vector<Eigen::Vector2d> normals = {},
                              double face_band = 0.0) {
  constexpr int kAngles = 180;
  std::vector<int> left, bins, counts;
  std::vector<double> xs, ys;
  for (int l = 0; l < lines; ++l) {
    if (points.size() < 2) {
      left.push_back(int(points.size()));
      continue;
    }
    Eigen::Vector2d lo = points.front(), hi = points.front();
    for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const Eigen::Vector2d mid = 0.5 * (lo + hi);
    const int rho_bins = 2 * int(std::ceil((hi - lo).norm() / 2.0)) + 3, offset = rho_bins / 2;
    // The winner is the bin that first reaches the most votes, counting angle by angle and point by
    // point: the first angle whose row holds the most votes, and in it the bin that gets there first.
    xs.resize(points.size()), ys.resize(points.size()), bins.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) xs[i] = points[i].x(), ys[i] = points[i].y();
    const auto bins_at = [&](int k) {
      const double th = std::numbers::pi * k / kAngles;
      const double nx = std::cos(th), ny = std::sin(th), mx = mid.x(), my = mid.y(), off = offset;
      // n . (p - mid), offset first, so that rounding is truncation of a positive number (std::lround
      // is a call); coordinates in arrays of their own, so that the compiler computes several at once.
      for (std::size_t i = 0; i < xs.size(); ++i)
        bins[i] = std::clamp(int(nx * (xs[i] - mx) + ny * (ys[i] - my) + off + 0.5), 0, rho_bins - 1);
    };
    const std::size_t rho = std::size_t(rho_bins), n_points = points.size();
    int best_angle = 0, best_votes = -1;
    for (int k = 0; k < kAngles; ++k) {
      bins_at(k);
      // Four histograms taking turns: increments of one bin (points along a wall) would otherwise
      // wait for each other.
      counts.assign(4 * rho, 0);
      int* h = counts.data();
      std::size_t i = 0;
      for (; i + 4 <= n_points; i += 4) {
        ++h[std::size_t(bins[i])], ++h[rho + std::size_t(bins[i + 1])];
        ++h[2 * rho + std::size_t(bins[i + 2])], ++h[3 * rho + std::size_t(bins[i + 3])];
      }
      for (; i < n_points; ++i) ++h[std::size_t(bins[i])];
      int most = 0;
      for (std::size_t j = 0; j < rho; ++j) most = std::max(most, h[j] + h[rho + j] + h[2 * rho + j] + h[3 * rho + j]);
      if (most > best_votes) best_votes = most, best_angle = k;
    }
    bins_at(best_angle);
    counts.assign(rho, 0);
    int best_bin = 0;
    for (const int b : bins) {
      if (++counts[std::size_t(b)] == best_votes) {
        best_bin = b;
        break;
      }
    }
    const double th = std::numbers::pi * best_angle / kAngles;
    Eigen::Vector2d n(std::cos(th), std::sin(th));
    Eigen::Vector2d on = mid + double(best_bin - offset) * n;
    // Refit to the points near the voted line, then drop the points on it.
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    std::vector<const Eigen::Vector2d*> near;
    for (const auto& p : points)
      if (std::abs(n.dot(p - on)) <= 2.0 * tolerance) near.push_back(&p), c += p;
    if (near.size() >= 2) {
      c /= double(near.size());
      Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
      for (const auto* p : near) cov += (*p - c) * (*p - c).transpose();
      n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(cov).eigenvectors().col(0);
      on = c;
    }
    if (fitted) fitted->push_back({n, on});
    // The side the line's own points were seen from: +1 or -1 when nearly all from one, else 0.
    int side = 0;
    if (normals.size() == points.size() && face_band > tolerance) {
      int plus = 0, minus = 0;
      for (std::size_t i = 0; i < points.size(); ++i) {
        if (std::abs(n.dot(points[i] - on)) > tolerance) continue;
        const double s = n.dot(normals[i]);
        plus += s > 0.5, minus += s < -0.5;
      }
      constexpr double kOneSide = 0.9;
      if (plus >= kOneSide * (plus + minus) && plus > 0) side = 1;
      else if (minus >= kOneSide * (plus + minus) && minus > 0) side = -1;
    }
    const auto on_line = [&](std::size_t i) {
      const double d = std::abs(n.dot(points[i] - on));
      // A point seen from no single side (free on several) is no other face either.
      return d <= tolerance || (side != 0 && d <= face_band && side * n.dot(normals[i]) > -0.5);
    };
    std::size_t kept = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (on_line(i)) continue;
      points[kept] = points[i];
      if (!normals.empty()) normals[kept] = normals[i];
      ++kept;
    }
    points.resize(kept);
    if (!normals.empty()) normals.resize(kept);
    left.push_back(int(points.size()));
  }
  return left;
}

// Lines within 10 degrees of parallel (|n1 . n2| at least this), or of square (at most this).
const double kParallel = std::cos(10.0 * std::numbers::pi / 180.0), kSquare = std::sin(10.0 * std::numbers::pi / 180.0);

// The points the line `l` of beyond_lines took (`left` as it gives it, `total` points before).
int points_on(const std::vector<int>& left, int total, std::size_t l) { return (l == 0 ? total : left[l - 1]) - left[l]; }

// The sides of a room among `lines` (`left` as beyond_lines gives it, `total` points before): lines
// that hold `min_points` points or more, run along the strongest side or square to it (within 10
// degrees), and lie at least `min_width` from a stronger parallel side. A weaker line closer than
// that beside a side is a jog in that wall, a niche's back or a door's reveal, not the room's other
// side; a line askew is a slanted wall, no side of a rectangle. Adds the points on the sides to
// `on_sides`.
std::vector<const Line*> room_sides(const std::vector<Line>& lines, const std::vector<int>& left, int total, int min_points,
                                    double min_width, int& on_sides) {
  std::vector<const Line*> sides;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const int on = points_on(left, total, l);
    if (on < min_points) continue;
    const Line& line = lines[l];
    const bool detail = std::any_of(sides.begin(), sides.end(), [&](const Line* s) {
      return std::abs(s->normal.dot(line.normal)) >= kParallel && std::abs(s->normal.dot(line.on - s->on)) < min_width;
    });
    // A rectangular room's sides run along the strongest one or square to it.
    const bool askew = !sides.empty() && std::abs(sides[0]->normal.dot(line.normal)) < kParallel &&
                       std::abs(sides[0]->normal.dot(line.normal)) > kSquare;
    if (detail || askew) continue;
    sides.push_back(&line);
    on_sides += on;
  }
  return sides;
}

// The most of `lines` that run parallel to one another (within 10 degrees).
int most_parallel(const std::vector<const Line*>& lines) {
  int most = 0;
  for (const Line* x : lines)
    most = std::max(most, int(std::count_if(lines.begin(), lines.end(), [&](const Line* y) {
                                return std::abs(x->normal.dot(y->normal)) >= kParallel;
                              })));
  return most;
}

// Stretches of `line` at least `min_length` cells long between two of `points` on it (within
// `tolerance`) where the cells on the line are free in both maps (b's cells by a_to_b); one cell in
// ten may be otherwise (a speck of clutter).
int openings_on(const std::vector<Eigen::Vector2d>& points, const Line& line, double tolerance, double min_length,
                const GridLevel& a, const GridLevel& b, const core::Transform2& a_to_b) {
  const Eigen::Vector2d u(-line.normal.y(), line.normal.x());
  std::vector<double> along;
  for (const auto& p : points)
    if (std::abs(line.normal.dot(p - line.on)) <= tolerance) along.push_back(u.dot(p - line.on));
  std::sort(along.begin(), along.end());
  const auto free_at = [](const GridLevel& g, const Eigen::Vector2d& q) { return free_cell(g, q.x(), q.y()); };
  int openings = 0;
  for (std::size_t i = 1; i < along.size(); ++i) {
    // The matched walls are one per 4 x 4 block: the stretch between two of them starts and ends
    // up to 2 cells inside the walls.
    const double from = along[i - 1] + 2.0, to = along[i] - 2.0;
    if (to - from < min_length) continue;
    int cells = 0, open = 0;
    for (double s = from; s <= to; s += 1.0) {
      const Eigen::Vector2d q = line.on + s * u;
      ++cells;
      open += free_at(a, q) && free_at(b, a_to_b.apply(q));
    }
    openings += 10 * open >= 9 * cells;
  }
  return openings;
}

// How many of the four half-lines from where the two lines meet carry at least `min_points`
// points farther than `margin` from the meeting point (and within `tolerance` of the line): 2 for
// an L (a room's corner), 3 for a T (a wall meeting another that goes on past it), 4 for a cross;
// 0 when the lines are nearly parallel (no junction).
int junction_arms(const std::vector<Eigen::Vector2d>& points, const Line& l1, const Line& l2, double tolerance,
                  double margin, int min_points) {
  const double det = l1.normal.x() * l2.normal.y() - l1.normal.y() * l2.normal.x();
  if (std::abs(det) < std::sin(std::numbers::pi / 6.0)) return 0;  // closer than 30 degrees
  // Where n1 . x = n1 . on1 and n2 . x = n2 . on2.
  const double c1 = l1.normal.dot(l1.on), c2 = l2.normal.dot(l2.on);
  const Eigen::Vector2d meet((c1 * l2.normal.y() - c2 * l1.normal.y()) / det,
                             (l1.normal.x() * c2 - l2.normal.x() * c1) / det);
  int arms = 0;
  for (const Line* l : {&l1, &l2}) {
    const Eigen::Vector2d u(-l->normal.y(), l->normal.x());
    int plus = 0, minus = 0;
    for (const auto& p : points) {
      if (std::abs(l->normal.dot(p - meet)) > tolerance) continue;
      const double s = u.dot(p - meet);
      plus += s > margin, minus += s < -margin;
    }
    arms += (plus >= min_points) + (minus >= min_points);
  }
  return arms;
}

// Which of the first three of `lines` closes one end of a hall, or -1: two of them parallel
// (within 10 degrees, at least 4 tolerances apart) and the third across them (within 10 degrees of
// square), with the points on the two parallel lines (within `tolerance`) on one side of the third,
// more than `tolerance` off it, and the points on the third between the other two. A U, whichever
// order the Hough transform found its sides in.
int closed_end(const std::vector<Eigen::Vector2d>& points, const std::vector<Line>& lines, double tolerance) {
  for (int across = 0; across < 3; ++across) {
    const Line& c = lines[std::size_t(across)];
    const Line& s1 = lines[std::size_t((across + 1) % 3)];
    const Line& s2 = lines[std::size_t((across + 2) % 3)];
    if (std::abs(s1.normal.dot(s2.normal)) < kParallel || std::abs(c.normal.dot(s1.normal)) > kSquare) continue;
    const double side_offset = s1.normal.dot(s2.on - s1.on);  // s2 from s1, along s1's normal
    if (std::abs(side_offset) < 4.0 * tolerance) continue;  // one thick wall, not two
    int before = 0, beyond = 0, between = 0, outside = 0;
    for (const auto& p : points) {
      const double along = c.normal.dot(p - c.on);
      const double from_s1 = s1.normal.dot(p - s1.on), from_s2 = s2.normal.dot(p - s2.on);
      if (std::abs(from_s1) <= tolerance || std::abs(from_s2) <= tolerance) {
        if (along > tolerance) ++beyond;
        else if (along < -tolerance) ++before;
      } else if (std::abs(along) <= tolerance) {
        // Between the parallel lines: on the same side of s1 as s2 is, and closer to s1 than s2 is.
        const double t = from_s1 * (side_offset >= 0.0 ? 1.0 : -1.0);
        if (t > 0.0 && t < std::abs(side_offset)) ++between;
        else ++outside;
      }
    }
    if (std::min(before, beyond) <= 1 && std::max(before, beyond) >= 3 && between >= 3 && outside <= 1) return across;
  }
  return -1;
}

// The share of a map's free cells (every second row and column) for which `outside` holds, given
// the cell's place in a's cells (`to_a` places the map's cells there).
template <typename Outside>
double free_share(const GridLevel& g, const core::Transform2& to_a, Outside outside) {
  long total = 0, out = 0;
  for (int y = 0; y < g.height(); y += 2)
    for (int x = 0; x < g.width(); x += 2) {
      if (!g.is_free(x, y)) continue;
      ++total;
      out += outside(to_a.apply(Eigen::Vector2d(x, y)));
    }
  return total > 0 ? double(out) / double(total) : 0.0;
}

// The share of a map's free cells that lie outside the strip between the two parallel lines s1 and
// s2 by more than `margin`: what the map saw past a hall's side walls.
double free_outside_strip(const GridLevel& g, const core::Transform2& to_a, const Line& s1, const Line& s2, double margin) {
  const double width = std::abs(s1.normal.dot(s2.on - s1.on));
  // A cell is outside when its distance from the strip's centre line, along s1's normal, is more
  // than half the width plus the margin.
  const Eigen::Vector2d& n = s1.normal;
  const double centre = 0.5 * (n.dot(s1.on) + n.dot(s2.on)), reach = 0.5 * width + margin;
  return free_share(g, to_a, [&](const Eigen::Vector2d& p) { return std::abs(n.dot(p) - centre) > reach; });
}

// The share of a map's free cells more than `margin` beyond one of a room's `sides`, on the side
// away from the room (the centroid of `walls`, the matched walls on them): what the map saw outside
// the room.
double free_beyond_sides(const GridLevel& g, const core::Transform2& to_a, const std::vector<const Line*>& sides,
                         const std::vector<Eigen::Vector2d>& walls, double margin) {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& p : walls) centre += p;
  centre /= double(std::max<std::size_t>(walls.size(), 1));
  return free_share(g, to_a, [&](const Eigen::Vector2d& p) {
    return std::any_of(sides.begin(), sides.end(), [&](const Line* l) {
      const double room_side = l->normal.dot(centre - l->on), cell_side = l->normal.dot(p - l->on);
      return (room_side >= 0.0) != (cell_side >= 0.0) && std::abs(cell_side) > margin;
    });
  });
}

// The matched walls inside a room, more than `margin` in from the outline of all of them (their
// extent along the sides' two directions): a partition's end, a pillar, furniture, which pin where
// in the room the other map lies. The outline's own blocks (a thick wall's second face, ragged
// corners, a short side) are not counted.
int details_inside(const std::vector<Eigen::Vector2d>& walls, const std::vector<const Line*>& sides, double margin) {
  if (walls.empty() || sides.empty()) return 0;
  const Eigen::Vector2d n1 = sides[0]->normal, n2(-n1.y(), n1.x());
  double lo1 = n1.dot(walls[0]), hi1 = lo1, lo2 = n2.dot(walls[0]), hi2 = lo2;
  for (const auto& p : walls) {
    lo1 = std::min(lo1, n1.dot(p)), hi1 = std::max(hi1, n1.dot(p));
    lo2 = std::min(lo2, n2.dot(p)), hi2 = std::max(hi2, n2.dot(p));
  }
  return int(std::count_if(walls.begin(), walls.end(), [&](const Eigen::Vector2d& p) {
    const double u = n1.dot(p), v = n2.dot(p);
    return u - lo1 > margin && hi1 - u > margin && v - lo2 > margin && hi2 - v > margin;
  }));
}

}  // namespace

AlignmentQuality evaluate_alignment(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a,
                                    const QualityOptions& options) {
  Tally t;
  tally(b, a, b_to_a, core::Transform2::identity(), true, options, t);
  tally(a, b, b_to_a.inverse(), b_to_a, false, options, t);
  AlignmentQuality q;
  q.tested = t.tested;
  q.residual_rms = t.matched > 0 ? std::sqrt(t.squared_residuals / (t.matched + t.near)) : 0.0;
  q.matched = t.matched;
  q.contradicted = t.contradicted;
  q.score = t.matched - options.contradiction_weight * t.contradicted;
  q.agreement = t.matched + t.contradicted > 0 ? double(t.matched) / double(t.matched + t.contradicted) : 0.0;
  std::tie(q.open_space_walls, q.open_space_at) = largest_group(t.open_space);
  if (options.shape) {
    std::vector<Line> lines;
    const std::vector<int> left = beyond_lines(t.structure_positions, 4, 2.0, &lines, t.structure_normals,
                                               options.face_band_m / a.grid().resolution());
    q.beyond_corner = left[1];
    if (lines.size() >= 2) q.junction_arms = junction_arms(t.structure_positions, lines[0], lines[1], 2.0, 4.0, 3);
    q.wall_ends = t.wall_ends;
    q.beyond_room = left[3];
    const int total = int(t.structure_positions.size());
    // A side: a wall 16 cells long seen by both maps (8 blocks of 4 cells), a metre or more from
    // the room's other side along it.
    constexpr int kSideBlocks = 8;
    constexpr double kRoomWidthM = 1.0;
    int on_sides = 0;
    const auto sides = room_sides(lines, left, total, kSideBlocks, kRoomWidthM / a.grid().resolution(), on_sides);
    q.parallel_lines = most_parallel(sides);
    q.off_room_sides = total - on_sides;
    if (sides.size() >= 3 && q.parallel_lines <= 2) {
      constexpr double kMargin = 4.0;
      q.outside_room = std::min(free_beyond_sides(a.level(0), core::Transform2::identity(), sides, t.structure_positions, kMargin),
                                free_beyond_sides(b.level(0), b_to_a, sides, t.structure_positions, kMargin));
      q.room_details = details_inside(t.structure_positions, sides, 0.5 * kRoomWidthM / a.grid().resolution());
    }
    const double min_opening = options.min_opening_m / a.grid().resolution();
    const core::Transform2 a_to_b = b_to_a.inverse();
    for (std::size_t l = 0; l < lines.size(); ++l)
      if (points_on(left, total, l) >= 3)
        q.common_openings += openings_on(t.structure_positions, lines[l], 2.0, min_opening, a.level(0), b.level(0), a_to_b);
    if (lines.size() >= 3) {
      const int across = closed_end(t.structure_positions, lines, 2.0);
      if (across >= 0) {
        // One end of a hall only if neither map saw past the hall's side walls (its free cells
        // between them): a map that saw rooms beside the hall shows where along it the end is.
        const Line& s1 = lines[std::size_t((across + 1) % 3)];
        const Line& s2 = lines[std::size_t((across + 2) % 3)];
        constexpr double kMargin = 4.0, kMostOutside = 0.02;
        if (free_outside_strip(a.level(0), core::Transform2::identity(), s1, s2, kMargin) <= kMostOutside &&
            free_outside_strip(b.level(0), b_to_a, s1, s2, kMargin) <= kMostOutside)
          q.beyond_end = left[2];
      }
    }
  }
  if (t.positions.size() < 3) return q;
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& p : t.positions) c += p;
  c /= double(t.positions.size());
  double r2 = 0.0;
  for (const auto& p : t.positions) r2 += (p - c).squaredNorm();
  const double radius = std::sqrt(r2 / double(t.positions.size()));
  q.overlap_radius = radius;
  q.overlap_centre = c;
  if (radius < 1e-6) return q;
  // Information of (tx, ty, theta * radius): G = [I | perp(p - c) / radius], H = sum G^T S G.
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < t.positions.size(); ++i) {
    const Eigen::Vector2d d = (t.positions[i] - c) / radius;
    Eigen::Matrix<double, 2, 3> g;
    g << 1.0, 0.0, -d.y(), 0.0, 1.0, d.x();
    h += g.transpose() * t.structures[i] * g;
  }
  // Both maps contribute a copy of each matched wall; count each wall once.
  h *= 0.5;
  q.constraint = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(h, Eigen::EigenvaluesOnly).eigenvalues()(0);
  return q;
}

}  // namespace fleetmap::merging

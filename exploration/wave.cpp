#include "exploration/wave.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>

#include "core/error.h"

namespace fleetmap::exploration {

namespace {

// Straight neighbours first: the 4-connected wave uses only those.
constexpr int kDx[8] = {1, -1, 0, 0, 1, -1, 1, -1};
constexpr int kDy[8] = {0, 0, 1, -1, 1, 1, -1, -1};

}  // namespace

std::int64_t WaveField::reached_count() const {
  return std::count_if(units_.begin(), units_.end(), [](std::uint32_t u) { return u != kUnreachedUnits; });
}

std::uint32_t WaveField::step_units(int dir, int entered_index) const {
  if (step_units_.empty()) return dir < 4 ? kUnitsPerCell : kDiagonalUnits;
  return step_units_[2 * std::size_t(entered_index) + (dir < 4 ? 0 : 1)];
}

void compute_wave_into(const WaveGrid& grid, std::span<const Cell> sources, const WaveOptions& options, WaveField& out,
                       bool label) {
  const std::size_t n = std::size_t(grid.width) * std::size_t(grid.height);
  if (grid.passable.size() != n || (!grid.occupancy.empty() && grid.occupancy.size() != n) ||
      (!grid.step_factor.empty() && grid.step_factor.size() != n)) {
    throw Error("compute_wave: passable/occupancy/step_factor sizes do not match the grid");
  }
  out.width_ = grid.width;
  out.height_ = grid.height;
  out.eight_connected_ = options.eight_connected;
  out.units_.assign(n, WaveField::kUnreachedUnits);
  out.passable_.assign(grid.passable.begin(), grid.passable.end());
  const bool occupancy_weighted = options.occupancy_weight > 0.0 && !grid.occupancy.empty();
  const bool weighted = occupancy_weighted || !grid.step_factor.empty();
  std::uint32_t max_step = WaveField::kDiagonalUnits;
  if (weighted) {
    out.step_units_.resize(2 * n);
    for (std::size_t i = 0; i < n; ++i) {
      const double factor =
          occupancy_weighted ? 1.0 + options.occupancy_weight * std::clamp(double(grid.occupancy[i]), 0.0, 1.0) : 1.0;
      const std::uint32_t times = grid.step_factor.empty() ? 1 : std::max<std::uint32_t>(1, grid.step_factor[i]);
      out.step_units_[2 * i] = times * std::uint32_t(std::lround(double(WaveField::kUnitsPerCell) * factor));
      out.step_units_[2 * i + 1] = times * std::uint32_t(std::lround(double(WaveField::kDiagonalUnits) * factor));
      max_step = std::max(max_step, out.step_units_[2 * i + 1]);
    }
  } else {
    out.step_units_.clear();
  }
  const int w = grid.width, h = grid.height;
  std::uint32_t* units = out.units_.data();
  const std::uint8_t* passable = out.passable_.data();
  constexpr std::uint32_t kNone = WaveField::kUnreachedUnits;
  if (label) out.source_.assign(n, -1);
  else out.source_.clear();
  std::int32_t* source = label ? out.source_.data() : nullptr;

  if (!options.eight_connected && !weighted) {
    // Unit costs: a plain BFS over a flat queue (wave-algorithm paper, Table 1).
    thread_local std::vector<int> queue;
    queue.resize(n);
    std::size_t head = 0, tail = 0;
    for (const Cell& s : sources) {
      if (s.x < 0 || s.y < 0 || s.x >= w || s.y >= h) continue;
      const int i = s.y * w + s.x;
      if (units[i] == 0) continue;
      units[i] = 0;
      if (source) source[i] = std::int32_t(&s - sources.data());
      queue[tail++] = i;
    }
    constexpr std::uint32_t step = WaveField::kUnitsPerCell;
    while (head < tail) {
      const int i = queue[head++];
      const int x = i % w, y = i / w;
      const std::uint32_t next = units[i] + step;
      const auto visit = [&](int j) {
        units[j] = next;
        if (source) source[j] = source[i];
        queue[tail++] = j;
      };
      if (x + 1 < w && passable[i + 1] && units[i + 1] == kNone) visit(i + 1);
      if (x > 0 && passable[i - 1] && units[i - 1] == kNone) visit(i - 1);
      if (y + 1 < h && passable[i + w] && units[i + w] == kNone) visit(i + w);
      if (y > 0 && passable[i - w] && units[i - w] == kNone) visit(i - w);
    }
  } else {
    // Dial's algorithm: a circular array of buckets, one per cost value, wide enough for the
    // largest single step; every cell is settled in cost order without a heap.
    const std::size_t bucket_count = max_step + 1;
    thread_local std::vector<std::vector<int>> buckets;
    if (buckets.size() < bucket_count) buckets.resize(bucket_count);
    for (std::size_t b = 0; b < bucket_count; ++b) buckets[b].clear();
    std::size_t pending = 0;
    for (const Cell& s : sources) {
      if (s.x < 0 || s.y < 0 || s.x >= w || s.y >= h) continue;
      const int i = s.y * w + s.x;
      if (units[i] == 0) continue;
      units[i] = 0;
      if (source) source[i] = std::int32_t(&s - sources.data());
      buckets[0].push_back(i);
      ++pending;
    }
    const int neighbours = options.eight_connected ? 8 : 4;
    const std::uint32_t* weighted_steps = weighted ? out.step_units_.data() : nullptr;
    for (std::uint32_t d = 0; pending > 0; ++d) {
      auto& bucket = buckets[d % bucket_count];
      while (!bucket.empty()) {
        const int i = bucket.back();
        bucket.pop_back();
        --pending;
        if (units[i] != d) continue;  // settled earlier at a lower cost
        const int x = i % w, y = i / w;
        for (int k = 0; k < neighbours; ++k) {
          const int nx = x + kDx[k], ny = y + kDy[k];
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const int j = ny * w + nx;
          if (!passable[j]) continue;
          if (k >= 4 && (!passable[y * w + nx] || !passable[ny * w + x])) continue;  // no corner cutting
          const std::uint32_t step = weighted_steps ? weighted_steps[2 * std::size_t(j) + (k < 4 ? 0 : 1)]
                                                    : (k < 4 ? WaveField::kUnitsPerCell : WaveField::kDiagonalUnits);
          const std::uint32_t c = d + step;
          if (c < units[j]) {
            units[j] = c;
            if (source) source[j] = source[i];
            buckets[c % bucket_count].push_back(j);
            ++pending;
          }
        }
      }
    }
  }
  out.cost_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.cost_[i] = units[i] == kNone ? WaveField::kUnreached : float(units[i]) / float(WaveField::kUnitsPerCell);
  }
}

void compute_wave(const WaveGrid& grid, std::span<const Cell> sources, const WaveOptions& options, WaveField& out) {
  compute_wave_into(grid, sources, options, out, false);
}

void compute_labelled_wave(const WaveGrid& grid, std::span<const Cell> sources, const WaveOptions& options, WaveField& out) {
  compute_wave_into(grid, sources, options, out, true);
}

std::vector<float> pairwise_wave_costs(const WaveGrid& grid, std::span<const Cell> goals, const WaveOptions& options,
                                       WaveField& scratch) {
  const std::size_t m = goals.size();
  constexpr double kNone = std::numeric_limits<double>::infinity();
  std::vector<double> cost(m * m, kNone);
  for (std::size_t a = 0; a < m; ++a) cost[a * m + a] = 0.0;
  compute_labelled_wave(grid, goals, options, scratch);
  const int w = scratch.width_, h = scratch.height_;
  const std::uint32_t* units = scratch.units_.data();
  const std::int32_t* source = scratch.source_.data();
  // A goal on another goal's cell (or outside the grid) has no region of its own: it stands in for
  // the goal whose wave holds its cell.
  std::vector<int> region(m, -1);
  for (std::size_t a = 0; a < m; ++a) {
    if (goals[a].x >= 0 && goals[a].y >= 0 && goals[a].x < w && goals[a].y < h) region[a] = source[goals[a].y * w + goals[a].x];
  }
  // Joins between touching regions: the cheapest crossing of their border. Each neighbour pair is
  // looked at once (right, down, and the two lower diagonals, which may not cut a corner).
  std::vector<double> join(m * m, kNone);
  const int neighbours = options.eight_connected ? 4 : 2;
  constexpr int kNx[4] = {1, 0, 1, -1}, kNy[4] = {0, 1, 1, 1};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      const int si = source[i];
      if (si < 0) continue;
      for (int k = 0; k < neighbours; ++k) {
        const int nx = x + kNx[k], ny = y + kNy[k];
        if (nx < 0 || nx >= w || ny >= h) continue;
        const int j = ny * w + nx;
        const int sj = source[j];
        if (sj < 0 || sj == si) continue;
        if (k >= 2 && (!scratch.passable_[std::size_t(y * w + nx)] || !scratch.passable_[std::size_t(ny * w + x)])) continue;
        const int dir = k < 2 ? 0 : 4;
        // Across the border into j (the wave's step into j) and into i (for the other direction);
        // the dearer of the two, so that the join is a path either way.
        const double step = double(std::max(scratch.step_units(dir, j), scratch.step_units(dir, i)));
        const double c = double(units[i]) + step + double(units[j]);
        const std::size_t ab = std::size_t(si) * m + std::size_t(sj);
        if (c < join[ab]) join[ab] = join[std::size_t(sj) * m + std::size_t(si)] = c;
      }
    }
  }
  std::vector<std::vector<std::pair<int, double>>> adjacent(m);
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b < m; ++b)
      if (a != b && join[a * m + b] < kNone) adjacent[a].push_back({int(b), join[a * m + b]});
  // Dijkstra over the joins from every region's goal.
  std::vector<double> dist(m);
  using Item = std::pair<double, int>;
  for (std::size_t a = 0; a < m; ++a) {
    if (region[a] != int(a)) continue;
    std::fill(dist.begin(), dist.end(), kNone);
    dist[a] = 0.0;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
    open.push({0.0, int(a)});
    while (!open.empty()) {
      const auto [d, u] = open.top();
      open.pop();
      if (d > dist[std::size_t(u)]) continue;
      for (const auto& [v, c] : adjacent[std::size_t(u)]) {
        if (d + c < dist[std::size_t(v)]) {
          dist[std::size_t(v)] = d + c;
          open.push({d + c, v});
        }
      }
    }
    for (std::size_t b = 0; b < m; ++b) cost[a * m + b] = dist[b];
  }
  // Goals without a region of their own take their stand-in's costs.
  std::vector<float> out(m * m, WaveField::kUnreached);
  for (std::size_t a = 0; a < m; ++a) {
    for (std::size_t b = 0; b < m; ++b) {
      if (a == b) {
        out[a * m + b] = 0.0f;
        continue;
      }
      if (region[a] < 0 || region[b] < 0) continue;
      const double c = cost[std::size_t(region[a]) * m + std::size_t(region[b])];
      if (c < kNone) out[a * m + b] = float(c / double(WaveField::kUnitsPerCell));
    }
  }
  return out;
}

std::vector<Cell> WaveField::path_to(const Cell& target) const {
  if (!reached(target)) return {};
  std::vector<Cell> path = {target};
  Cell c = target;
  const int neighbours = eight_connected_ ? 8 : 4;
  // Each step goes back to a neighbour the wave came from: units(n) + step(n -> c) == units(c).
  // Among those, straight steps first, so paths stay close to straight lines.
  while (units_[std::size_t(c.y * width_ + c.x)] > 0) {
    const int i = c.y * width_ + c.x;
    const std::uint32_t here = units_[std::size_t(i)];
    Cell previous = c;
    for (int k = 0; k < neighbours; ++k) {
      const Cell n{c.x + kDx[k], c.y + kDy[k]};
      if (!contains(n)) continue;
      const std::uint32_t there = units_[std::size_t(n.y * width_ + n.x)];
      if (there == kUnreachedUnits || there >= here) continue;
      if (k >= 4 && (!passable_[std::size_t(c.y * width_ + n.x)] || !passable_[std::size_t(n.y * width_ + c.x)])) continue;
      if (there + step_units(k, i) == here) {
        previous = n;
        break;
      }
    }
    if (previous == c) break;  // only a source has no predecessor
    c = previous;
    path.push_back(c);
  }
  std::reverse(path.begin(), path.end());
  return path;
}

}  // namespace fleetmap::exploration

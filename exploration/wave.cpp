#include "exploration/wave.h"

#include <algorithm>
#include <cmath>

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

void compute_wave(const WaveGrid& grid, std::span<const Cell> sources, const WaveOptions& options, WaveField& out) {
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
      queue[tail++] = i;
    }
    constexpr std::uint32_t step = WaveField::kUnitsPerCell;
    while (head < tail) {
      const int i = queue[head++];
      const int x = i % w, y = i / w;
      const std::uint32_t next = units[i] + step;
      if (x + 1 < w && passable[i + 1] && units[i + 1] == kNone) units[i + 1] = next, queue[tail++] = i + 1;
      if (x > 0 && passable[i - 1] && units[i - 1] == kNone) units[i - 1] = next, queue[tail++] = i - 1;
      if (y + 1 < h && passable[i + w] && units[i + w] == kNone) units[i + w] = next, queue[tail++] = i + w;
      if (y > 0 && passable[i - w] && units[i - w] == kNone) units[i - w] = next, queue[tail++] = i - w;
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

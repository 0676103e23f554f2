#include "exploration/wave.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <span>

namespace fleetmap::exploration {
namespace {

struct RandomGrid {
  int w, h;
  std::vector<std::uint8_t> passable;
  std::vector<float> occupancy;
};

RandomGrid random_grid(std::mt19937& rng, int w, int h, double blocked) {
  RandomGrid g{w, h, std::vector<std::uint8_t>(std::size_t(w * h)), std::vector<float>(std::size_t(w * h))};
  std::bernoulli_distribution b(blocked);
  std::uniform_real_distribution<float> p(0.0f, 1.0f);
  for (int i = 0; i < w * h; ++i) {
    g.passable[std::size_t(i)] = !b(rng);
    g.occupancy[std::size_t(i)] = p(rng);
  }
  return g;
}

// Textbook Dijkstra with std::priority_queue and explicit step costs, as the reference.
std::vector<double> reference(const RandomGrid& g, const std::vector<Cell>& sources, bool eight, double weight,
                              double straight, double diagonal, bool round_steps) {
  const int w = g.w, h = g.h;
  std::vector<double> d(std::size_t(w * h), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> q;
  for (const Cell& s : sources) {
    d[std::size_t(s.y * w + s.x)] = 0.0;
    q.push({0.0, s.y * w + s.x});
  }
  while (!q.empty()) {
    const auto [c, i] = q.top();
    q.pop();
    if (c > d[std::size_t(i)]) continue;
    const int x = i % w, y = i / w;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dy == 0) || (!eight && dx != 0 && dy != 0)) continue;
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const int j = ny * w + nx;
        if (!g.passable[std::size_t(j)]) continue;
        const bool diag = dx != 0 && dy != 0;
        if (diag && (!g.passable[std::size_t(y * w + nx)] || !g.passable[std::size_t(ny * w + x)])) continue;
        double step = (diag ? diagonal : straight) * (1.0 + weight * double(g.occupancy[std::size_t(j)]));
        if (round_steps) step = std::round(step);
        if (c + step < d[std::size_t(j)]) {
          d[std::size_t(j)] = c + step;
          q.push({c + step, j});
        }
      }
    }
  }
  return d;
}

struct Case {
  bool eight;
  double weight;
};

class WaveMatchesReference : public ::testing::TestWithParam<Case> {};

TEST_P(WaveMatchesReference, OnRandomGridsWithSeveralSources) {
  const Case c = GetParam();
  std::mt19937 rng(42);
  for (int trial = 0; trial < 40; ++trial) {
    std::uniform_int_distribution<int> size(1, 40);
    const RandomGrid g = random_grid(rng, size(rng), size(rng), 0.3);
    std::vector<Cell> sources;
    std::uniform_int_distribution<int> sx(0, g.w - 1), sy(0, g.h - 1);
    for (int k = 0; k < 1 + trial % 3; ++k) sources.push_back({sx(rng), sy(rng)});
    WaveOptions o;
    o.eight_connected = c.eight;
    o.occupancy_weight = c.weight;
    const WaveField f = compute_wave({g.w, g.h, g.passable, g.occupancy, {}}, sources, o);
    // Exact, in whole units of 1/70 cell.
    const auto units = reference(g, sources, c.eight, c.weight, 70.0, 99.0, true);
    // Against the true costs: a diagonal of 99/70 is within 5e-5 of sqrt(2); a weighted step is rounded
    // to whole units of 1/70 cell, at most 0.5/70 of its length (every step is at least one cell).
    const auto exact = reference(g, sources, c.eight, c.weight, 1.0, std::sqrt(2.0), false);
    const double relative = c.weight > 0.0 ? 0.5 / 70.0 : 5e-5;
    for (int i = 0; i < g.w * g.h; ++i) {
      if (std::isinf(units[std::size_t(i)])) {
        EXPECT_EQ(f.units_at(i), WaveField::kUnreachedUnits) << "cell " << i;
        EXPECT_FALSE(f.reached(Cell{i % g.w, i / g.w}));
        continue;
      }
      ASSERT_EQ(double(f.units_at(i)), units[std::size_t(i)]) << "trial " << trial << " cell " << i;
      EXPECT_NEAR(f.cost_at(i), exact[std::size_t(i)], relative * exact[std::size_t(i)] + 1e-4);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Variants, WaveMatchesReference,
                         ::testing::Values(Case{false, 0.0}, Case{true, 0.0}, Case{false, 2.0}, Case{true, 3.0}));

TEST(Wave, PathsDescendTheWaveAndHaveItsLength) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 30; ++trial) {
    const RandomGrid g = random_grid(rng, 30, 25, 0.25);
    const Cell source{3, 4};
    for (const bool eight : {false, true}) {
      WaveOptions o;
      o.eight_connected = eight;
      const WaveField f = compute_wave({g.w, g.h, g.passable, {}, {}}, std::vector<Cell>{source}, o);
      for (int i = 0; i < g.w * g.h; i += 7) {
        const Cell target{i % g.w, i / g.w};
        const auto path = f.path_to(target);
        if (!f.reached(target)) {
          EXPECT_TRUE(path.empty());
          continue;
        }
        ASSERT_FALSE(path.empty());
        EXPECT_EQ(path.front(), source);
        EXPECT_EQ(path.back(), target);
        double length = 0.0;
        for (std::size_t k = 1; k < path.size(); ++k) {
          const int dx = std::abs(path[k].x - path[k - 1].x), dy = std::abs(path[k].y - path[k - 1].y);
          ASSERT_LE(dx, 1);
          ASSERT_LE(dy, 1);
          ASSERT_TRUE(eight || dx + dy == 1);
          ASSERT_TRUE(g.passable[std::size_t(path[k].y * g.w + path[k].x)]);
          length += (dx + dy == 2) ? 99.0 / 70.0 : 1.0;
        }
        EXPECT_NEAR(length, f.cost(target), 1e-4);
      }
    }
  }
}

TEST(Wave, FourConnectedIsSeedThreeCounting) {
  // The wave-algorithm paper, Fig. 1: the robot's cell is 0, its neighbours 1, theirs 2, ...
  std::vector<std::uint8_t> open(5 * 5, 1);
  const WaveField f = compute_wave({5, 5, open, {}, {}}, std::vector<Cell>{{2, 2}}, WaveOptions{false, 0.0});
  EXPECT_EQ(f.cost({2, 2}), 0.0f);
  EXPECT_EQ(f.cost({3, 2}), 1.0f);
  EXPECT_EQ(f.cost({3, 3}), 2.0f);
  EXPECT_EQ(f.cost({0, 0}), 4.0f);
  EXPECT_EQ(f.reached_count(), 25);
}

TEST(Wave, NoCornerCutting) {
  // Two blocked cells touching diagonally: the diagonal step between them is not allowed.
  //   . #
  //   # .
  std::vector<std::uint8_t> p = {1, 0, 0, 1};
  const WaveField f = compute_wave({2, 2, p, {}, {}}, std::vector<Cell>{{0, 0}}, WaveOptions{true, 0.0});
  EXPECT_FALSE(f.reached({1, 1}));
}

// The costs between goals from one labelled wave: never below the wave from either goal, the same
// as it from every goal to its nearest one (no third goal's region lies on that path), and
// symmetric; goals the grid does not connect are kUnreached apart.
TEST(Wave, PairwiseCostsFromOneLabelledWave) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 40; ++trial) {
    const RandomGrid g = random_grid(rng, 30, 24, 0.25);
    std::vector<Cell> goals;
    std::uniform_int_distribution<int> sx(0, g.w - 1), sy(0, g.h - 1);
    while (goals.size() < std::size_t(2 + trial % 9)) {
      const Cell c{sx(rng), sy(rng)};
      if (g.passable[std::size_t(c.y * g.w + c.x)]) goals.push_back(c);
    }
    if (trial % 5 == 0) goals.push_back(goals.front());  // two goals on one cell
    WaveOptions o;
    o.eight_connected = trial % 2 == 0;
    const std::size_t m = goals.size();
    WaveField scratch;
    const auto pairwise = pairwise_wave_costs({g.w, g.h, g.passable, {}, {}}, goals, o, scratch);
    ASSERT_EQ(pairwise.size(), m * m);
    for (std::size_t a = 0; a < m; ++a) {
      const WaveField from_a = compute_wave({g.w, g.h, g.passable, {}, {}}, std::span<const Cell>(&goals[a], 1), o);
      float nearest_exact = WaveField::kUnreached, nearest_pairwise = WaveField::kUnreached;
      for (std::size_t b = 0; b < m; ++b) {
        const float exact = from_a.cost(goals[b]), c = pairwise[a * m + b];
        EXPECT_EQ(c, pairwise[b * m + a]) << "trial " << trial;
        if (exact == WaveField::kUnreached) {
          EXPECT_EQ(c, WaveField::kUnreached) << "trial " << trial << ": unconnected goals " << a << ", " << b;
          continue;
        }
        EXPECT_GE(c, exact - 1e-4f) << "trial " << trial;
        if (b == a || goals[b] == goals[a]) {
          EXPECT_EQ(c, 0.0f);
          continue;
        }
        nearest_exact = std::min(nearest_exact, exact);
        nearest_pairwise = std::min(nearest_pairwise, c);
      }
      if (nearest_exact == WaveField::kUnreached) EXPECT_EQ(nearest_pairwise, WaveField::kUnreached);
      else EXPECT_NEAR(nearest_pairwise, nearest_exact, 1e-4) << "trial " << trial << " goal " << a;
    }
    // The labels: each reached cell belongs to a goal no farther than any other.
    for (int i = 0; i < g.w * g.h; i += 5) EXPECT_EQ(scratch.source_at(i) >= 0, scratch.cost_at(i) < WaveField::kUnreached);
  }
}

}  // namespace
}  // namespace fleetmap::exploration

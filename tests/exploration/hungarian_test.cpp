#include "exploration/hungarian.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>

namespace fleetmap::exploration {
namespace {

// Every injective assignment of the smaller side into the larger, by enumeration.
double brute_force(const Eigen::MatrixXd& c) {
  const int n = int(c.rows()), m = int(c.cols());
  const bool rows_small = n <= m;
  const int small = rows_small ? n : m, large = rows_small ? m : n;
  std::vector<int> perm(static_cast<std::size_t>(large));
  std::iota(perm.begin(), perm.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  do {
    double total = 0.0;
    for (int i = 0; i < small; ++i) total += rows_small ? c(i, perm[std::size_t(i)]) : c(perm[std::size_t(i)], i);
    best = std::min(best, total);
  } while (std::next_permutation(perm.begin(), perm.end()));
  return best;
}

TEST(Hungarian, EqualsBruteForceUpToSevenBySeven) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> cost(-5.0, 20.0);
  for (int n = 1; n <= 7; ++n) {
    for (int m = 1; m <= 7; ++m) {
      for (int trial = 0; trial < 6; ++trial) {
        Eigen::MatrixXd c(n, m);
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < m; ++j) c(i, j) = trial % 2 ? std::round(cost(rng)) : cost(rng);  // ties too
        const std::vector<int> a = solve_assignment(c);
        ASSERT_EQ(int(a.size()), n);
        double total = 0.0;
        std::vector<char> used(std::size_t(m), false);
        int assigned = 0;
        for (int i = 0; i < n; ++i) {
          if (a[std::size_t(i)] < 0) continue;
          ASSERT_LT(a[std::size_t(i)], m);
          ASSERT_FALSE(used[std::size_t(a[std::size_t(i)])]) << "column used twice";
          used[std::size_t(a[std::size_t(i)])] = true;
          total += c(i, a[std::size_t(i)]);
          ++assigned;
        }
        EXPECT_EQ(assigned, std::min(n, m));
        EXPECT_NEAR(total, brute_force(c), 1e-9) << n << "x" << m << " trial " << trial;
      }
    }
  }
}

TEST(Hungarian, EmptyAndNonFinite) {
  EXPECT_TRUE(solve_assignment(Eigen::MatrixXd(0, 3)).empty());
  EXPECT_EQ(solve_assignment(Eigen::MatrixXd(2, 0)), (std::vector<int>{-1, -1}));
  Eigen::MatrixXd bad(1, 1);
  bad(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_ANY_THROW(solve_assignment(bad));
}

}  // namespace
}  // namespace fleetmap::exploration

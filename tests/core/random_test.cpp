#include "core/random.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace fleetmap::core {
namespace {

std::vector<double> draw(Random& r, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(r.normal(0.0, 1.0) + r.uniform());
  return v;
}

TEST(Random, SameSeedSameNumbers) {
  Random a(123), b(123), c(124);
  const auto va = draw(a, 100), vb = draw(b, 100), vc = draw(c, 100);
  EXPECT_EQ(va, vb);
  EXPECT_NE(va, vc);
}

TEST(Random, ForksAreReproducibleAndDistinct) {
  Random a(9);
  Random f1 = a.fork(1), f1_again = a.fork(1), f2 = a.fork(2);
  EXPECT_EQ(draw(f1, 50), draw(f1_again, 50));
  Random g1 = a.fork(1);
  EXPECT_NE(draw(g1, 50), draw(f2, 50));
}

TEST(Random, NormalHasTheAskedSpread) {
  Random r(5);
  const int n = 20000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = r.normal(2.0, 0.5);
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  // Standard errors: 0.5/sqrt(n) = 0.0035 for the mean; about 0.0025 for the deviation.
  EXPECT_NEAR(mean, 2.0, 5 * 0.0035);
  EXPECT_NEAR(sd, 0.5, 5 * 0.0025);
  EXPECT_EQ(r.normal(1.5, 0.0), 1.5);
}

}  // namespace
}  // namespace fleetmap::core

#include "exploration/hungarian.h"

#include <limits>

#include "core/error.h"

namespace fleetmap::exploration {

namespace {

// Rows <= columns. Classic shortest-augmenting-path form with row/column potentials u, v.
std::vector<int> solve_wide(const Eigen::MatrixXd& a) {
  const int n = int(a.rows()), m = int(a.cols());
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> u(std::size_t(n) + 1, 0.0), v(std::size_t(m) + 1, 0.0);
  std::vector<int> p(std::size_t(m) + 1, 0), way(std::size_t(m) + 1, 0);  // p[j]: row (1-based) on column j
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(std::size_t(m) + 1, kInf);
    std::vector<char> used(std::size_t(m) + 1, false);
    do {
      used[std::size_t(j0)] = true;
      const int i0 = p[std::size_t(j0)];
      double delta = kInf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[std::size_t(j)]) continue;
        const double cur = a(i0 - 1, j - 1) - u[std::size_t(i0)] - v[std::size_t(j)];
        if (cur < minv[std::size_t(j)]) minv[std::size_t(j)] = cur, way[std::size_t(j)] = j0;
        if (minv[std::size_t(j)] < delta) delta = minv[std::size_t(j)], j1 = j;
      }
      for (int j = 0; j <= m; ++j) {
        if (used[std::size_t(j)]) {
          u[std::size_t(p[std::size_t(j)])] += delta;
          v[std::size_t(j)] -= delta;
        } else {
          minv[std::size_t(j)] -= delta;
        }
      }
      j0 = j1;
    } while (p[std::size_t(j0)] != 0);
    do {
      const int j1 = way[std::size_t(j0)];
      p[std::size_t(j0)] = p[std::size_t(j1)];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(std::size_t(n), -1);
  for (int j = 1; j <= m; ++j) {
    if (p[std::size_t(j)] != 0) row_to_col[std::size_t(p[std::size_t(j)] - 1)] = j - 1;
  }
  return row_to_col;
}

}  // namespace

std::vector<int> solve_assignment(const Eigen::MatrixXd& cost) {
  if (!cost.allFinite()) throw Error("solve_assignment: costs must be finite");
  if (cost.rows() == 0 || cost.cols() == 0) return std::vector<int>(std::size_t(cost.rows()), -1);
  if (cost.rows() <= cost.cols()) return solve_wide(cost);
  const std::vector<int> col_to_row = solve_wide(cost.transpose());
  std::vector<int> row_to_col(std::size_t(cost.rows()), -1);
  for (std::size_t c = 0; c < col_to_row.size(); ++c) {
    if (col_to_row[c] >= 0) row_to_col[std::size_t(col_to_row[c])] = int(c);
  }
  return row_to_col;
}

}  // namespace fleetmap::exploration

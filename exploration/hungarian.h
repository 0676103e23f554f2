#pragma once
// The assignment problem solved exactly (Kuhn-Munkres with potentials, O(n^2 m)).
#include <Eigen/Core>
#include <vector>

namespace fleetmap::exploration {

// Minimum-cost assignment of rows to distinct columns of a finite cost matrix. With more rows than
// columns only `cols` rows are assigned. Returns, per row, its column or -1.
std::vector<int> solve_assignment(const Eigen::MatrixXd& cost);

}  // namespace fleetmap::exploration

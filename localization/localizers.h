#pragma once
// The factories behind the localizer registry (localizer_registry.cpp). Add a localizer by
// writing its file, declaring its factory here and adding one row to the registry table.
#include <memory>

#include "localization/localizer.h"

namespace fleetmap::localization {

// The covariance of a pose whose frame turns by `angle`: J P J^T with J = diag(R(angle), 1).
Eigen::Matrix3d rotate_pose_covariance(const Eigen::Matrix3d& covariance, double angle);

std::unique_ptr<Localizer> make_ideal_localizer(const LocalizerContext& context);
std::unique_ptr<Localizer> make_odometry_localizer(const LocalizerContext& context);
std::unique_ptr<Localizer> make_ekf_localizer(const LocalizerContext& context);       // ekf_localizer.cpp
std::unique_ptr<Localizer> make_ekf_slam_localizer(const LocalizerContext& context);  // ekf_slam_localizer.cpp
std::unique_ptr<Localizer> make_polynomial_localizer(const LocalizerContext& context);  // polynomial_localizer.cpp
std::unique_ptr<Localizer> make_scan_matching_localizer(const LocalizerContext& context);  // scan_matching_localizer.cpp
std::unique_ptr<Localizer> make_mcl_localizer(const LocalizerContext& context);            // mcl_localizer.cpp
std::unique_ptr<Localizer> make_rbpf_localizer(const LocalizerContext& context);           // rbpf_localizer.cpp
std::unique_ptr<Localizer> make_grid_fastslam_localizer(const LocalizerContext& context);  // rbpf_localizer.cpp
std::unique_ptr<Localizer> make_graph_slam_localizer(const LocalizerContext& context);      // graph_slam_localizer.cpp
std::unique_ptr<Localizer> make_fastslam2_localizer(const LocalizerContext& context);      // fastslam2.cpp

}  // namespace fleetmap::localization

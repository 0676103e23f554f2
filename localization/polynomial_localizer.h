#pragma once
// `polynomial`: D'Alfonso et al.'s polynomial EKF-SLAM (localization/polynomial_slam.h) as a
// Localizer: the one face of the filter, for the registry and for the experiments. It learns its
// map from the range scans it is given (update_scan), as polynomials whose c_0 coefficients share
// the state with the pose; point landmarks and robot detections are not used.
//  - The registered localizer (make_polynomial_localizer) builds it from a LocalizerContext: P0 and
//    Q from the options, the distance readings' noise options.scan_range_noise, a scan thinned to
//    36 beams.
//  - D'Alfonso et al.'s experiment (experiments/slam_experiment.cpp) builds it with every option of
//    the filter (its scenario's P0, Q and `polynomial:` settings, every sensor's reading) and
//    reaches the filter through slam() for the rendezvous exchange (§3.2).
#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "localization/localizer.h"
#include "localization/polynomial_slam.h"

namespace fleetmap::localization {

class PolynomialLocalizer final : public Localizer {
 public:
  // A scan is thinned to `max_beams` evenly spaced beams (0: every beam is read).
  PolynomialLocalizer(const core::Pose2& start, const Eigen::Matrix3d& initial_covariance,
                      const Eigen::Matrix3d& process_noise, const PolynomialSlamOptions& options,
                      std::size_t max_beams = 0);

  std::string name() const override { return "polynomial"; }
  bool uses_scans() const override { return true; }
  void predict(const Odometry& u) override { slam_.predict(u); }
  void update_scan(const RangeScan& scan, const mapping::OccupancyGrid& own_map) override;
  void change_frame(const core::Transform2& new_from_old) override { slam_.change_frame(new_from_old); }
  core::Pose2 pose() const override { return slam_.pose(); }
  Eigen::Matrix3d covariance() const override { return slam_.pose_covariance(); }
  std::vector<std::pair<std::string, double>> counters() const override;

  PolynomialSlam& slam() { return slam_; }
  const PolynomialSlam& slam() const { return slam_; }

 private:
  PolynomialSlam slam_;
  std::size_t max_beams_;
};

}  // namespace fleetmap::localization

// `scan-matching`: maximum-likelihood incremental mapping (León et al., §II.A, eq. (1)-(4); Hähnel et
// al. 2002). Each step the odometry gives a guess; the new scan is aligned to the robot's map so far
// (m_{t-1}, built at the estimated poses) with match_scan_to_grid() and the aligned pose replaces the
// odometry step; then the scan joins the map at that pose.
//
// The localizer keeps its own copy of that map (a CowGrid, which also records where in each cell the
// beams ended, for sub-cell matching as GMapping does). It starts from the robot's own grid at the
// first scan, and again whenever that grid's geometry changes (after change_frame): so a teammate's
// merged map also serves for matching from then on.
//
// The covariance grows as dead reckoning's, with each step's match covariance as the increment
// (a match is relative to the robot's own map, so it never shrinks the uncertainty).
#include <cmath>

#include "mapping/range_scan.h"
#include "localization/cow_grid.h"
#include "localization/ekf_models.h"
#include "localization/localizer.h"
#include "localization/localizers.h"
#include "localization/scan_matcher.h"

namespace fleetmap::localization {

namespace {

class ScanMatchingLocalizer final : public Localizer {
 public:
  explicit ScanMatchingLocalizer(const LocalizerContext& c)
      : pose_(c.initial_pose), options_(c.options), covariance_(initial_covariance(c.options)) {}
  std::string name() const override { return "scan-matching"; }
  bool uses_scans() const override { return true; }

  void predict(const Odometry& u) override {
    const Eigen::Matrix3d f = motion_jacobian(pose_, u);
    covariance_ = f * covariance_ * f.transpose();
    pending_ = process_noise(options_);
    pose_ = integrate_motion(pose_, u);
    turned_ += std::abs(u.omega * u.dt);
  }

  void update_scan(const RangeScan& scan, const mapping::OccupancyGrid& own_map) override {
    if (!map_ready_ || !(map_.geometry() == own_map.geometry())) {
      map_ = CowGrid::from_occupancy_grid(own_map);
      map_ready_ = true;
    }
    const ScanMatch match = match_scan_to_grid(map_, scan, pose_, scan_matcher_options(options_, scan.max_range, own_map.resolution(), turned_));
    if (match.matched) {
      pose_ = match.pose;
      pending_ = match.covariance;
      ++matches_;
    } else {
      ++skipped_;
    }
    covariance_ += pending_;
    pending_.setZero();
    turned_ = 0.0;
    mapping::insert_scan(map_, pose_, scan);
  }

  core::Pose2 pose() const override { return pose_; }
  Eigen::Matrix3d covariance() const override { return covariance_ + pending_; }
  void change_frame(const core::Transform2& t) override {
    pose_ = core::Pose2::from_transform(t * pose_.as_transform());
    covariance_ = rotate_pose_covariance(covariance_, t.rotation());
    map_ready_ = false;  // restart from the robot's map in the new frame at the next scan
  }
  std::vector<std::pair<std::string, double>> counters() const override {
    return {{"scan_matches", double(matches_)}, {"scans_not_matched", double(skipped_)}};
  }
  std::optional<mapping::OccupancyGrid> map_estimate() const override {
    if (!map_ready_) return std::nullopt;
    return map_.to_occupancy_grid();
  }

 private:
  core::Pose2 pose_;
  LocalizerOptions options_;
  Eigen::Matrix3d covariance_;
  Eigen::Matrix3d pending_ = Eigen::Matrix3d::Zero();
  CowGrid map_;
  bool map_ready_ = false;
  int matches_ = 0, skipped_ = 0;
  double turned_ = 0.0;  // by the odometry since the last scan
};

}  // namespace

std::unique_ptr<Localizer> make_scan_matching_localizer(const LocalizerContext& c) {
  return std::make_unique<ScanMatchingLocalizer>(c);
}

}  // namespace fleetmap::localization

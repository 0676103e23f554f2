// `graph-slam`: GraphSlam (graph_slam.h) behind the Localizer interface. The odometry between two
// scans is the prior of the next scan's match; pose() is the newest scan's pose in the map frame
// moved by the odometry since. The own_map the simulator keeps is not read: the submaps are the map.
#include "localization/graph_slam.h"
#include "localization/localizer.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

namespace {

// The declared parameters (localizer_registry.cpp) over GraphSlamOptions' defaults.
GraphSlamOptions options_from(const core::Params& p, const LocalizerOptions& shared) {
  GraphSlamOptions o;
  o.turn_noise_per_rad = shared.turn_noise_per_rad;
  o.drive_noise_per_m = shared.drive_noise_per_m;
  if (p.specs().empty()) return o;
  o.max_range_m = p.number("max_range");
  o.scans_per_submap = int(p.number("scans_per_submap"));
  o.insert_min_distance_m = p.number("insert_min_distance");
  o.max_constraint_distance_m = p.number("max_constraint_distance");
  o.loop_sampling_ratio = p.number("loop_sampling_ratio");
  o.loop_rival_errors = p.number("loop_rival_errors");
  o.huber_scale = p.number("huber_scale");
  return o;
}

class GraphSlamLocalizer final : public Localizer {
 public:
  explicit GraphSlamLocalizer(const LocalizerContext& c)
      : slam_(options_from(c.params, c.options), c.initial_pose), pose_(c.initial_pose) {
    const double xy = c.options.initial_xy, th = c.options.initial_theta;
    covariance_ = Eigen::Vector3d(xy * xy, xy * xy, th * th).asDiagonal();
  }
  std::string name() const override { return "graph-slam"; }
  bool uses_scans() const override { return true; }
  bool ignores_own_map() const override { return true; }

  void predict(const Odometry& u) override {
    odometry_ = integrate_motion(odometry_, u);
    dt_ += u.dt;
    pose_ = integrate_motion(pose_, u);
  }
  void update_scan(const RangeScan& scan, const mapping::OccupancyGrid& /*own_map*/) override {
    pose_ = slam_.add_scan(odometry_, scan, dt_);
    odometry_ = core::Pose2();
    dt_ = 0.0;
  }
  core::Pose2 pose() const override { return pose_; }
  // The matcher's spread is not estimated; the initial uncertainty stands for it.
  Eigen::Matrix3d covariance() const override { return covariance_; }
  void change_frame(const core::Transform2& new_from_old) override {
    const core::Pose2 t = core::Pose2::from_transform(new_from_old);
    slam_.change_frame(t);
    pose_ = t.compose(pose_);
  }
  std::optional<std::vector<core::Pose2>> finish_trajectory() override {
    slam_.finish();
    auto poses = slam_.poses();
    if (!poses.empty()) pose_ = poses.back().compose(odometry_);
    return poses;
  }
  std::vector<std::pair<std::string, double>> counters() const override {
    return {{"nodes", double(slam_.nodes())},
            {"submaps", double(slam_.submaps())},
            {"loop_closures", double(slam_.loop_closures())},
            {"rejected_loop_closures", double(slam_.rejected_loop_closures())},
            {"optimizations", double(slam_.optimizations())},
            {"relocalized_scans", double(slam_.relocalized())}};
  }

 private:
  GraphSlam slam_;
  core::Pose2 pose_;
  core::Pose2 odometry_;  // since the last scan
  double dt_ = 0.0;
  Eigen::Matrix3d covariance_;
};

}  // namespace

std::unique_ptr<Localizer> make_graph_slam_localizer(const LocalizerContext& context) {
  return std::make_unique<GraphSlamLocalizer>(context);
}

}  // namespace fleetmap::localization

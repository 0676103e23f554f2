// `polynomial`: D'Alfonso et al.'s polynomial EKF-SLAM as a Localizer. It learns its map from the range
// scans it is given (update_scan), as polynomials whose c_0 coefficients share the state with the
// pose; point landmarks and robot detections are not used. The distance readings' noise is
// options.scan_range_noise.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "localization/ekf_models.h"
#include "localization/localizer.h"
#include "localization/localizers.h"
#include "localization/polynomial_slam.h"

namespace fleetmap::localization {

namespace {

// D'Alfonso et al. uses five distance sensors; a 360-beam laser gives far more readings than the filter
// needs (each is one O(n^2) update), so a scan is thinned to this many evenly spaced beams.
constexpr std::size_t kMaxBeams = 36;

class PolynomialLocalizer final : public Localizer {
 public:
  explicit PolynomialLocalizer(const LocalizerContext& c)
      : slam_(c.initial_pose, initial_covariance((validate_options(c.options), c.options)), process_noise(c.options),
              slam_options(c.options)) {}

  std::string name() const override { return "polynomial"; }

  void predict(const Odometry& u) override { slam_.predict(u); }

  void update_scan(const RangeScan& scan, const mapping::OccupancyGrid& /*own_map*/) override {
    const std::size_t n = std::min(scan.angles.size(), scan.ranges.size());
    if (n == 0) return;
    const std::size_t stride = (n + kMaxBeams - 1) / kMaxBeams;
    std::vector<double> angles;
    std::vector<std::optional<double>> ranges;
    for (std::size_t i = 0; i < n; i += stride) {
      angles.push_back(scan.angles[i]);
      ranges.push_back(scan.ranges[i]);
    }
    slam_.update(angles, ranges);
  }

  void change_frame(const core::Transform2& new_from_old) override { slam_.change_frame(new_from_old); }

  core::Pose2 pose() const override { return slam_.pose(); }
  Eigen::Matrix3d covariance() const override { return slam_.pose_covariance(); }

  std::vector<std::pair<std::string, double>> counters() const override {
    const auto& c = slam_.counters();
    return {{"polynomials", double(slam_.map().landmarks.size())},
            {"clusters", double(slam_.map().clusters.size())},
            {"polynomial_updates", double(c.updates)},
            {"rejected_readings", double(c.rejected_readings)},
            {"polynomials_created", double(c.polynomials_created)},
            {"refits", double(c.refits)},
            {"merges", double(c.merges)},
            {"diverged_steps", double(c.diverged_steps)}};
  }

 private:
  static PolynomialSlamOptions slam_options(const LocalizerOptions& o) {
    PolynomialSlamOptions p;
    p.range_noise = o.scan_range_noise;
    return p;
  }

  PolynomialSlam slam_;
};

}  // namespace

std::unique_ptr<Localizer> make_polynomial_localizer(const LocalizerContext& c) {
  return std::make_unique<PolynomialLocalizer>(c);
}

}  // namespace fleetmap::localization

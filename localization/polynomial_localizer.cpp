#include "localization/polynomial_localizer.h"

#include <algorithm>
#include <optional>

#include "localization/ekf_models.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

namespace {

// D'Alfonso et al. uses five distance sensors; a 360-beam laser gives far more readings than the filter
// needs (each is one O(n^2) update), so the registered localizer thins a scan to this many evenly
// spaced beams.
constexpr std::size_t kMaxBeams = 36;

}  // namespace

PolynomialLocalizer::PolynomialLocalizer(const core::Pose2& start, const Eigen::Matrix3d& initial_covariance,
                                         const Eigen::Matrix3d& process_noise, const PolynomialSlamOptions& options,
                                         std::size_t max_beams)
    : slam_(start, initial_covariance, process_noise, options), max_beams_(max_beams) {}

void PolynomialLocalizer::update_scan(const RangeScan& scan, const mapping::OccupancyGrid& /*own_map*/) {
  const std::size_t n = std::min(scan.angles.size(), scan.ranges.size());
  if (n == 0) return;
  const std::size_t stride = max_beams_ == 0 ? 1 : (n + max_beams_ - 1) / max_beams_;
  if (stride == 1 && n == scan.angles.size() && n == scan.ranges.size()) {
    slam_.update(scan.angles, scan.ranges);
    return;
  }
  std::vector<double> angles;
  std::vector<std::optional<double>> ranges;
  for (std::size_t i = 0; i < n; i += stride) {
    angles.push_back(scan.angles[i]);
    ranges.push_back(scan.ranges[i]);
  }
  slam_.update(angles, ranges);
}

std::vector<std::pair<std::string, double>> PolynomialLocalizer::counters() const {
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

std::unique_ptr<Localizer> make_polynomial_localizer(const LocalizerContext& c) {
  validate_options(c.options);
  return std::make_unique<PolynomialLocalizer>(c.initial_pose, initial_covariance(c.options), process_noise(c.options),
                                               polynomial_slam_options(c.params, c.options.scan_range_noise), kMaxBeams);
}

}  // namespace fleetmap::localization

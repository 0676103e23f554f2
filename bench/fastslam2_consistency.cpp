// FastSLAM 2.0's consistency (Montemerlo et al. 2003; Bailey, Nieto & Nebot 2006): the mean NEES
// over Monte Carlo runs of two laps of the localization tests' ring world (48 landmarks, a 12 m
// sensor, noise drawn exactly per the filters' model, the start known), before the loop closes
// (steps 1-90) and after (steps 101-200), beside `ekf-slam` on the same readings. Not a Google
// Benchmark: it prints markdown. Results: bench/README.md, "## FastSLAM 2.0 consistency".
//   fleetmap_bench_fastslam2_consistency [runs=20] [particles: 50 200 1000 ...] [resample_threshold=0.75]
#include <Eigen/Core>

#include <cstdlib>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "localization/ekf_models.h"
#include "localization/fastslam2.h"
#include "localization/localizer.h"
#include "localization/metrics.h"
#include "tests/localization/localization_sim.h"

namespace fleetmap::localization {
namespace {

constexpr int kSteps = 200;

struct Windows {
  double before = 0.0, after = 0.0, error_before = 0.0, error_after = 0.0;
  long resamples = 0;
};

Eigen::Vector3d error_of(const core::Pose2& estimate, const core::Pose2& truth) {
  return {estimate.x - truth.x, estimate.y - truth.y, core::normalize_angle(estimate.theta - truth.theta)};
}

// Mean NEES and position error over the runs in the two windows, for fastslam2 (particles > 0) or ekf-slam.
Windows measure(int runs, int particles, double threshold) {
  LocalizerOptions o;
  o.process_noise_xy = 0.03;
  o.process_noise_theta = 0.005;
  o.range_noise = 0.1;
  o.bearing_noise = 0.02;
  o.initial_xy = o.initial_theta = 0.0;
  testing::SimWorld world = testing::ring_world(24);
  world.sensor_range = 12.0;
  Windows w;
  for (int run = 0; run < runs; ++run) {
    FastSlam2Options f;
    f.particles = std::max(1, particles);
    f.resample_threshold = threshold;
    f.process_noise = process_noise(o);
    f.measurement_noise = measurement_noise(o);
    FastSlam2 fastslam(testing::loop_start(), initial_covariance(o), f, 1000 + std::uint64_t(run));
    LocalizerContext c;
    c.initial_pose = testing::loop_start();
    c.options = o;
    auto ekf = make_localizer("ekf-slam", c);
    core::Random rng = core::Random(77).fork(std::uint64_t(run));
    core::Pose2 truth = testing::loop_start();
    for (int k = 1; k <= kSteps; ++k) {
      const Odometry u = testing::command(k - 1, truth);
      truth = testing::move(truth, u, o, rng);
      const auto readings = testing::read_landmarks(truth, world, o, rng);
      core::Pose2 estimate;
      Eigen::Matrix3d covariance;
      if (particles > 0) {
        fastslam.predict(u);
        fastslam.update(readings);
        estimate = fastslam.pose();
        covariance = fastslam.pose_covariance();
      } else {
        ekf->predict(u);
        ekf->update_landmarks(readings);
        estimate = ekf->pose();
        covariance = ekf->covariance();
      }
      const Eigen::Vector3d e = error_of(estimate, truth);
      const double n = nees(e, covariance).value_or(0.0);
      if (k <= 90) {
        w.before += n / (90.0 * runs);
        w.error_before += e.head<2>().norm() / (90.0 * runs);
      } else if (k > 100) {
        w.after += n / (100.0 * runs);
        w.error_after += e.head<2>().norm() / (100.0 * runs);
      }
    }
    w.resamples += fastslam.resamples();
  }
  return w;
}

}  // namespace
}  // namespace fleetmap::localization

int main(int argc, char** argv) {
  using namespace fleetmap::localization;
  const int runs = argc > 1 ? std::atoi(argv[1]) : 20;
  std::vector<int> particles;
  double threshold = 0.75;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.find('.') != std::string::npos) {
      threshold = std::atof(a.c_str());
    } else {
      particles.push_back(std::atoi(a.c_str()));
    }
  }
  if (particles.empty()) particles = {50, 200, 1000};
  if (runs < 1 || !(threshold > 0.0 && threshold <= 1.0)) {
    fmt::print(stderr, "fleetmap_bench_fastslam2_consistency: runs must be >= 1 and the threshold in (0, 1]\n");
    return 2;
  }
  fmt::print("Mean NEES (3 when consistent) and position error over {} runs; loop closes at steps 91-100; "
             "resampling below N_eff = {} N\n\n",
             runs, threshold);
  fmt::print("| filter | NEES steps 1-90 | NEES steps 101-200 | error 1-90, m | error 101-200, m | resamplings per run |\n");
  fmt::print("|---|---|---|---|---|---|\n");
  const Windows e = measure(runs, 0, threshold);
  fmt::print("| ekf-slam | {:.2f} | {:.2f} | {:.3f} | {:.3f} | - |\n", e.before, e.after, e.error_before, e.error_after);
  for (int p : particles) {
    const Windows w = measure(runs, p, threshold);
    fmt::print("| fastslam2, {} particles | {:.1f} | {:.1f} | {:.3f} | {:.3f} | {:.0f} |\n", p, w.before, w.after,
               w.error_before, w.error_after, double(w.resamples) / runs);
  }
  return 0;
}

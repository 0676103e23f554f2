#include "localization/localizer.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

core::Registry<LocalizerFactory>& localizer_registry() {
  static core::Registry<LocalizerFactory> registry("localization");
  static const bool built_in = [] {
    auto& r = registry;
    r.add("ideal", "the simulator's true pose (an upper bound to compare with)", make_ideal_localizer);
    r.add("odometry", "dead reckoning from the noisy motion, never corrected", make_odometry_localizer);
    r.add("ekf", "EKF on the pose with range-bearing readings of known landmarks (by id, or nearest neighbour gated)",
          make_ekf_localizer);
    r.add("ekf-slam",
          "EKF-SLAM: pose and point landmarks learnt as they are seen (augmentation as D'Alfonso et al., "
          "eq. (4)-(5))",
          make_ekf_slam_localizer);
    r.add("polynomial",
          "polynomial EKF-SLAM (D'Alfonso et al.): walls as polynomials learnt from the range scan, c0 "
          "coefficients in the state",
          make_polynomial_localizer);
    r.add("scan-matching",
          "ML incremental mapping: each scan aligned to the robot's own grid replaces the odometry step (León et al. "
          "2009, sec. II.A)",
          make_scan_matching_localizer);
    r.add("mcl",
          "Monte Carlo localization on the known map; collaborative with robot_detections, lost_robots start uniform "
          "(León et al., sec. IV)",
          make_mcl_localizer);
    r.add("rbpf",
          "Rao-Blackwellized particle filter, a grid per particle, scan-matching proposal (León et al., sec. II.C; "
          "Grisetti et al. 2005)",
          make_rbpf_localizer);
    r.add("fastslam-grid",
          "grid-based FastSLAM: particles drawn from the raw motion model, each weighted by its scan on its own grid, "
          "no scan-matching proposal (León et al., sec. II.B)",
          make_grid_fastslam_localizer);
    r.add("graph-slam",
          "graph SLAM: scans matched to submaps (correlative search + least squares), loop closures by branch and "
          "bound, pose graph with a robust loss on Ceres (Hess et al. 2016)",
          make_graph_slam_localizer);
    r.add("fastslam2",
          "FastSLAM 2.0: particles over the path, an EKF per landmark in each, proposal including the readings "
          "(Montemerlo et al. 2003)",
          make_fastslam2_localizer);
    return true;
  }();
  (void)built_in;
  return registry;
}

void register_localizer(std::string name, std::string help, LocalizerFactory make) {
  localizer_registry().add(std::move(name), std::move(help), std::move(make));
}

std::vector<std::string> localizer_names() { return localizer_registry().names(); }

std::string localizer_help() { return localizer_registry().help(); }

std::unique_ptr<Localizer> make_localizer(const std::string& name, const LocalizerContext& context) {
  return localizer_registry().get(name).make(context);
}

}  // namespace fleetmap::localization

#include "localization/localizer.h"
#include "localization/localizers.h"
#include "localization/polynomial_slam.h"

namespace fleetmap::localization {

core::Registry<LocalizerFactory>& localizer_registry() {
  static core::Registry<LocalizerFactory> registry("localization");
  static const bool built_in = [] {
    auto& r = registry;
    using core::ParamSpec;
    const auto particles = [](double n, double most, const char* doc) {
      return ParamSpec::number("particles", n, {1, most, true}, "", doc);
    };
    // A reading farther than this (squared Mahalanobis distance) from every landmark is a new one;
    // chi2(2) at 1 - 1e-6, so a true reading starts a duplicate once in a million.
    const auto new_landmark_gate = ParamSpec::number(
        "new_landmark_gate", 27.63, {0, 1e6}, "",
        "unknown identities: a reading farther than this (squared Mahalanobis) from every landmark starts a new one; "
        "between association_gate and this it is rejected");
    r.add("ideal", "the simulator's true pose (an upper bound to compare with)", make_ideal_localizer);
    r.add("odometry", "dead reckoning from the noisy motion, never corrected", make_odometry_localizer);
    r.add("ekf", "EKF on the pose with range-bearing readings of known landmarks (by id, or nearest neighbour gated)",
          make_ekf_localizer);
    r.add("ekf-slam",
          "EKF-SLAM: pose and point landmarks learnt as they are seen (augmentation as D'Alfonso et al., "
          "eq. (4)-(5))",
          make_ekf_slam_localizer,
          {new_landmark_gate,
           ParamSpec::number("forget_after_steps", 0, {0, 1e9, true}, "",
                             "a landmark not observed for more steps than this leaves the state (0: never)")});
    r.add("polynomial",
          "polynomial EKF-SLAM (D'Alfonso et al.): walls as polynomials learnt from the range scan, c0 "
          "coefficients in the state",
          make_polynomial_localizer, polynomial_slam_params());
    r.add("scan-matching",
          "ML incremental mapping: each scan aligned to the robot's own grid replaces the odometry step (León et al. "
          "2009, sec. II.A)",
          make_scan_matching_localizer);
    r.add("mcl",
          "Monte Carlo localization on the known map; collaborative with robot_detections, lost_robots start uniform "
          "(León et al., sec. IV)",
          make_mcl_localizer, {particles(2000, 1e6, "particles per robot")});
    r.add("rbpf",
          "Rao-Blackwellized particle filter, a grid per particle, scan-matching proposal (León et al., sec. II.C; "
          "Grisetti et al. 2005)",
          make_rbpf_localizer,
          {particles(30, 1e4, "particles per robot, each with its own grid"),
           ParamSpec::flag("sample_motion", true,
                           "each particle's search starts from its odometry step drawn with the process noise (false: "
                           "from the step itself, so one particle is the scan matcher)"),
           // GMapping's linearUpdate / angularUpdate; defaults chosen on the training logs.
           ParamSpec::number("linear_update", 0.3, {0, 1e3}, "m",
                             "a scan is matched and mapped once the odometry moved this far since the last one (0 "
                             "here or in angular_update: every scan)"),
           ParamSpec::number("angular_update", 0.1, {0, 1e3}, "rad",
                             "... or turned this much since the last one")});
    r.add("fastslam-grid",
          "grid-based FastSLAM: particles drawn from the raw motion model, each weighted by its scan on its own grid, "
          "no scan-matching proposal (León et al., sec. II.B)",
          make_grid_fastslam_localizer, {particles(30, 1e4, "particles per robot, each with its own grid")});
    r.add("graph-slam",
          "graph SLAM: scans matched to submaps (correlative search + least squares), loop closures by branch and "
          "bound, pose graph with a robust loss on Ceres (Hess et al. 2016)",
          make_graph_slam_localizer,
          // Defaults: GraphSlamOptions' (graph_slam.h), chosen on the training logs.
          {ParamSpec::number("max_range", 30, {0.1, 1e3}, "m", "beams are used up to this range"),
           ParamSpec::number("scans_per_submap", 30, {1, 1e4, true}, "",
                             "a new submap starts every this many inserted scans (each takes twice as many)"),
           ParamSpec::number("insert_min_distance", 0.2, {0, 1e3}, "m",
                             "a scan joins the submaps when the robot moved this far since the last one"),
           ParamSpec::number("max_constraint_distance", 10, {0, 1e6}, "m",
                             "loop closures are searched between scans and submaps at most this far apart"),
           ParamSpec::number("loop_sampling_ratio", 0.1, {0, 1}, "", "share of (scan, submap) pairs searched for closures"),
           ParamSpec::number("loop_rival_errors", 2, {0, 1e3}, "",
                             "a closure is refused unless it beats a rival match elsewhere by this many standard errors"),
           ParamSpec::number("huber_scale", 10, {1e-3, 1e6}, "",
                             "loop closures' robust loss scale, in standard deviations")});
    r.add("fastslam2",
          "FastSLAM 2.0: particles over the path, an EKF per landmark in each, proposal including the readings "
          "(Montemerlo et al. 2003)",
          make_fastslam2_localizer,
          {particles(100, 1e4, "particles per robot (Bailey's FastSLAM 2.0 implementation uses 100)"),
           new_landmark_gate});
    return true;
  }();
  (void)built_in;
  return registry;
}

void register_localizer(std::string name, std::string help, LocalizerFactory make, std::vector<core::ParamSpec> params) {
  localizer_registry().add(std::move(name), std::move(help), std::move(make), std::move(params));
}

std::vector<std::string> localizer_names() { return localizer_registry().names(); }

std::string localizer_help() { return localizer_registry().help(); }

core::Params localizer_options(const std::string& name, const core::Settings& settings) {
  return localizer_registry().configure(name, settings);
}

std::unique_ptr<Localizer> make_localizer(const std::string& name, const LocalizerContext& context) {
  const auto& entry = localizer_registry().get(name);
  if (context.params.specs().empty()) {
    LocalizerContext c = context;
    c.params = localizer_registry().params(name);
    return entry.make(c);
  }
  if (!(context.params.owner() == localizer_registry().params(name).owner())) {
    throw InputError("localization '" + name + "': given the parameters of " + context.params.owner());
  }
  return entry.make(context);
}

}  // namespace fleetmap::localization

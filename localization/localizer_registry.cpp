#include <functional>

#include "core/error.h"
#include "localization/localizer.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

namespace {

struct Entry {
  std::string name;
  std::string help;
  std::function<std::unique_ptr<Localizer>(const LocalizerContext&)> make;
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> kEntries = {
      {"ideal", "the simulator's true pose (an upper bound to compare with)", make_ideal_localizer},
      {"odometry", "dead reckoning from the noisy motion, never corrected", make_odometry_localizer},
      {"ekf", "EKF on the pose with range-bearing readings of known landmarks (by id, or nearest neighbour gated)",
       make_ekf_localizer},
      {"ekf-slam", "EKF-SLAM: pose and point landmarks learnt as they are seen (seed 000 eq. (4)-(5))",
       make_ekf_slam_localizer},
      {"polynomial", "seed 000's polynomial EKF-SLAM: walls as polynomials learnt from the range scan, c0 coefficients in the state",
       make_polynomial_localizer},
      {"scan-matching", "ML incremental mapping: each scan aligned to the robot's own grid replaces the odometry step (seed 002 §II.A)",
       make_scan_matching_localizer},
      {"mcl", "Monte Carlo localization on the known map; collaborative with robot_detections, lost_robots start uniform (seed 002 §IV)",
       make_mcl_localizer},
      {"rbpf", "Rao-Blackwellized particle filter, a grid per particle, scan-matching proposal (seed 002 §II.C)",
       make_rbpf_localizer},
  };
  return kEntries;
}

}  // namespace

std::vector<std::string> localizer_names() {
  std::vector<std::string> names;
  for (const auto& e : registry()) names.push_back(e.name);
  return names;
}

std::string localizer_help() {
  std::string s;
  for (const auto& e : registry()) s += "  " + e.name + ": " + e.help + "\n";
  return s;
}

std::unique_ptr<Localizer> make_localizer(const std::string& name, const LocalizerContext& context) {
  for (const auto& e : registry()) {
    if (e.name == name) return e.make(context);
  }
  std::string names;
  for (const auto& e : registry()) names += (names.empty() ? "" : ", ") + e.name;
  throw InputError("unknown localization '" + name + "' (valid: " + names + ")");
}

}  // namespace fleetmap::localization

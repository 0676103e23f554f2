// What a run leaves (Simulation's third part): the result of a run, and the observable space it
// left unexplored with the reason each region was left.
#include <algorithm>
#include <bit>

#include <opencv2/imgproc.hpp>

#include "sim/simulation.h"

namespace fleetmap::sim {

std::vector<UnexploredRegion> Simulation::unexplored_regions() const {
  const auto& g = world_.geometry();
  cv::Mat left(g.height(), g.width(), CV_8UC1, cv::Scalar(0));
  for (int idx : observable_.observable)
    if (merged_.log_odds_at(idx) == 0.0f) left.at<std::uint8_t>(idx / g.width(), idx % g.width()) = 1;
  cv::Mat labels;
  const int n = cv::connectedComponents(left, labels, 8, CV_32S);
  std::vector<UnexploredRegion> out(std::size_t(std::max(0, n - 1)));
  std::vector<std::vector<Eigen::Vector2d>> cells(out.size());
  for (int idx : observable_.observable) {
    const int label = labels.at<int>(idx / g.width(), idx % g.width());
    if (label > 0) cells[std::size_t(label - 1)].push_back(g.cell_center(g.cell_of_index(idx)));
  }
  // What the robots' explorers left when they ran out of targets, in the world frame.
  std::vector<exploration::TeamExplorer::LeftFrontier> frontiers;
  for (int i = 0; i < scenario_.robot_count; ++i)
    for (auto f : explorer_.left_frontiers(i)) {
      f.position_m = frame_origin(i) * f.position_m;
      frontiers.push_back(std::move(f));
    }
  const bool finished = all_finished();
  for (std::size_t k = 0; k < out.size(); ++k) {
    auto& r = out[k];
    r.area_m2 = double(cells[k].size()) * observable_.cell_area_m2;
    for (const auto& c : cells[k]) r.centre_m += c;
    r.centre_m /= double(std::max<std::size_t>(1, cells[k].size()));
    if (!finished) {
      r.reason = "step limit: the run ended with targets left";
      continue;
    }
    // The nearest frontier piece the explorers left, if the region is within its reach: a piece is
    // represented by one cell and reaches piece_radius_m from it (on cells of the explorer's size).
    const double cell = std::max(g.resolution(), scenario_.exploration.planning_resolution_m);
    double best = scenario_.exploration.targets.piece_radius_m + 2.0 * cell;
    r.reason = "no frontier on the robots' maps: too small to be one, or closed off by cells mapped as walls";
    for (const auto& f : frontiers)
      for (const auto& c : cells[k])
        if ((c - f.position_m).norm() < best) {
          best = (c - f.position_m).norm();
          r.reason = f.reason;
        }
  }
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.area_m2 > b.area_m2; });
  return out;
}

RunResult Simulation::result() const {
  RunResult r;
  r.scenario = scenario_;
  r.steps = step_;
  r.finished = all_finished();
  r.coverage = coverage_;
  for (std::size_t k = 0; k < coverage_.size(); ++k) {
    if (!r.steps_to_95 && coverage_[k] >= 0.95) r.steps_to_95 = int(k);
    if (!r.steps_to_99 && coverage_[k] >= 0.99) r.steps_to_99 = int(k);
  }
  std::int64_t sensed = 0, shared = 0;
  for (int idx : observable_.observable) {
    const int robots = std::popcount(sensed_by_[std::size_t(idx)]);
    sensed += robots > 0;
    shared += robots > 1;
  }
  r.redundancy = sensed ? double(shared) / double(sensed) : 0.0;
  r.bytes_sent = bytes_sent_;
  r.meetings = meetings_;
  r.space.observable_cells = std::int64_t(observable_.observable.size());
  r.space.unreachable_cells = std::int64_t(observable_.unreachable.size());
  r.space.pose_cells = observable_.poses;
  r.space.free_cells = observable_.free_cells;
  r.space.largest_region_pose_cells = observable_.largest_region_poses;
  r.space.start_regions = observable_.start_regions;
  r.space.cell_area_m2 = observable_.cell_area_m2;
  for (int idx : observable_.unreachable)
    if (merged_.log_odds_at(idx) != 0.0f) r.space.seen_unreachable.push_back(idx);
  r.unexplored = unexplored_regions();
  for (const Robot& robot : robots_) r.robots.push_back(robot.track);
  for (int i = 0; i < scenario_.robot_count; ++i) r.robot_frames.push_back(frame_origin(i));
  r.merges = merges_;
  for (std::size_t i = 0; i < r.robots.size(); ++i) r.robots[i].localizer_counters = robots_[i].localizer->counters();
  r.events = events_;
  r.landmarks = world_.landmarks();
  r.merged = merged_;
  for (const Robot& robot : robots_) r.robot_maps.push_back(robot.map);
  r.map_quality = mapping::map_quality(merged_, world_.truth());
  for (int i = 0; i < scenario_.robot_count; ++i) {
    r.robot_map_quality.push_back(
        mapping::map_quality(robots_[std::size_t(i)].map, world_.truth(), r.robot_frames[std::size_t(i)]));
  }
  r.exploration = explorer_.stats();
  r.timing = timing_;
  return r;
}

}  // namespace fleetmap::sim

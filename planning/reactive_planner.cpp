// The naive baseline: the map-alignment paper, §VII's reactive steering, on an occupancy grid.
//
// The paper's robot computes the steering angle toward the target, and at each control step looks
// for landmarks in the semicircle of radius r_max in front of it. A landmark whose bearing lies
// within (-theta, theta) of the heading becomes a sub-target and the robot turns by theta away from
// it (left when it lies to the right, right otherwise); once the robot has passed the sub-target it
// steers toward the target again. Here the landmarks are the cells the robot's centre may not enter
// (FreeSpace::valid is false), and one turn direction is kept until the way to the goal is clear,
// so the robot does not swing back and forth in front of a wall.
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <string>

#include "core/format.h"
#include "core/angle.h"
#include "core/error.h"
#include "planning/planners.h"

namespace fleetmap::planning {

namespace {

using core::normalize_angle;

Eigen::Vector2d direction(double angle) { return {std::cos(angle), std::sin(angle)}; }

double bearing(const Eigen::Vector2d& from, double heading, const Eigen::Vector2d& to) {
  const Eigen::Vector2d d = to - from;
  return normalize_angle(std::atan2(d.y(), d.x()) - heading);
}

// The nearest invalid cell centre within `look_ahead` of `p` whose bearing from `heading` lies in
// (-cone, cone): the map-alignment paper's check for a landmark in the robot's path. Callers pass the distance to
// the goal when it is shorter, since what lies beyond the goal hinders nothing.
std::optional<Eigen::Vector2d> landmark_ahead(const FreeSpace& space, const Eigen::Vector2d& p, double heading,
                                              double look_ahead, double cone) {
  const GridGeometry& g = space.geometry();
  const Cell centre = g.world_to_cell_unbounded(p);
  const int reach = static_cast<int>(std::ceil(look_ahead / g.resolution())) + 1;
  std::optional<Eigen::Vector2d> nearest;
  double nearest_distance = look_ahead;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const Cell c{centre.x + dx, centre.y + dy};
      if (!g.contains(c) || space.valid(c)) continue;
      const Eigen::Vector2d q = g.cell_center(c);
      const double distance = (q - p).norm();
      if (distance > nearest_distance || std::abs(bearing(p, heading, q)) >= cone) continue;
      nearest = q;
      nearest_distance = distance;
    }
  }
  return nearest;
}

class ReactivePlanner final : public Planner {
 public:
  explicit ReactivePlanner(const core::Params& p)
      : turn_angle_deg_(p.number("turn_angle_deg")),
        look_ahead_m_(p.number("look_ahead")),
        step_m_(p.number("step")),
        max_travel_factor_(p.number("max_travel_factor")) {}
  std::string name() const override { return "reactive"; }

 protected:
  Search search(const FreeSpace& space, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                const PlannerOptions& options, Clock::time_point deadline) override {
    const GridGeometry& g = space.geometry();
    const double step = step_m_ > 0.0 ? step_m_ : 0.5 * g.resolution();
    const double theta = core::deg2rad(turn_angle_deg_);
    const double max_travel = max_travel_factor_ * (g.width_m() + g.height_m());
    const int max_turns = static_cast<int>(std::ceil(2.0 * std::numbers::pi / theta));

    Search s;
    Eigen::Vector2d p = start;
    std::vector<Eigen::Vector2d> points{start};
    std::vector<double> headings;  // the heading of each step, to merge collinear steps
    double heading = 0.0;
    double travelled = 0.0;
    int turn_sign = 0;  // +1 left, -1 right, 0 not avoiding anything
    bool avoiding = false;  // a sub-target is set
    Eigen::Vector2d sub_target = Eigen::Vector2d::Zero();

    while (true) {
      const Eigen::Vector2d to_goal = goal - p;
      if (to_goal.norm() <= step && space.segment_valid(p, goal)) {
        points.push_back(goal);
        headings.push_back(std::atan2(to_goal.y(), to_goal.x()));
        break;
      }
      if (Clock::now() > deadline) {
        s.detail = fmt::format("reactive: no path within {:.2f} s (travelled {:.1f} m)", options.time_budget_s, travelled);
        return s;
      }
      if (travelled > max_travel) {
        s.detail = fmt::format("reactive: gave up after travelling {:.1f} m without reaching the goal", travelled);
        return s;
      }
      if (!avoiding) heading = std::atan2(to_goal.y(), to_goal.x());

      // check_steering: turn by theta until neither a landmark ahead nor the next step is blocked.
      Eigen::Vector2d next;
      for (int turns = 0;; ++turns) {
        std::optional<Eigen::Vector2d> blocker =
            landmark_ahead(space, p, heading, std::min(look_ahead_m_, to_goal.norm()), theta);
        next = p + std::min(step, to_goal.norm()) * direction(heading);
        if (!blocker) {
          if (const auto hit = space.first_invalid_distance(p, next)) {
            // Blocked by a cell beside the cone: steer away from where the step fails.
            blocker = p + (*hit + 1e-6) * direction(heading);
          }
        }
        if (!blocker) {
          if (turns == 0 && !avoiding) turn_sign = 0;  // the way to the goal is clear
          break;
        }
        if (turns >= max_turns) {
          s.detail = "reactive: boxed in at " + core::format_point(p);
          return s;
        }
        if (turn_sign == 0) turn_sign = bearing(p, heading, *blocker) < 0.0 ? +1 : -1;
        heading = normalize_angle(heading + turn_sign * theta);
        sub_target = *blocker;
        avoiding = true;
      }

      travelled += (next - p).norm();
      p = next;
      points.push_back(p);
      headings.push_back(heading);
      // The robot has passed its sub-target once it lies beside or behind it, or out of range.
      if (avoiding &&
          (std::abs(bearing(p, heading, sub_target)) >= 0.5 * std::numbers::pi || (sub_target - p).norm() > look_ahead_m_)) {
        avoiding = false;
      }
    }

    s.found = true;
    s.first_solution = Clock::now();
    if (!options.simplify) {
      s.path = std::move(points);
      return s;
    }
    // Consecutive steps with one heading (up to rounding) are one straight segment; the merged
    // segment is checked again, so rounding cannot make it clip a cell the steps avoided.
    s.path.push_back(points.front());
    for (std::size_t i = 1; i + 1 < points.size(); ++i) {
      const bool straight = std::abs(normalize_angle(headings[i] - headings[i - 1])) < 1e-9;
      if (!straight || !space.segment_valid(s.path.back(), points[i + 1])) s.path.push_back(points[i]);
    }
    s.path.push_back(points.back());
    return s;
  }
 private:
  double turn_angle_deg_, look_ahead_m_, step_m_, max_travel_factor_;
};

}  // namespace

std::unique_ptr<Planner> make_reactive_planner(const core::Params& params) {
  return std::make_unique<ReactivePlanner>(params);
}

}  // namespace fleetmap::planning

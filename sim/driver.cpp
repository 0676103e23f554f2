#include "sim/driver.h"

#include <algorithm>
#include <cmath>

#include "core/angle.h"

namespace fleetmap::sim {

std::optional<Command> CommandScript::next(const DriverView& view) {
  if (view.step < 0 || std::size_t(view.step) >= commands_.size()) return std::nullopt;
  return commands_[std::size_t(view.step)];
}

WaypointDriver::WaypointDriver(WaypointDrive drive, double period_s)
    : drive_(std::move(drive)), period_s_(period_s), next_(drive_.closed ? 1 : 0) {
  if (drive_.waypoints.empty()) over_ = true;
  if (drive_.closed) next_ %= std::max<std::size_t>(1, drive_.waypoints.size());
}

std::optional<Command> WaypointDriver::next(const DriverView& view) {
  if (over_) return std::nullopt;
  const auto& way = drive_.waypoints;
  // One waypoint passed per step at most; a closed loop counts a lap each time it is back on its
  // first waypoint.
  if ((way[next_] - view.truth.position()).norm() < drive_.reached_m) {
    if (!drive_.closed && next_ + 1 == way.size()) {
      lap_ends_.push_back(view.step);
      over_ = true;
      return std::nullopt;
    }
    if (drive_.closed && next_ == 0) {
      lap_ends_.push_back(view.step);
      if (++laps_ == drive_.laps) {
        over_ = true;
        return std::nullopt;
      }
    }
    next_ = (next_ + 1) % way.size();
  }
  const Eigen::Vector2d d = way[next_] - view.truth.position();
  const double error = core::normalize_angle(std::atan2(d.y(), d.x()) - view.truth.theta);
  Command c;
  c.omega = std::clamp(error / period_s_, -drive_.max_turn_rate_rps, drive_.max_turn_rate_rps);
  c.v = std::abs(error) > drive_.turn_in_place_rad ? 0.0 : std::min(drive_.speed_mps, d.norm() / period_s_);
  return c;
}

}  // namespace fleetmap::sim

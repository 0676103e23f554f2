// Map frames of a run (Simulation's second part): two robots in different frames that can talk ask
// the scenario's merging::MapAligner (rendezvous, overlap, landmarks, or a registered one) for the
// transform between their frames; on success the sender's whole group moves into the receiver's
// frame.
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "core/angle.h"
#include "merging/map_aligner.h"
#include "sim/simulation.h"

namespace fleetmap::sim {

void Simulation::try_merge(int i, int j) {
  // The robot in the lower-numbered frame receives: the other's group adopts its frame.
  const int receiver = robots_[std::size_t(i)].frame < robots_[std::size_t(j)].frame ? i : j;
  const int sender = receiver == i ? j : i;
  MergeRecord record;
  record.step = step_;
  record.receiver = receiver;
  record.sender = sender;
  const Robot &r = robots_[std::size_t(receiver)], &s = robots_[std::size_t(sender)];
  if (aligner_->costly()) {
    int& last = last_attempt_[std::size_t(receiver)][std::size_t(sender)];
    if (step_ - last < scenario_.merge_attempt_every) return;
    last = step_;
  }
  merging::AlignmentRequest request;
  request.receiver_map = &r.map;
  request.sender_map = &s.map;
  request.receiver_pose = r.localizer->pose();
  request.sender_pose = s.localizer->pose();
  const Detection* rs = detection(receiver, sender);
  const Detection* sr = detection(sender, receiver);
  if (rs != nullptr && sr != nullptr) request.detection = merging::MutualObservation{rs->range, rs->bearing, sr->range, sr->bearing};
  request.receiver_landmarks = r.localizer->landmark_estimates();
  request.sender_landmarks = s.localizer->landmark_estimates();
  request.seed = scenario_.seed;
  if (aligner_->sends_map()) bytes_sent_ += exchange_.send_without_fusing(sender, receiver);
  const merging::FrameAlignment m = aligner_->align(request);
  if (!m.attempted) return;
  bytes_sent_ += m.bytes_sent;
  record.method = m.method.empty() ? scenario_.merging : m.method;
  record.confidence = m.confidence;
  if (!m.merged) {
    record.reason = m.reason;
    if (setup_.on_merge_attempt) setup_.on_merge_attempt(record, r.map, s.map);
    merges_.push_back(record);
    return;
  }
  const core::Transform2* t = &m.sender_to_receiver;  // sender's frame (metres) into the receiver's
  // Against the truth: where the sender's frame really lies in the receiver's.
  const core::Transform2 truth = frame_origin(receiver).inverse() * frame_origin(sender);
  const Eigen::Vector2d at = robots_[std::size_t(sender)].localizer->pose().position();
  record.merged = true;
  record.rotation_error_deg = core::rad2deg(std::abs(core::normalize_angle(t->rotation() - truth.rotation())));
  record.position_error_m = (t->apply(at) - truth.apply(at)).norm();
  if (setup_.on_merge_attempt) setup_.on_merge_attempt(record, r.map, s.map);
  merges_.push_back(record);
  events_.push_back({step_, "merge", receiver, sender,
                     fmt::format("{} merge, confidence {:.2f}: rotation error {:.2f} deg, position error {:.3f} m",
                                 record.method, record.confidence, record.rotation_error_deg, record.position_error_m)});
  adopt_frame(robots_[std::size_t(sender)].frame, robots_[std::size_t(receiver)].frame, *t);
}

void Simulation::adopt_frame(int from, int to, const core::Transform2& t) {
  const core::GridGeometry& target = frame_geometry_[std::size_t(to)];
  const core::Transform2 back = t.inverse();
  for (int k = 0; k < scenario_.robot_count; ++k) {
    Robot& robot = robots_[std::size_t(k)];
    if (robot.frame != from) continue;
    // Resample the map into the new frame: each target cell takes the source cell under its centre.
    const mapping::OccupancyGrid& old = robot.map;
    mapping::OccupancyGrid moved(target, old.options());
    Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
    for (const auto& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(old.width(), 0), Eigen::Vector2d(0, old.height()),
                               Eigen::Vector2d(old.width(), old.height())}) {
      const Eigen::Vector2d g = target.world_to_grid(t.apply(old.geometry().grid_to_world(corner)));
      lo = lo.cwiseMin(g);
      hi = hi.cwiseMax(g);
    }
    const int x0 = std::max(0, int(std::floor(lo.x()))), x1 = std::min(target.width(), int(std::ceil(hi.x())) + 1);
    const int y0 = std::max(0, int(std::floor(lo.y()))), y1 = std::min(target.height(), int(std::ceil(hi.y())) + 1);
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const auto source = old.geometry().world_to_cell(back.apply(target.cell_center({x, y})));
        if (!source) continue;
        const float l = old.log_odds(*source);
        if (l != 0.0f) moved.set_log_odds({x, y}, l);
      }
    }
    robot.map = std::move(moved);
    robot.localizer->change_frame(t);
    exchange_.reset(k, target);
    explorer_.reset_robot(k);
    robot.frame = to;
  }
}

}  // namespace fleetmap::sim

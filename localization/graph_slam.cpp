#include "localization/graph_slam.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <numbers>

#include "core/angle.h"

namespace fleetmap::localization {

namespace {

// The angle in [-pi, pi), for Ceres's jets as for doubles.
template <typename T>
T wrap(const T& a) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  return a - kTwoPi * ceres::floor((a + std::numbers::pi) / kTwoPi);
}

// The error of `relative`, the pose of b in a's frame: weighted (x, y, theta) of inv(a) * b - relative
// (Hess et al. 2016, eq. (5)).
struct RelativePoseCost {
  RelativePoseCost(const core::Pose2& relative, double translation_weight, double rotation_weight)
      : z_(relative), tw_(translation_weight), rw_(rotation_weight) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residual) const {
    const T c = ceres::cos(a[2]), s = ceres::sin(a[2]);
    const T dx = b[0] - a[0], dy = b[1] - a[1];
    residual[0] = tw_ * (c * dx + s * dy - z_.x);
    residual[1] = tw_ * (-s * dx + c * dy - z_.y);
    residual[2] = rw_ * wrap(T(b[2] - a[2] - z_.theta));
    return true;
  }
  core::Pose2 z_;
  double tw_, rw_;
};

struct Submap {
  core::Pose2 local;   // the grid frame's origin in the local (odometry + matching) frame: a translation
  core::Pose2 global;  // the same in the map frame (optimized)
  SubmapGrid grid;
  int inserted = 0;
  bool finished = false;
  std::unique_ptr<PrecomputedGrids> precomputed;  // once finished
  double sampler_pulses = 0.0, sampler_samples = 0.0;
  // The nodes matched against or inserted into it lie in this range (of consecutive scans).
  std::size_t first_node = 0, last_node = 0;
  bool has_nodes = false;
};

struct Node {
  core::Pose2 local, global;
  PointCloud loop_points;  // sensor frame, for the loop-closure search
};

}  // namespace

struct GraphSlam::State {
  GraphSlamOptions o;
  core::Pose2 initial;
  std::deque<Submap> submaps;  // stable references while growing
  std::vector<std::size_t> active;  // at most two, oldest first
  std::vector<Node> nodes;
  std::vector<GraphConstraint> constraints;
  std::size_t loops = 0, rejected_loops = 0, optimizations = 0, relocalized = 0;
  std::optional<core::Pose2> last_step;  // the local motion from the last but one node to the last
  double last_dt = 0.0;
  std::optional<core::Pose2> last_inserted;  // local
  // Local frame -> map frame for new nodes and submaps, from the last optimization.
  core::Pose2 local_to_global;

  // Cartographer's fixed-ratio sampler: true when the share of pulses so far is below the ratio.
  bool sample(Submap& m) const {
    ++m.sampler_pulses;
    if (m.sampler_samples / m.sampler_pulses < o.loop_sampling_ratio) {
      ++m.sampler_samples;
      return true;
    }
    return false;
  }

  void search_loop(std::size_t node_index, std::size_t submap_index) {
    Submap& m = submaps[submap_index];
    Node& n = nodes[node_index];
    const core::Pose2 in_submap = m.global.inverse().compose(n.global);  // node in the submap's frame
    if (in_submap.position().norm() > o.max_constraint_distance_m) return;
    if (!sample(m)) return;
    // The grid's frame is the submap's.
    const auto match = branch_and_bound_match(*m.precomputed, n.loop_points, in_submap, o.loop_search);
    if (!match) return;
    const core::Pose2 refined = refine_match(m.grid, n.loop_points, match->pose, match->pose, o.loop_refine);
    // A match is a loop closure only where the window holds no rival, a match farther than
    // loop_rival_radius_m from it, that the scan's points tell apart from it by less than
    // loop_rival_errors standard errors: a corridor or a row of like rooms matches at several
    // places, and the wrong one pulls the graph by metres.
    BranchAndBoundOptions rival_search = o.loop_search;
    rival_search.exclude_center = match->pose.position();
    rival_search.exclude_radius_m = o.loop_rival_radius_m;
    const auto rival = branch_and_bound_match(*m.precomputed, n.loop_points, in_submap, rival_search);
    if (rival && score_advantage(m.grid, n.loop_points, match->pose, rival->pose) < o.loop_rival_errors) {
      ++rejected_loops;
      return;
    }
    constraints.push_back({submap_index, node_index, refined, true, match->score});
    ++loops;
  }

  void finish_submap(std::size_t index) {
    Submap& m = submaps[index];
    m.finished = true;
    m.precomputed = std::make_unique<PrecomputedGrids>(m.grid, o.branch_and_bound_depth);
    m.grid.release_insertion_state();
    // Earlier nodes may have passed here before (the newer ones are searched as they come).
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if (!m.has_nodes || i < m.first_node || i > m.last_node) search_loop(i, index);
    }
  }

  void optimize(int iterations) {
    if (submaps.empty()) return;
    std::vector<std::array<double, 3>> np(nodes.size()), sp(submaps.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) np[i] = {nodes[i].global.x, nodes[i].global.y, nodes[i].global.theta};
    for (std::size_t i = 0; i < submaps.size(); ++i) sp[i] = {submaps[i].global.x, submaps[i].global.y, submaps[i].global.theta};
    ceres::Problem problem;
    for (auto& p : sp) problem.AddParameterBlock(p.data(), 3);
    for (auto& p : np) problem.AddParameterBlock(p.data(), 3);
    problem.SetParameterBlockConstant(sp[0].data());
    for (const auto& c : constraints) {
      const double tw = c.loop ? o.loop_translation_weight : o.intra_translation_weight;
      const double rw = c.loop ? o.loop_rotation_weight : o.intra_rotation_weight;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<RelativePoseCost, 3, 3, 3>(new RelativePoseCost(c.relative, tw, rw)),
                               c.loop ? new ceres::HuberLoss(o.huber_scale) : nullptr, sp[c.submap].data(), np[c.node].data());
    }
    // Consecutive nodes keep local SLAM's motion between them.
    for (std::size_t i = 1; i < nodes.size(); ++i) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RelativePoseCost, 3, 3, 3>(new RelativePoseCost(
              nodes[i - 1].local.inverse().compose(nodes[i].local), o.consecutive_translation_weight, o.consecutive_rotation_weight)),
          nullptr, np[i - 1].data(), np[i].data());
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.max_num_iterations = iterations;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    for (std::size_t i = 0; i < nodes.size(); ++i) nodes[i].global = core::Pose2(np[i][0], np[i][1], core::normalize_angle(np[i][2]));
    for (std::size_t i = 0; i < submaps.size(); ++i) submaps[i].global = core::Pose2(sp[i][0], sp[i][1], core::normalize_angle(sp[i][2]));
    // New nodes follow the newest node's correction.
    const Node& last = nodes.back();
    local_to_global = last.global.compose(last.local.inverse());
    ++optimizations;
  }
};

GraphSlam::GraphSlam(const GraphSlamOptions& options, const core::Pose2& initial_pose) : s_(std::make_unique<State>()) {
  s_->o = options;
  s_->initial = initial_pose;
  if ((options.local_search.hit_field || options.local_refine.hit_field) && s_->o.grid.hit_field_sigma_m <= 0.0) {
    const double r = options.grid.resolution_m;
    s_->o.grid.hit_field_sigma_m = std::sqrt(options.range_noise_m * options.range_noise_m + 2.0 * r * r / 12.0);
  }
}
GraphSlam::~GraphSlam() = default;
GraphSlam::GraphSlam(GraphSlam&&) noexcept = default;
GraphSlam& GraphSlam::operator=(GraphSlam&&) noexcept = default;

core::Pose2 GraphSlam::add_scan(const core::Pose2& odometry, const mapping::RangeScan& scan, double dt_s) {
  State& s = *s_;
  const GraphSlamOptions& o = s.o;
  PointCloud points;
  points.reserve(scan.ranges.size());
  // joined[i]: points i - 1 and i are one surface (surface_min_incidence_rad).
  std::vector<bool> joined;
  joined.reserve(scan.ranges.size());
  std::optional<std::size_t> last_beam;
  for (std::size_t b = 0; b < scan.ranges.size(); ++b) {
    const auto& r = scan.ranges[b];
    if (!r || *r < o.min_range_m || *r > o.max_range_m || !std::isfinite(*r)) continue;
    points.emplace_back(*r * std::cos(scan.angles[b]), *r * std::sin(scan.angles[b]));
    bool join = false;
    if (last_beam) {
      const double dphi = std::abs(core::normalize_angle(scan.angles[b] - scan.angles[*last_beam]));
      if (dphi < o.surface_min_incidence_rad) {
        const double previous = *scan.ranges[*last_beam];
        const double gap = previous * std::sin(dphi) / std::sin(o.surface_min_incidence_rad - dphi) + 3.0 * o.range_noise_m;
        join = (points.back() - points[points.size() - 2]).norm() <= gap;
      }
    }
    joined.push_back(join);
    last_beam = b;
  }
  const PointCloud match_points = voxel_filter(points, o.match_voxel_m);
  PointCloud loop_points = voxel_filter(points, o.loop_voxel_m);

  const core::Pose2 prior = s.nodes.empty() ? s.initial : s.nodes.back().local.compose(odometry);
  core::Pose2 local = prior;
  std::optional<std::size_t> matched;
  // The odometry is an outlier when it departs from moving on at the last step's velocity by more
  // than the robot can accelerate in the time (real odometry jumps: slipping wheels, glitching
  // encoders); then the step is taken as unknown between the two predictions.
  std::optional<core::Pose2> steady;
  // The last step's velocity predicts the next scan of a regular stream only: not across a gap
  // in the log (the Intel lab's has gaps of seconds between scans 0.2 s apart).
  const bool regular = dt_s > 0.0 && s.last_dt > 0.0 && dt_s <= 2.0 * s.last_dt;
  if (s.last_step && regular) {
    const double k = dt_s / s.last_dt;
    const core::Pose2 step(k * s.last_step->x, k * s.last_step->y, k * s.last_step->theta);
    const double e = std::hypot(odometry.x - step.x, odometry.y - step.y);
    const double et = std::abs(core::normalize_angle(odometry.theta - step.theta));
    if (e > o.local_search.linear_window_m + o.max_acceleration * dt_s * dt_s ||
        et > o.local_search.angular_window_rad + o.max_angular_acceleration * dt_s * dt_s) {
      steady = step;
    }
  }
  if (!s.active.empty() && s.submaps[s.active.front()].inserted > 0 && !match_points.empty()) {
    matched = s.active.front();
    const Submap& m = s.submaps[*matched];
    // Matching happens in the grid frame, the submap's (its local origin is a translation).
    const core::Pose2 in_grid = m.local.inverse().compose(prior);
    core::Pose2 refined;
    CorrelativeOptions search = o.local_search;
    search.angular_window_rad += 3.0 * o.turn_noise_per_rad * std::abs(odometry.theta);
    search.linear_window_m += 3.0 * o.drive_noise_per_m * std::hypot(odometry.x, odometry.y);
    auto match_near = [&](const core::Pose2& guess) {
      // The exhaustive search only needs to land in the refinement's basin: the sparser points do.
      const MatchResult coarse = correlative_match(m.grid, loop_points, guess, search);
      return refine_match(m.grid, match_points, coarse.pose, guess, o.local_refine);
    };
    // Odometry that did not change at all while the robot was moving is as likely a stale reading
    // (the odometry messages stopped; real logs then catch up with a jump) as a stop: both are
    // matched and the scan decides, the steady motion first. So is a translation that did not
    // change while the robot was driving, whatever the heading did (the wheels' distance stalled
    // while the heading kept coming): even when that stop is beyond what the robot can brake, the
    // steady motion is matched first, with the heading the odometry read.
    const bool still = odometry.x == 0.0 && odometry.y == 0.0 && odometry.theta == 0.0;
    const bool was_moving = s.last_step && (s.last_step->x != 0.0 || s.last_step->y != 0.0 || s.last_step->theta != 0.0);
    const bool stale_translation = !still && odometry.x == 0.0 && odometry.y == 0.0 && s.last_step &&
                                   (s.last_step->x != 0.0 || s.last_step->y != 0.0);
    if (regular && ((!steady && still && was_moving) || stale_translation)) {
      const double k = dt_s / s.last_dt;
      const core::Pose2 step(k * s.last_step->x, k * s.last_step->y, still ? k * s.last_step->theta : odometry.theta);
      const core::Pose2 moving = match_near(m.local.inverse().compose(s.nodes.back().local.compose(step)));
      const core::Pose2 stopped = match_near(in_grid);
      refined = match_score(m.grid, match_points, stopped) > match_score(m.grid, match_points, moving) ? stopped : moving;
    } else if (!steady) {
      refined = match_near(in_grid);
    } else {
      // Branch and bound over the window around the steady prediction that reaches the odometry's.
      // The test that flagged the odometry trusts the scans' timestamps, and a log's may not tell
      // the time between them (a corrected log keeps the scans its SLAM used, some 0.01 s apart
      // after a 30 degree turn): the odometry's own match stands unless the scan prefers the steady
      // one, as for stale odometry above.
      const core::Pose2 center = m.local.inverse().compose(s.nodes.back().local.compose(*steady));
      BranchAndBoundOptions wide;
      wide.linear_window_m = std::hypot(odometry.x - steady->x, odometry.y - steady->y) + o.local_search.linear_window_m;
      wide.angular_window_rad = std::min(std::numbers::pi, std::abs(core::normalize_angle(odometry.theta - steady->theta)) +
                                                               o.local_search.angular_window_rad);
      wide.min_score = 0.0;
      wide.translation_weight = o.relocalize_translation_weight;
      wide.rotation_weight = o.relocalize_rotation_weight;
      const int depth = std::clamp(int(std::ceil(std::log2(wide.linear_window_m / m.grid.resolution()))), 1, o.branch_and_bound_depth);
      const PrecomputedGrids grids(m.grid, depth);
      const auto found = branch_and_bound_match(grids, match_points, center, wide);
      const core::Pose2 start = found ? found->pose : center;
      const core::Pose2 relocalized = refine_match(m.grid, match_points, start, start, o.local_refine);
      const core::Pose2 by_odometry = match_near(in_grid);
      if (match_score(m.grid, match_points, relocalized) > match_score(m.grid, match_points, by_odometry)) {
        refined = relocalized;
        ++s.relocalized;
      } else {
        refined = by_odometry;
      }
    }
    local = m.local.compose(refined);
  }
  if (!s.nodes.empty()) {
    s.last_step = s.nodes.back().local.inverse().compose(local);
    s.last_dt = dt_s;
  }

  const std::size_t index = s.nodes.size();
  Node node;
  node.local = local;
  node.global = s.local_to_global.compose(local);
  node.loop_points = std::move(loop_points);
  s.nodes.push_back(std::move(node));

  std::vector<std::size_t> linked;
  if (matched) linked.push_back(*matched);
  // Insert when the robot moved enough since the last inserted scan.
  const bool moved = !s.last_inserted ||
                     (local.position() - s.last_inserted->position()).norm() >= o.insert_min_distance_m ||
                     std::abs(core::normalize_angle(local.theta - s.last_inserted->theta)) >= o.insert_min_angle_rad;
  std::optional<std::size_t> finished;
  if (moved && !points.empty()) {
    s.last_inserted = local;
    if (s.active.empty() || s.submaps[s.active.back()].inserted >= o.scans_per_submap) {
      Submap m;
      m.grid = SubmapGrid(o.grid);
      m.local = core::Pose2(local.x, local.y, 0.0);
      m.global = s.local_to_global.compose(m.local);
      s.submaps.push_back(std::move(m));
      s.active.push_back(s.submaps.size() - 1);
      if (s.active.size() > 2) s.active.erase(s.active.begin());
    }
    std::vector<Eigen::Vector2d> hits;
    hits.reserve(points.size());
    for (const auto& p : points) hits.push_back(local.transform(p));
    for (const std::size_t a : s.active) {
      Submap& m = s.submaps[a];
      const core::Pose2 to_grid = m.local.inverse();
      std::vector<Eigen::Vector2d> in_grid;
      in_grid.reserve(hits.size());
      for (const auto& h : hits) in_grid.push_back(to_grid.transform(h));
      m.grid.insert(to_grid.transform(local.position()), in_grid);
      for (std::size_t i = 0; i < in_grid.size(); ++i) m.grid.add_surface(joined[i] ? in_grid[i - 1] : in_grid[i], in_grid[i]);
      ++m.inserted;
      if (std::find(linked.begin(), linked.end(), a) == linked.end()) linked.push_back(a);
    }
    if (s.submaps[s.active.front()].inserted >= 2 * o.scans_per_submap) {
      finished = s.active.front();
      s.active.erase(s.active.begin());
    }
  }
  for (const std::size_t a : linked) {
    Submap& m = s.submaps[a];
    if (!m.has_nodes) m.first_node = index, m.has_nodes = true;
    m.last_node = index;
    s.constraints.push_back({a, index, s.submaps[a].local.inverse().compose(local), false, 0.0});
  }
  // Loop closures of this node against the finished submaps it is not part of.
  for (std::size_t m = 0; m < s.submaps.size(); ++m) {
    if (s.submaps[m].finished && std::find(linked.begin(), linked.end(), m) == linked.end()) s.search_loop(index, m);
  }
  if (finished) s.finish_submap(*finished);
  if (o.optimize_every_n_nodes > 0 && (index + 1) % std::size_t(o.optimize_every_n_nodes) == 0) s.optimize(o.iterations);
  return s.nodes.back().global;
}

void GraphSlam::finish() {
  if (!s_->nodes.empty()) s_->optimize(s_->o.final_iterations);
}

std::vector<core::Pose2> GraphSlam::poses() const {
  std::vector<core::Pose2> out;
  out.reserve(s_->nodes.size());
  for (const auto& n : s_->nodes) out.push_back(n.global);
  return out;
}

std::size_t GraphSlam::nodes() const { return s_->nodes.size(); }
std::size_t GraphSlam::submaps() const { return s_->submaps.size(); }
std::size_t GraphSlam::loop_closures() const { return s_->loops; }
std::size_t GraphSlam::optimizations() const { return s_->optimizations; }
std::size_t GraphSlam::rejected_loop_closures() const { return s_->rejected_loops; }
std::size_t GraphSlam::relocalized() const { return s_->relocalized; }
const std::vector<GraphConstraint>& GraphSlam::constraints() const { return s_->constraints; }

void GraphSlam::change_frame(const core::Pose2& new_from_old) {
  for (auto& n : s_->nodes) n.global = new_from_old.compose(n.global);
  for (auto& m : s_->submaps) m.global = new_from_old.compose(m.global);
  s_->local_to_global = new_from_old.compose(s_->local_to_global);
}

}  // namespace fleetmap::localization

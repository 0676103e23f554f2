// One file, over 500 lines, on purpose: a robot's task cycle (check progress, detour, give way,
// retry failed approaches, assign in groups) shares the RobotState bookkeeping and the wave set-up,
// and reads best in one place; the pieces that stand alone (frontiers, targets, waves, strategies,
// tours) have their own files.
#include "exploration/team_explorer.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <unordered_map>

#include "exploration/tour_gain.h"
#include "mapping/grid_traversal.h"

namespace fleetmap::exploration {

namespace {

Cell robot_cell(const ExplorerRobot& r) { return r.map->geometry().world_to_cell_unbounded(r.pose.position()); }

WaveGrid wave_grid(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& passable,
                   const std::vector<std::uint8_t>& factor, std::vector<float>& occupancy, const WaveOptions& options) {
  WaveGrid g{map.width(), map.height(), passable, {}, factor};
  if (options.occupancy_weight > 0.0) {
    occupancy.resize(passable.size());
    for (std::size_t i = 0; i < occupancy.size(); ++i) occupancy[i] = float(mapping::log_odds_to_probability(map.log_odds_at(int(i))));
    g.occupancy = occupancy;
  }
  return g;
}

// A robot standing in inflated space (it cut a corner, or the map just grew a wall beside it) must
// still find a way out: the free cells within the inflation distance of it become passable. A robot
// on a passable cell needs no way out (opening around it would let paths cut round wall ends).
void open_around(const mapping::OccupancyGrid& map, const Cell& c, const TraversabilityOptions& options,
                 std::vector<std::uint8_t>& passable) {
  if (map.contains(c) && passable[std::size_t(map.geometry().index(c))]) return;
  const double reach = (options.robot_radius_m + options.safety_margin_m) / map.resolution() + 1.0;
  const int r = int(std::ceil(reach));
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const Cell n{c.x + dx, c.y + dy};
      if (double(dx * dx + dy * dy) > reach * reach || !map.contains(n)) continue;
      if (map.state(n) == mapping::CellState::Free) passable[std::size_t(map.geometry().index(n))] = 1;
    }
  }
}

// Other robots are obstacles: the cells within two radii plus the margin of each robot that `self`
// can talk to become impassable.
void mark_robots(const mapping::OccupancyGrid& map, const std::vector<ExplorerRobot>& robots, int self,
                 const std::vector<std::vector<char>>& links, const TraversabilityOptions& options,
                 std::vector<std::uint8_t>& passable) {
  const double reach = (2.0 * options.robot_radius_m + options.safety_margin_m) / map.resolution();
  const int r = int(std::ceil(reach));
  const auto mark = [&](const Cell& c) {
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const Cell n{c.x + dx, c.y + dy};
        if (double(dx * dx + dy * dy) <= reach * reach && map.contains(n)) passable[std::size_t(map.geometry().index(n))] = 0;
      }
    }
  };
  for (std::size_t j = 0; j < robots.size(); ++j) {
    if (int(j) == self || (self >= 0 && !links[std::size_t(self)][j])) continue;
    mark(robot_cell(robots[j]));
  }
}

// The robots `robot` just bumped into: the cells closer to where they stand than two radii (where
// its centre cannot be), so that a path keeps its disc clear of theirs; its own cell, touching
// them, stays open.
void mark_bumped_robots(const mapping::OccupancyGrid& map, const ExplorerRobot& robot,
                        const TraversabilityOptions& options, std::vector<std::uint8_t>& passable) {
  const double res = map.resolution();
  const double reach = 2.0 * options.robot_radius_m - 0.5 * res;
  const int r = int(std::ceil(reach / res));
  for (const Eigen::Vector2d& p : robot.bumped_robots) {
    const auto c = map.geometry().world_to_cell(p);
    if (!c) continue;
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const Cell n{c->x + dx, c->y + dy};
        if (map.contains(n) && (map.geometry().cell_center(n) - p).norm() < reach) passable[std::size_t(map.geometry().index(n))] = 0;
      }
    }
  }
}

}  // namespace

TeamExplorer::TeamExplorer(int robots, const ExplorationOptions& options)
    : options_(options),
      strategy_(make_strategy(options.strategy, options.strategy_settings)),
      robots_(std::size_t(std::max(0, robots))),
      given_up_(robots_.size()) {}

bool TeamExplorer::all_finished() const {
  return std::all_of(robots_.begin(), robots_.end(), [](const RobotState& r) { return r.finished; });
}

std::vector<Eigen::Vector2d> TeamExplorer::path(int i) const {
  const RobotState& r = robots_[std::size_t(i)];
  std::vector<Eigen::Vector2d> out;
  if (!r.has_task) return out;
  out.reserve(r.path.size() - std::min(r.next, r.path.size()));
  for (std::size_t k = r.next; k < r.path.size(); ++k) out.push_back(r.geometry.cell_center(r.path[k]));
  return out;
}

std::optional<Eigen::Vector2d> TeamExplorer::goal(int i) const {
  const RobotState& r = robots_[std::size_t(i)];
  if (!r.has_task) return std::nullopt;
  return r.geometry.cell_center(r.goal);
}

void TeamExplorer::passage_grid(const std::vector<std::uint8_t>& passage, std::vector<std::uint8_t>& passable,
                                std::vector<std::uint8_t>& factor) const {
  passable = passage;
  factor.resize(passable.size());
  const auto tight = std::uint8_t(std::clamp(options_.tight_cost_factor, 1, 255));
  for (std::size_t i = 0; i < passable.size(); ++i) {
    factor[i] = passable[i] == std::uint8_t(Passage::Fits) ? tight : 1;
    passable[i] = passable[i] != std::uint8_t(Passage::Blocked);
  }
}

namespace {

double cell_distance2(const Cell& a, const Cell& b) {
  return double(a.x - b.x) * (a.x - b.x) + double(a.y - b.y) * (a.y - b.y);
}

// Frontier cells this close (in cells) are the same frontier when counting failed approaches.
double same_frontier_cells(double resolution) { return std::max(3.0, 0.15 / resolution); }
// Goals this close (in cells) are the same approach.
double same_goal_cells(double resolution) { return std::max(2.0, 0.1 / resolution); }

}  // namespace

void TeamExplorer::fail_approach(int i, Failure why, std::int64_t known_cells,
                                 const std::vector<std::vector<char>>* tell) {
  RobotState& r = robots_[std::size_t(i)];
  r.has_task = false;
  const double res = r.geometry.resolution();
  const FailedApproach failure{r.frontier, r.goal, known_cells, why, false};
  for (std::size_t j = 0; j < robots_.size(); ++j) {
    if (int(j) != i && (tell == nullptr || !(*tell)[std::size_t(i)][j])) continue;
    auto& failed = robots_[j].failed;
    failed.push_back(failure);
    // After max_attempts failed approaches to one frontier, every one of them stays.
    const double near = same_frontier_cells(res);
    const auto at_frontier = [&](const FailedApproach& f) { return cell_distance2(f.frontier, failure.frontier) <= near * near; };
    if (std::count_if(failed.begin(), failed.end(), at_frontier) >= options_.max_attempts) {
      if (int(j) == i) ++stats_.frontiers_abandoned;
      for (auto& f : failed)
        if (at_frontier(f)) f.for_good = true;
    }
  }
}

bool TeamExplorer::blocked(const RobotState& r, const Cell& frontier, const Cell& goal, double resolution) const {
  const double piece = options_.targets.piece_radius_m / resolution, same_goal = same_goal_cells(resolution);
  const double near = same_frontier_cells(resolution);
  for (const auto& f : r.failed) {
    const double df = cell_distance2(f.frontier, frontier);
    if (f.for_good && df <= near * near) return true;
    if (df <= piece * piece && cell_distance2(f.goal, goal) <= same_goal * same_goal) return true;
  }
  return false;
}

std::vector<std::uint8_t> TeamExplorer::wave_from(const mapping::OccupancyGrid& map, const Cell& from, WaveField& out,
                                                  const std::function<void(std::vector<std::uint8_t>&)>& block,
                                                  const std::function<void(std::vector<std::uint8_t>&)>& block_after_open) {
  std::vector<std::uint8_t> passable, factor;
  passage_grid(passage_cells(map, options_.traversability), passable, factor);
  if (block) block(passable);
  open_around(map, from, options_.traversability, passable);
  if (block_after_open) block_after_open(passable);
  std::vector<float> occupancy;
  compute_wave(wave_grid(map, passable, factor, occupancy, options_.wave), std::span<const Cell>(&from, 1), options_.wave,
               out);
  ++stats_.waves;
  return passable;
}

void TeamExplorer::set_path(RobotState& r, std::vector<Cell> path, const mapping::OccupancyGrid& map) const {
  r.path = std::move(path);
  r.was_clear.resize(r.path.size());
  for (std::size_t k = 0; k < r.path.size(); ++k) r.was_clear[k] = cell_fits(map, r.path[k], options_.traversability);
  r.next = 0;
}

std::vector<Cell> TeamExplorer::plan(const mapping::OccupancyGrid& map, const ExplorerRobot& robot, const Cell& goal,
                                     const WaveField& wave) {
  if (provider_) {
    const auto points = provider_(map, robot.pose.position(), map.geometry().cell_center(goal));
    if (points.size() >= 2) {
      // The cells the segments cross, in order, each once.
      std::vector<Cell> cells;
      for (std::size_t k = 1; k < points.size(); ++k) {
        mapping::traverse_segment(map.geometry(), points[k - 1], points[k], [&](const Cell& c, double) {
          if (cells.empty() || !(cells.back() == c)) cells.push_back(c);
          return true;
        });
      }
      const bool ends_at_goal = !cells.empty() && cells.back() == goal;
      if (ends_at_goal) {
        ++stats_.provider_paths;
        return cells;
      }
    }
    ++stats_.provider_fallbacks;
  }
  return wave.path_to(goal);
}

bool TeamExplorer::check_task(int i, const std::vector<ExplorerRobot>& robots,
                              const std::vector<std::vector<char>>& links) {
  const ExplorerRobot& robot = robots[std::size_t(i)];
  RobotState& r = robots_[std::size_t(i)];
  const auto& map = *robot.map;
  const double res = map.resolution();
  const Eigen::Vector2d p = robot.pose.position();

  track_progress(r, map, p);

  if (r.yielding) {
    if ((map.geometry().cell_center(r.goal) - p).norm() <= options_.reach_tolerance_m || r.next >= r.path.size() ||
        r.steps_since_progress > options_.stall_steps) {
      r.has_task = r.yielding = false;
    }
    return r.has_task;
  }
  // A goal that sees its unseen cell from beyond the observe range must be reached closely: a
  // robot stopping short would have it out of range.
  const double far = options_.targets.observe_range_m / res;
  const double tolerance = std::sqrt(double((r.goal.x - r.unknown.x) * (r.goal.x - r.unknown.x) +
                                            (r.goal.y - r.unknown.y) * (r.goal.y - r.unknown.y))) > far
                               ? res
                               : options_.reach_tolerance_m;
  if ((map.geometry().cell_center(r.goal) - p).norm() <= tolerance || r.next >= r.path.size()) {
    ++stats_.targets_reached;
    r.has_task = false;
    // Standing at the goal, in sight of the unseen cell, and it is still unseen (the beams passed
    // beside it): this approach failed, another goal is tried next; the robots this one talks to
    // learn it too. Whatever frontier cells are left around it: a target found again at this goal
    // would be reached again at once, every round.
    if (!map.observed(r.unknown)) {
      ++stats_.unobservable;
      fail_approach(i, Failure::Unobservable, map.observed_count(), &links);
    }
    return false;
  }
  if (frontier_cells_near(map, r.frontier, options_.targets.piece_radius_m, options_.targets.frontiers, r.kind) == 0) {
    r.has_task = false;  // explored meanwhile, by this robot or by what it was told
    return false;
  }
  // Stuck, most likely behind or facing another robot: plan a way around the robots it knows of.
  if (r.steps_since_progress > 0 && r.steps_since_progress % options_.detour_after_steps == 0) {
    wave_from(
        map, robot_cell(robot), wave_,
        [&](std::vector<std::uint8_t>& passable) { mark_robots(map, robots, i, links, options_.traversability, passable); },
        [&](std::vector<std::uint8_t>& passable) { mark_bumped_robots(map, robot, options_.traversability, passable); });
    if (wave_.reached(r.goal)) {
      ++stats_.detours;
      set_path(r, wave_.path_to(r.goal), map);
    } else if (!robot.bumped_robots.empty()) {
      // A robot it just bumped into bars every way to the goal: another target, rather than
      // pushing against it until the stall limit.
      ++stats_.given_up_stalled;
      ++stats_.targets_given_up;
      given_up_[std::size_t(i)].push_back({map.geometry().cell_center(r.goal), "stalled: a robot bars the way"});
      fail_approach(i, Failure::Stalled, map.observed_count());
      return false;
    }
  }
  if (r.steps_since_progress > options_.stall_steps) {
    ++stats_.given_up_stalled;
    ++stats_.targets_given_up;
    given_up_[std::size_t(i)].push_back({map.geometry().cell_center(r.goal), "stalled: no progress along the path"});
    fail_approach(i, Failure::Stalled, map.observed_count());
    return false;
  }
  return replan_around_new_obstacles(i, robot);
}

void TeamExplorer::track_progress(RobotState& r, const mapping::OccupancyGrid& map, const Eigen::Vector2d& p) {
  // The furthest path cell near the robot, looking a little ahead.
  const std::size_t look = std::min(r.path.size(), r.next + 12);
  std::size_t passed = r.next;
  for (std::size_t k = r.next; k < look; ++k) {
    if ((map.geometry().cell_center(r.path[k]) - p).norm() <= 1.5 * map.resolution()) passed = k + 1;
  }
  r.next = std::max(r.next, passed);
  // Progress means fewer path cells left than ever before on this task; a replanned path that
  // starts where the robot stands does not count.
  const std::size_t remaining = r.path.size() - std::min(r.next, r.path.size());
  if (remaining < r.best_remaining) {
    r.best_remaining = remaining;
    r.steps_since_progress = 0;
  } else {
    ++r.steps_since_progress;
  }
}

bool TeamExplorer::replan_around_new_obstacles(int i, const ExplorerRobot& robot) {
  RobotState& r = robots_[std::size_t(i)];
  const auto& map = *robot.map;
  // Cells clear when planned, blocked now, on the path ahead: plan again to the same goal, or give it up.
  const std::size_t end = std::min(r.path.size(), r.next + std::size_t(options_.path_check_cells));
  for (std::size_t k = r.next; k < end; ++k) {
    if (!r.was_clear[k] || cell_fits(map, r.path[k], options_.traversability)) continue;
    if (!cell_fits(map, r.goal, options_.traversability)) {
      r.has_task = false;  // the goal itself turned out too close to a wall: a new target, not a failure
      return false;
    }
    wave_from(map, robot_cell(robot), wave_);
    ++stats_.paths_replanned;
    if (!wave_.reached(r.goal)) {
      ++stats_.given_up_unreachable;
      ++stats_.targets_given_up;
      given_up_[std::size_t(i)].push_back({map.geometry().cell_center(r.goal), "cut off: new obstacles closed every path"});
      fail_approach(i, Failure::Unreachable, map.observed_count());
      return false;
    }
    set_path(r, plan(map, robot, r.goal, wave_), map);
    break;
  }
  return true;
}

void TeamExplorer::make_way(int stuck, const std::vector<ExplorerRobot>& robots,
                            const std::vector<std::vector<char>>& links) {
  const RobotState& s = robots_[std::size_t(stuck)];
  const auto& geometry = robots[std::size_t(stuck)].map->geometry();
  const double res = geometry.resolution();
  const double keep_cells = (2.0 * options_.traversability.robot_radius_m + options_.traversability.safety_margin_m) / res + 1.0;
  const std::size_t ahead = std::min(s.path.size(), s.next + std::size_t(options_.path_check_cells));
  const auto near_path = [&](const Cell& c) {
    for (std::size_t k = s.next; k < ahead; ++k) {
      const double dx = c.x - s.path[k].x, dy = c.y - s.path[k].y;
      if (dx * dx + dy * dy <= keep_cells * keep_cells) return true;
    }
    const Cell me = robot_cell(robots[std::size_t(stuck)]);
    const double dx = c.x - me.x, dy = c.y - me.y;
    return dx * dx + dy * dy <= keep_cells * keep_cells;
  };
  for (std::size_t j = 0; j < robots_.size(); ++j) {
    RobotState& other = robots_[j];
    if (int(j) == stuck || !other.finished || other.has_task || !links[std::size_t(stuck)][j]) continue;
    const Cell at = robot_cell(robots[j]);
    if (!near_path(at)) continue;
    // The nearest place (by wave cost on its own map) that is clear of the stuck robot's way.
    const auto& map = *robots[j].map;
    const std::vector<std::uint8_t> passable = wave_from(map, at, wave_);
    const int window = int(std::ceil(4.0 / res));
    float best = WaveField::kUnreached;
    Cell goal = at;
    for (int dy = -window; dy <= window; ++dy) {
      for (int dx = -window; dx <= window; ++dx) {
        const Cell c{at.x + dx, at.y + dy};
        const float cost = wave_.cost(c);
        if (cost >= best || !map.contains(c) || !passable[std::size_t(map.geometry().index(c))] || near_path(c)) continue;
        best = cost;
        goal = c;
      }
    }
    if (best == WaveField::kUnreached) continue;
    other.has_task = other.yielding = true;
    other.goal = other.frontier = goal;
    set_path(other, wave_.path_to(goal), map);
    other.best_remaining = other.path.size();
    other.steps_since_progress = 0;
    ++stats_.yields;
  }
}

void TeamExplorer::update(const std::vector<ExplorerRobot>& robots, const std::vector<std::vector<char>>& links) {
  ++rounds_;
  decisions_.clear();
  std::vector<ExplorerRobot> views = robots;
  coarse_.resize(robots.size());
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const double resolution = robots[i].map->resolution();
    const int factor = int(std::floor(options_.planning_resolution_m / resolution + 1e-9));
    if (factor < 2) continue;
    coarse_[i] = mapping::coarsen(*robots[i].map, factor);
    views[i].map = &coarse_[i];
  }
  decide(views, links);
}

void TeamExplorer::decide(const std::vector<ExplorerRobot>& robots, const std::vector<std::vector<char>>& links) {
  const int n = int(robots_.size());
  std::vector<char> needy(std::size_t(n), false);
  for (int i = 0; i < n; ++i) {
    RobotState& r = robots_[std::size_t(i)];
    r.geometry = robots[std::size_t(i)].map->geometry();
    const auto known = robots[std::size_t(i)].map->observed_count();
    // Failed approaches are retried once the map has grown enough.
    std::erase_if(r.failed, [&](const FailedApproach& f) {
      return !f.for_good && known - f.known_cells >= options_.retry_after_new_cells;
    });
    if (r.finished) {
      if (r.has_task) check_task(i, robots, links);  // a yield task
      if (known - r.known_when_finished >= options_.retry_after_new_cells / 4 + 1 && !r.has_task) r.finished = false;
      else continue;
    }
    if (r.has_task && check_task(i, robots, links)) continue;
    needy[std::size_t(i)] = true;
  }

  for (int i = 0; i < n; ++i) {
    const RobotState& r = robots_[std::size_t(i)];
    if (r.has_task && !r.yielding && r.steps_since_progress >= options_.detour_after_steps) make_way(i, robots, links);
  }

  // Groups of robots that can talk now (connected components of the link graph).
  std::vector<int> group(std::size_t(n), -1);
  int groups = 0;
  for (int i = 0; i < n; ++i) {
    if (group[std::size_t(i)] >= 0) continue;
    std::vector<int> stack = {i};
    group[std::size_t(i)] = groups;
    while (!stack.empty()) {
      const int a = stack.back();
      stack.pop_back();
      for (int b = 0; b < n; ++b) {
        if (group[std::size_t(b)] < 0 && links[std::size_t(a)][std::size_t(b)]) {
          group[std::size_t(b)] = groups;
          stack.push_back(b);
        }
      }
    }
    ++groups;
  }

  for (int g = 0; g < groups; ++g) {
    int leader = -1;
    for (int i = 0; i < n && leader < 0; ++i)
      if (group[std::size_t(i)] == g && needy[std::size_t(i)]) leader = i;
    if (leader < 0) continue;
    std::vector<int> members, claim_holders;
    for (int i = 0; i < n; ++i) {
      if (group[std::size_t(i)] != g) continue;
      const RobotState& r = robots_[std::size_t(i)];
      if (needy[std::size_t(i)] || (strategy_->joint() && r.has_task)) members.push_back(i);
      else if (r.has_task) claim_holders.push_back(i);
    }
    assign_group(members, leader, robots, claim_holders);
  }
}

void TeamExplorer::assign_group(const std::vector<int>& members, int leader, const std::vector<ExplorerRobot>& robots,
                                const std::vector<int>& claim_holders) {
  ++stats_.assignment_rounds;
  const auto& map = *robots[std::size_t(leader)].map;
  const double res = map.resolution();
  const std::vector<std::uint8_t> passage = passage_cells(map, options_.traversability);
  std::vector<std::uint8_t> passable, factor;
  passage_grid(passage, passable, factor);
  for (int i : members) open_around(map, robot_cell(robots[std::size_t(i)]), options_.traversability, passable);
  std::vector<float> occupancy;
  const WaveGrid grid = wave_grid(map, passable, factor, occupancy, options_.wave);
  std::vector<WaveField> waves(members.size());
  for (std::size_t k = 0; k < members.size(); ++k) {
    const Cell from = robot_cell(robots[std::size_t(members[k])]);
    compute_wave(grid, std::span<const Cell>(&from, 1), options_.wave, waves[k]);
    ++stats_.waves;
  }
  // A goal is usable by member k when its wave reaches it, it is not an approach that failed for
  // it, and on its own map too the robot fits there and the frontier is open (what it checks while
  // driving: a target it would drop at once would be handed to it again every round).
  // The frontier's kind counts too: check_task drops a target whose kind of frontier is gone.
  std::vector<std::unordered_map<std::int64_t, bool>> open_on_own_map(members.size());
  const auto usable_by = [&](std::size_t k, const Cell& frontier, const Cell& goal,
                             std::uint8_t kind = FrontierMask::kNarrow) {
    const int i = members[k];
    const auto& own_map = *robots[std::size_t(i)].map;
    if (!waves[k].reached(goal) || blocked(robots_[std::size_t(i)], frontier, goal, res)) return false;
    if (&own_map == &map) return true;
    if (!cell_fits(own_map, goal, options_.traversability)) return false;
    const auto [it, added] = open_on_own_map[k].try_emplace(std::int64_t(map.geometry().index(frontier)) * 4 + kind, false);
    if (added) {
      it->second =
          frontier_cells_near(own_map, frontier, options_.targets.piece_radius_m, options_.targets.frontiers, kind) > 0;
    }
    return it->second;
  };
  const TargetSet found = find_targets(map, passage, [&](const Cell& frontier, const Cell& goal) {
    for (std::size_t k = 0; k < members.size(); ++k)
      if (usable_by(k, frontier, goal)) return true;
    return false;
  }, options_.targets);
  const std::vector<Target>& targets = found.targets;

  AssignmentInput input;
  input.targets = targets;
  input.sensor_range_m = options_.sensor_range_m;
  for (int c : claim_holders) input.claimed.push_back(map.geometry().cell_center(robots_[std::size_t(c)].goal));
  for (std::size_t k = 0; k < members.size(); ++k) {
    const int i = members[k];
    AssignmentRobot ar;
    ar.team_index = i;
    ar.team_size = int(robots_.size());
    ar.position_m = robots[std::size_t(i)].pose.position();
    ar.heading_rad = robots[std::size_t(i)].pose.theta;
    ar.cost_m.resize(targets.size());
    for (std::size_t t = 0; t < targets.size(); ++t) {
      ar.cost_m[t] = usable_by(k, targets[t].frontier, targets[t].goal, targets[t].kind)
                         ? double(waves[k].cost(targets[t].goal)) * res
                                                                        : std::numeric_limits<double>::infinity();
    }
    input.robots.push_back(std::move(ar));
  }
  // Wave costs between the targets' goals on the same grid, for strategies that plan tours.
  input.target_costs_m = [&] {
    std::vector<Cell> goals;
    goals.reserve(targets.size());
    for (const Target& t : targets) goals.push_back(t.goal);
    const std::vector<float> cells = pairwise_wave_costs(grid, goals, options_.wave, wave_);
    ++stats_.waves;
    const auto m = Eigen::Index(targets.size());
    Eigen::MatrixXd costs(m, m);
    for (Eigen::Index a = 0; a < m; ++a) {
      for (Eigen::Index b = 0; b < m; ++b) {
        const float c = cells[std::size_t(a * m + b)];
        costs(a, b) = c == WaveField::kUnreached ? std::numeric_limits<double>::infinity() : double(c) * res;
      }
    }
    return costs;
  };
  // The unknown area behind each target, for strategies that weigh targets by what they reveal.
  input.target_gains_m2 = [&] { return unknown_area_behind(map, targets, options_.sensor_range_m); };
  ScoreSheet sheet;
  if (record_) input.scores = &sheet;
  const std::vector<int> choice = strategy_->assign(input);
  if (record_) record(members, leader, map, targets, choice, sheet);
  for (std::size_t k = 0; k < members.size(); ++k) {
    RobotState& r = robots_[std::size_t(members[k])];
    const int t = choice[k];
    if (t < 0) {
      if (r.has_task) continue;
      if (std::any_of(r.failed.begin(), r.failed.end(), [](const FailedApproach& f) { return !f.for_good; })) {
        // Nothing else to do: try the failed approaches again next round.
        std::erase_if(r.failed, [](const FailedApproach& f) { return !f.for_good; });
        continue;
      }
      r.finished = true;
      r.known_when_finished = robots[std::size_t(members[k])].map->observed_count();
      // What is left, for the report of a run that ends early.
      r.left.clear();
      const auto at = [&](const Cell& c) { return map.geometry().cell_center(c); };
      for (const Cell& c : found.without_goal) r.left.push_back({at(c), "unreachable: no pose the robots can reach sees it"});
      for (std::size_t u = 0; u < targets.size(); ++u) {
        if (std::isfinite(input.robots[k].cost_m[u])) continue;
        std::string why = "unreachable: no path on the robot's map";
        for (const auto& f : r.failed) {
          const double near = same_frontier_cells(res);
          if (!f.for_good || cell_distance2(f.frontier, targets[u].frontier) > near * near) continue;
          why = f.why == Failure::Unobservable ? "unobservable: reached every approach, the unseen cell stayed unseen"
                                               : "unreachable: every approach stalled or was cut off";
        }
        r.left.push_back({at(targets[u].frontier), why});
      }
      continue;
    }
    const Target& target = targets[std::size_t(t)];
    if (r.has_task && !r.yielding && r.goal == target.goal) continue;  // same target: keep the progress made
    r.has_task = true;
    r.yielding = false;
    r.finished = false;
    r.frontier = target.frontier;
    r.unknown = target.unknown;
    r.kind = target.kind;
    r.goal = target.goal;
    set_path(r, plan(*robots[std::size_t(members[k])].map, robots[std::size_t(members[k])], target.goal, waves[k]),
             *robots[std::size_t(members[k])].map);
    r.best_remaining = r.path.size();
    r.steps_since_progress = 0;
  }
}

void TeamExplorer::record(const std::vector<int>& members, int leader, const mapping::OccupancyGrid& map,
                          const std::vector<Target>& targets, const std::vector<int>& choice, ScoreSheet& sheet) {
  const bool reported = sheet.robots.size() == members.size();
  if (reported) {
    sheet_ = sheet;
    sheet_.robots.clear();
  }
  const auto& g = map.geometry();
  for (std::size_t k = 0; k < members.size(); ++k) {
    const RobotState& r = robots_[std::size_t(members[k])];
    Decision d;
    d.round = rounds_;
    d.robot = members[k];
    d.leader = leader;
    d.group = members;
    d.reported = reported;
    d.kept = choice[k] < 0 && r.has_task;
    if (choice[k] >= 0) d.goal_m = g.cell_center(targets[std::size_t(choice[k])].goal);
    if (reported) {
      d.note = std::move(sheet.robots[k].note);
      for (auto& c : sheet.robots[k].candidates) {
        if (c.target < 0 || std::size_t(c.target) >= targets.size()) continue;
        const Target& target = targets[std::size_t(c.target)];
        Candidate out{g.cell_center(target.frontier), g.cell_center(target.goal), target.cells, std::move(c.terms), c.score, -1};
        for (std::size_t j = 0; j < members.size(); ++j)
          if (j != k && choice[j] == c.target) out.taken_by = members[j];
        if (choice[k] == c.target) d.chosen = int(d.candidates.size());
        d.candidates.push_back(std::move(out));
      }
    }
    decisions_.push_back(std::move(d));
  }
}

}  // namespace fleetmap::exploration

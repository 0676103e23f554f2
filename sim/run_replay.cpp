#include "sim/run_replay.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>


namespace fleetmap::sim {

namespace {

using viz::ReplayCell;

ReplayCell code_of(mapping::CellState s) {
  switch (s) {
    case mapping::CellState::Free: return ReplayCell::Free;
    case mapping::CellState::Occupied: return ReplayCell::Occupied;
    default: return ReplayCell::Unknown;
  }
}

// A frontier cell is a free cell to the map.
ReplayCell base(ReplayCell c) { return c == ReplayCell::Frontier ? ReplayCell::Free : c; }

// Cells [lo, hi) of a grid.
struct Box {
  core::Cell lo{1 << 30, 1 << 30}, hi{-(1 << 30), -(1 << 30)};
  bool empty() const { return hi.x <= lo.x || hi.y <= lo.y; }
  bool contains(const core::Cell& c) const { return c.x >= lo.x && c.y >= lo.y && c.x < hi.x && c.y < hi.y; }
  void add(const core::Cell& c) {
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y)};
    hi = {std::max(hi.x, c.x + 1), std::max(hi.y, c.y + 1)};
  }
};

}  // namespace

std::vector<int> RunReplay::refresh(Recorded& r, const mapping::OccupancyGrid& map) {
  const auto& g = map.geometry();
  const auto& lo = map.log_odds_data();
  std::vector<int> changed;
  if (r.cells.empty() || !(g == r.geometry)) {
    r.geometry = g;
    r.log_odds = lo;
    r.cells.resize(lo.size());
    for (std::size_t i = 0; i < lo.size(); ++i) {
      r.cells[i] = code_of(map.state_at(int(i)));
      changed.push_back(int(i));
    }
    return changed;
  }
  const int w = g.width();
  for (int y = 0; y < g.height(); ++y) {
    const std::size_t row = std::size_t(y) * std::size_t(w);
    if (std::memcmp(&lo[row], &r.log_odds[row], std::size_t(w) * sizeof(float)) == 0) continue;
    for (std::size_t i = row; i < row + std::size_t(w); ++i) {
      if (lo[i] == r.log_odds[i]) continue;
      r.log_odds[i] = lo[i];
      const ReplayCell now = code_of(map.state_at(int(i)));
      if (now == base(r.cells[i])) continue;
      r.cells[i] = now;
      changed.push_back(int(i));
    }
  }
  return changed;
}

void RunReplay::mark_frontiers(const Simulation& sim, const std::vector<int>& changed, bool all) {
  const mapping::OccupancyGrid& map = sim.merged_map();
  const auto& g = map.geometry();
  const auto mark = [&](const Box& window) {
    const exploration::FrontierMask mask(map, frontier_options_, window.lo, window.hi);
    for (int y = mask.lo().y; y < mask.hi().y; ++y)
      for (int x = mask.lo().x; x < mask.hi().x; ++x) {
        auto& c = merged_.cells[std::size_t(g.index({x, y}))];
        if (c == ReplayCell::Free || c == ReplayCell::Frontier) c = mask({x, y}) ? ReplayCell::Frontier : ReplayCell::Free;
      }
  };
  if (all) return mark(Box{{0, 0}, {g.width(), g.height()}});
  if (changed.empty()) return;
  // A cell's frontier status depends on the cells within the widths FrontierOptions open by: only
  // cells that near a changed cell are looked at again, in a window around each robot's new cells.
  const auto& o = frontier_options_;
  const int margin = 2 * int(std::ceil(std::max(o.min_unknown_width_m, o.min_narrow_width_m) / g.resolution())) + 3;
  const int reach = int(std::ceil(sim.scenario().range.max_range_m / g.resolution())) + 2;
  const int n = sim.scenario().robot_count;
  std::vector<Box> around(static_cast<std::size_t>(n)), touched(static_cast<std::size_t>(n) + 1);
  for (int i = 0; i < n; ++i) {
    const core::Cell c = g.world_to_cell_unbounded(sim.track(i).estimate.back().position());
    around[std::size_t(i)] = Box{{c.x - reach, c.y - reach}, {c.x + reach + 1, c.y + reach + 1}};
  }
  for (int idx : changed) {
    const core::Cell c = g.cell_of_index(idx);
    std::size_t k = 0;
    while (k < around.size() && !around[k].contains(c)) ++k;
    touched[k].add(c);  // k == n: near no robot (e.g. a map merged from far away)
  }
  for (auto& b : touched) {
    if (b.empty()) continue;
    b.lo = {std::max(0, b.lo.x - margin), std::max(0, b.lo.y - margin)};
    b.hi = {std::min(g.width(), b.hi.x + margin), std::min(g.height(), b.hi.y + margin)};
    mark(b);
  }
}

void RunReplay::relate(Recorded& own, const std::vector<int>& own_changed, const std::vector<int>& merged_changed,
                       bool all) const {
  const auto at = [&](std::size_t i) {
    own.relative[i] = own.cells[i] == base(merged_.cells[i]) ? ReplayCell::AsMerged : own.cells[i];
  };
  if (all || own.relative.size() != own.cells.size()) {
    own.relative.resize(own.cells.size());
    for (std::size_t i = 0; i < own.cells.size(); ++i) at(i);
    return;
  }
  for (int i : own_changed) at(std::size_t(i));
  for (int i : merged_changed) at(std::size_t(i));
}

void RunReplay::add_step(const Simulation& sim) {
  const int n = sim.scenario().robot_count;
  if (robots_.empty()) {
    frontier_options_ = explorer_options(sim.scenario()).targets.frontiers;
    merged_.layer = viz::ReplayLayer("merged map");
    own_.resize(std::size_t(n));
    robots_.resize(std::size_t(n));
    for (int i = 0; i < n; ++i) {
      robots_[std::size_t(i)].name = "robot " + std::to_string(i + 1);
      robots_[std::size_t(i)].color = viz::palette_color(i);
      own_[std::size_t(i)].layer = viz::ReplayLayer(robots_[std::size_t(i)].name + "'s map");
    }
    last_plan_.resize(std::size_t(n));
    given_up_seen_.assign(std::size_t(n), 0);
  }
  const int step = sim.step_count();
  const bool first = merged_.cells.empty() || !(merged_.geometry == sim.merged_map().geometry());
  const std::vector<int> changed = refresh(merged_, sim.merged_map());
  mark_frontiers(sim, changed, first);
  merged_.layer.add_step(merged_.geometry, merged_.cells);
  const std::vector<core::Pose2> truth = sim.true_poses();
  for (int i = 0; i < n; ++i) {
    Recorded& own = own_[std::size_t(i)];
    const bool new_geometry = own.cells.empty() || !(own.geometry == sim.robot_map(i).geometry());
    const std::vector<int> own_changed = refresh(own, sim.robot_map(i));
    if (own.geometry == merged_.geometry) {
      relate(own, own_changed, changed, first || new_geometry);
      own.layer.add_step(own.geometry, own.relative, true);
    } else {
      own.relative.clear();
      own.layer.add_step(own.geometry, own.cells);
    }

    viz::ReplayRobot& r = robots_[std::size_t(i)];
    r.truth.push_back(truth[std::size_t(i)]);
    r.estimate.push_back(sim.track(i).estimate.back());
    r.frame.push_back(core::Pose2::from_transform(sim.frame_origin(i)));
    r.finished.push_back(sim.finished(i));
    // A plan is stored once; while the robot follows it, a step records how much of it is behind.
    const std::vector<Eigen::Vector2d> path = sim.path(i);
    auto& last = last_plan_[std::size_t(i)];
    const bool suffix = !r.plans.empty() && !path.empty() && path.size() <= last.size() &&
                        std::equal(path.begin(), path.end(), last.end() - std::ptrdiff_t(path.size()));
    if (path.empty()) {
      r.plan.push_back(-1);
      r.passed.push_back(0);
    } else if (suffix && r.plan.back() >= 0) {
      r.plan.push_back(r.plan.back());
      r.passed.push_back(int(last.size() - path.size()));
    } else {
      r.plans.push_back(path);
      last = path;
      r.plan.push_back(int(r.plans.size()) - 1);
      r.passed.push_back(0);
    }
    const auto& given_up = sim.given_up(i);
    for (std::size_t k = given_up_seen_[std::size_t(i)]; k < given_up.size(); ++k) {
      given_up_.push_back({step, "given up", i, -1, given_up[k].reason, sim.frame_origin(i).apply(given_up[k].goal_m)});
    }
    given_up_seen_[std::size_t(i)] = given_up.size();
  }
  add_decisions(sim);
}

void RunReplay::add_decisions(const Simulation& sim) {
  const auto& explorer = sim.explorer();
  if (explorer.rounds() == rounds_seen_) return;
  rounds_seen_ = explorer.rounds();
  if (!explorer.decision_sheet().terms.empty()) sheet_ = explorer.decision_sheet();
  const bool lower = explorer.decision_sheet().lower_is_better;
  for (const auto& d : explorer.decisions()) {
    const core::Transform2& to_world = sim.frame_origin(d.leader);
    viz::ReplayDecision out;
    out.step = sim.step_count();
    out.leader = d.leader;
    out.group = d.group;
    out.weighed = int(d.candidates.size());
    out.kept = d.kept;
    out.reported = d.reported;
    out.note = d.note;
    if (d.goal_m) out.goal_m = to_world.apply(*d.goal_m);
    // Best first (NaN scores last), the chosen one always kept.
    std::vector<int> order(d.candidates.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = int(k);
    const auto key = [&](int k) {
      const double s = d.candidates[std::size_t(k)].score;
      return std::isnan(s) ? std::numeric_limits<double>::infinity() : lower ? s : -s;
    };
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
    for (std::size_t rank = 0; rank < order.size(); ++rank) {
      const int k = order[rank];
      if (int(rank) >= kCandidates && k != d.chosen) continue;
      const auto& c = d.candidates[std::size_t(k)];
      if (k == d.chosen) out.chosen = int(out.candidates.size());
      out.candidates.push_back({to_world.apply(c.frontier_m), to_world.apply(c.goal_m), c.cells, c.terms, c.score, c.taken_by});
    }
    robots_[std::size_t(d.robot)].decisions.push_back(std::move(out));
  }
}

std::size_t RunReplay::map_bytes() const {
  std::size_t bytes = merged_.layer.encoded_bytes();
  for (const auto& r : own_) bytes += r.layer.encoded_bytes();
  return bytes;
}

std::string RunReplay::html(const RunResult& result, const std::string& map_label) const {
  const Scenario& s = result.scenario;
  viz::Replay r;
  const int n = int(robots_.size());
  r.title = fmt::format("{}: {} robot{}, strategy {}", map_label, n, n == 1 ? "" : "s", s.exploration.strategy);
  const auto level = [](const std::optional<int>& v) { return v ? fmt::format("step {}", *v) : std::string("never"); };
  r.facts = {{"localization", s.localization},
             {"merging", s.merging},
             {"communication", std::isinf(s.communication.range_m) ? std::string("unlimited")
                               : s.communication.range_m == 0.0  ? std::string("only at rendezvous")
                                                                 : fmt::format("{} m", s.communication.range_m)},
             {"seed", std::to_string(s.seed)},
             {"steps", std::to_string(result.steps)},
             {"coverage", fmt::format("{:.1f}%", 100.0 * (result.coverage.empty() ? 0.0 : result.coverage.back()))},
             {"95%", level(result.steps_to_95)},
             {"99%", level(result.steps_to_99)}};
  r.robot_radius_m = s.robot.radius_m;
  r.period_s = s.period_s;
  r.estimates = s.localization != "ideal";
  const std::size_t steps = std::size_t(this->steps());
  r.coverage.assign(result.coverage.begin(), result.coverage.begin() + std::ptrdiff_t(std::min(steps, result.coverage.size())));
  r.coverage.resize(steps, r.coverage.empty() ? 0.0 : r.coverage.back());
  r.merged = merged_.layer;
  for (const auto& o : own_) r.robot_maps.push_back(o.layer);
  r.robots = robots_;
  for (std::size_t i = 0; i < r.robots.size() && i < result.robots.size(); ++i) r.robots[i].distance_m = result.robots[i].distance_m;
  for (const auto& e : result.events) r.events.push_back({e.step, e.kind, e.robot, e.other, e.detail, std::nullopt});
  for (const auto& m : result.merges) {
    if (m.merged) continue;  // a merge made is an event of the run already
    r.events.push_back({m.step, "refused merge", m.receiver, m.sender,
                        fmt::format("{}, confidence {:.2f}: {}", m.method, m.confidence, m.reason), std::nullopt});
  }
  r.events.insert(r.events.end(), given_up_.begin(), given_up_.end());
  r.scores = {s.exploration.strategy, sheet_.terms, sheet_.score, sheet_.lower_is_better, sheet_.rule};
  std::stable_sort(r.events.begin(), r.events.end(), [](const auto& a, const auto& b) { return a.step < b.step; });
  return viz::replay_html(r);
}

}  // namespace fleetmap::sim

#include "experiments/landmark_experiment.h"

#include <cmath>
#include <memory>
#include <set>

#include <fmt/format.h>

#include "core/angle.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/random.h"
#include "experiments/slam_experiment.h"
#include "localization/fastslam2.h"
#include "merging/rendezvous.h"
#include "sim/simulation.h"

namespace fleetmap::experiments {

double TransformError::translation() const { return std::hypot(dx, dy); }

TransformError transform_error(const core::Transform2& e, const core::Transform2& t) {
  return {std::abs(e.translation().x() - t.translation().x()), std::abs(e.translation().y() - t.translation().y()),
          std::abs(core::normalize_angle(e.rotation() - t.rotation()))};
}

LandmarkWorld make_landmark_world(const LandmarkExperimentOptions& o, const std::vector<LandmarkField>& fields) {
  LandmarkWorld w;
  core::Random rng = core::Random(o.seed).fork(0x1a4d);
  for (const auto& f : fields) {
    for (int i = 0; i < f.count; ++i) {
      w.landmarks.emplace_back(rng.uniform(f.lo.x(), f.hi.x()), rng.uniform(f.lo.y(), f.hi.y()));
      w.signatures.emplace_back(rng.uniform(0.0, o.signature_range), rng.uniform(0.0, o.signature_range));
    }
  }
  return w;
}

namespace {

// An all-free grid around the landmarks and the robots' starts and paths, 10 m beyond them.
mapping::OccupancyGrid open_ground(const LandmarkWorld& w, const LandmarkCase& c) {
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  const auto add = [&](const Eigen::Vector2d& p) { lo = lo.cwiseMin(p), hi = hi.cwiseMax(p); };
  for (const auto& p : w.landmarks) add(p);
  for (const auto& r : c.robots) {
    add(r.start.position());
    for (const auto& p : r.path) add(p);
  }
  const double res = 0.5, margin = 10.0;
  const int width = int(std::ceil((hi.x() - lo.x() + 2 * margin) / res)), height = int(std::ceil((hi.y() - lo.y() + 2 * margin) / res));
  mapping::OccupancyGrid g(core::GridGeometry(res, width, height, core::Pose2(lo.x() - margin, lo.y() - margin, 0.0)));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) g.set_state({x, y}, mapping::CellState::Free);
  return g;
}

RobotLandmarkMap landmark_map(const std::vector<localization::Landmark>& estimates, const LandmarkWorld& w, double noise,
                              const core::Random& stream) {
  RobotLandmarkMap out;
  for (const auto& l : estimates) {
    merging::MapLandmark m;
    m.position = l.position;
    m.covariance = l.covariance;
    // The signature as this robot read it: the true one with the sensor's noise, one draw per landmark.
    core::Random rng = stream.fork(std::uint64_t(l.id));
    m.signature = Eigen::Vector2d(w.signatures[std::size_t(l.id)].x() + rng.normal(0.0, noise),
                                  w.signatures[std::size_t(l.id)].y() + rng.normal(0.0, noise));
    out.map.landmarks.push_back(std::move(m));
    out.ids.push_back(l.id);
  }
  return out;
}

// The fused map with the true landmark of each entry: self's first (in order), then other's
// landmarks that were not duplicates, recognised by their transformed positions.
std::vector<int> merged_ids(const merging::LandmarkMergeResult& merged, const RobotLandmarkMap& self,
                            const RobotLandmarkMap& other, const core::Transform2& t) {
  std::vector<int> ids = self.ids;
  const merging::LandmarkMap moved = merging::transform_landmarks(other.map, t);
  for (std::size_t k = self.ids.size(); k < merged.merged.landmarks.size(); ++k) {
    int id = -1;
    for (std::size_t j = 0; j < moved.landmarks.size(); ++j) {
      if (moved.landmarks[j].position == merged.merged.landmarks[k].position) id = other.ids[j];
    }
    ids.push_back(id);
  }
  return ids;
}

void landmark_rms(const merging::LandmarkMap& map, const std::vector<int>& ids, const std::vector<Eigen::Vector2d>& truth,
                  double& rms_x, double& rms_y) {
  double sx = 0.0, sy = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < map.landmarks.size(); ++k) {
    if (ids[k] < 0) continue;
    const Eigen::Vector2d e = map.landmarks[k].position - truth[std::size_t(ids[k])];
    sx += e.x() * e.x(), sy += e.y() * e.y(), ++n;
  }
  rms_x = n ? std::sqrt(sx / n) : 0.0;
  rms_y = n ? std::sqrt(sy / n) : 0.0;
}

}  // namespace

namespace {

// The filter of robot i: the registered `fastslam2` localizer (both of its maps are measured).
const localization::FastSlam2& filter_of(const sim::Simulation& s, int i) {
  return localization::fastslam2_filter(s.localizer(i));
}

// What the leader (robot 0) does at a rendezvous: every follower reports its maps, pose and
// observation; both alignment methods are measured on both kinds of map, and the leader's global
// map grows by each follower's map aligned by the method Fig. 3 chooses (§VI, Fig. 9).
class Leader {
 public:
  Leader(const LandmarkExperimentOptions& o, const LandmarkCase& c, const LandmarkWorld& w, const core::Random& base,
         LandmarkCaseRun& out)
      : o_(o), c_(c), w_(w), base_(base), out_(out) {}

  void meet(const sim::Simulation& s) {
    const int k = s.step_count(), n = int(c_.robots.size());
    RobotLandmarkMap global = maps_of(s, 0, localization::ParticleMap::Combined);
    std::vector<int> source(global.ids.size(), 0);
    for (int j = 1; j < n; ++j) {
      const sim::Detection* lj = s.detection(0, j);
      const sim::Detection* jl = s.detection(j, 0);
      if (!lj || !jl) {
        const auto truth = s.true_poses();
        throw InputError(fmt::format("case '{}': robots {} and {} do not see each other at the rendezvous of step {} ({:.1f} m "
                                     "apart, camera range {:g} m): move their paths' ends closer",
                                     c_.name, c_.robots[0].name, c_.robots[std::size_t(j)].name, k,
                                     (truth[0].position() - truth[std::size_t(j)].position()).norm(),
                                     s.scenario().detector.max_range_m));
      }
      FollowerReport rep;
      rep.step = k;
      rep.leader = c_.robots[0].name;
      rep.follower = c_.robots[std::size_t(j)].name;
      rep.truth = frame_of(0).inverse() * frame_of(j);
      core::Random ransac = base_.fork(600 + std::uint64_t(j) + 10 * std::uint64_t(k));
      for (int kind = 0; kind < 2; ++kind) {
        const auto which = kind == 0 ? localization::ParticleMap::MaxWeight : localization::ParticleMap::Combined;
        const RobotLandmarkMap self = maps_of(s, 0, which), other = maps_of(s, j, which);
        // Each map with the pose that goes with it (the maximum-weight particle's, or the mean).
        const merging::Rendezvous meeting{filter_of(s, 0).pose(which), filter_of(s, j).pose(which),
                                          {lj->range, lj->bearing, jl->range, jl->bearing}};
        const auto evaluate = [&](MethodOutcome& m, const std::optional<core::Transform2>& t) {
          m.transform = t;
          if (!t) return;
          m.error = transform_error(*t, rep.truth);
          const auto merged = merging::merge_landmark_maps(self.map, other.map, *t, o_.alignment);
          landmark_rms(merged.merged, merged_ids(merged, self, other, *t), out_.truth_in_leader, m.landmark_rms_x,
                       m.landmark_rms_y);
        };
        const auto da = merging::align_landmarks(self.map, other.map, o_.alignment, ransac);
        evaluate(rep.data_association[kind], da.found ? std::optional(da.transform) : std::nullopt);
        evaluate(rep.observation[kind],
                 merging::rendezvous_transform(meeting.self_pose, meeting.other_pose, meeting.observation));
        if (kind == 1) {
          const std::set<int> mine(self.ids.begin(), self.ids.end());
          for (int id : other.ids) rep.shared += int(mine.count(id));
          rep.choice = merging::align_landmark_maps(self.map, other.map, meeting, o_.alignment, ransac);
          rep.overlap = rep.choice.overlapping_landmarks;
          if (rep.choice.transform) grow(global, source, other, j, *rep.choice.transform);
        }
      }
      rep.global_landmarks = int(global.map.landmarks.size());
      out_.reports.push_back(std::move(rep));
    }
    out_.global = global.map;
    out_.global_source = source;
  }

 private:
  core::Transform2 frame_of(int i) const { return c_.robots[std::size_t(i)].start.as_transform(); }

  RobotLandmarkMap maps_of(const sim::Simulation& s, int i, localization::ParticleMap which) const {
    return landmark_map(filter_of(s, i).map(which), w_, o_.signature_noise, base_.fork(500 + std::uint64_t(i)));
  }


  // The global map with follower j's map fused in; fused entries (the leader's, changed by the
  // fusion) are marked -1 in `source`.
  void grow(RobotLandmarkMap& global, std::vector<int>& source, const RobotLandmarkMap& other, int j,
            const core::Transform2& t) const {
    const RobotLandmarkMap before = global;
    const auto merged = merging::merge_landmark_maps(global.map, other.map, t, o_.alignment);
    const auto ids = merged_ids(merged, before, other, t);
    for (std::size_t s = 0; s < before.map.landmarks.size(); ++s) {
      if (merged.merged.landmarks[s].position != before.map.landmarks[s].position) source[s] = -1;
    }
    for (std::size_t s = before.ids.size(); s < ids.size(); ++s) source.push_back(j);
    global.map = merged.merged;
    global.ids = ids;
  }

  const LandmarkExperimentOptions& o_;
  const LandmarkCase& c_;
  const LandmarkWorld& w_;
  const core::Random& base_;
  LandmarkCaseRun& out_;
};

}  // namespace

// One run on the simulator: each robot driven by its precomputed commands (sim::CommandScript), in
// its own frame (its start, known exactly), with the registered `fastslam2` localizer; the observer
// records the true paths and lets the leader gather the reports at the case's rendezvous steps.
LandmarkCaseRun run_landmark_case(const LandmarkExperimentOptions& o, const LandmarkCase& c, int run,
                                  std::optional<double> range_noise) {
  const LandmarkWorld w = make_landmark_world(o, c.fields.empty() ? o.fields : c.fields);
  const core::Random base = core::Random(o.seed).fork(std::uint64_t(run) + 1);
  const int n = int(c.robots.size());

  sim::Scenario scenario;
  scenario.seed = base.seed();  // every stream the run uses is given below
  scenario.steps = c.steps;
  scenario.period_s = o.period_s;
  scenario.placement = sim::Placement::List;
  scenario.robot = o.robot;
  scenario.robot.max_speed_mps = o.speed_mps;
  scenario.noise = o.noise;
  scenario.landmark_sensor = o.sensor;
  scenario.detector = o.camera;
  if (range_noise) scenario.landmark_sensor.range_noise_m = scenario.detector.range_noise_m = *range_noise;
  scenario.landmarks = w.landmarks;
  // The ground is open: the range sensor (one short beam) never meets anything, so it draws no noise.
  scenario.range.angles_rad = {0.0};
  scenario.range.max_range_m = 1.0;
  scenario.localization = "fastslam2";
  scenario.localization_settings = {{"particles", std::to_string(o.particles)}};
  scenario.merging = "rendezvous";       // each robot maps in its own frame, its start
  scenario.communication.range_m = 0.0;  // robots talk when they see each other
  sim::SimulationSetup how;
  how.measure_coverage = false;
  // No frame alignment or grid exchange when robots see each other: the leader gathers the
  // followers' maps at the case's rendezvous steps (the observer below).
  how.on_meeting = [](sim::Simulation&, int, int) {};
  for (int i = 0; i < n; ++i) {
    const auto& r = c.robots[std::size_t(i)];
    scenario.starts.push_back(r.start);
    sim::RobotSetup rs;
    std::vector<sim::Command> commands;
    for (const auto& u : path_commands(r.start, r.path, o.speed_mps, c.steps, o.period_s, scenario.robot.max_turn_rate_rps))
      commands.push_back({u.v, u.omega});
    rs.driver = std::make_shared<sim::CommandScript>(std::move(commands));
    const std::uint64_t seed = base.fork(100 + std::uint64_t(i)).seed();
    rs.localizer = [seed](const localization::LocalizerContext& context) {
      localization::LocalizerContext own = context;
      own.initial_pose = core::Pose2();  // its map frame is its start: it knows its pose there exactly
      own.options.initial_xy = own.options.initial_theta = 0.0;
      own.seed = seed;
      return localization::make_localizer("fastslam2", own);
    };
    rs.motion_rng = std::make_shared<core::Random>(base.fork(200 + std::uint64_t(i)));
    rs.sensor_rng = std::make_shared<core::Random>(base.fork(300 + std::uint64_t(i)));
    rs.detector_rng = std::make_shared<core::Random>(base.fork(400 + std::uint64_t(i)));
    how.robots.push_back(std::move(rs));
  }
  scenario.robot_count = n;

  LandmarkCaseRun out;
  out.case_name = c.name;
  out.run = run;
  out.range_noise = scenario.landmark_sensor.range_noise_m;
  out.truth_paths.resize(static_cast<std::size_t>(n));
  const core::Transform2 leader_from_world = c.robots[0].start.as_transform().inverse();
  for (const auto& p : w.landmarks) out.truth_in_leader.push_back(leader_from_world.apply(p));
  Leader leader(o, c, w, base, out);
  std::size_t next_meeting = 0;
  const auto observe = [&](const sim::Simulation& s) {
    const auto truth = s.true_poses();
    for (int i = 0; i < n; ++i) {
      out.truth_paths[std::size_t(i)].push_back(
          core::Pose2::from_transform(leader_from_world * truth[std::size_t(i)].as_transform()));
    }
    if (next_meeting < c.rendezvous.size() && c.rendezvous[next_meeting] == s.step_count()) {
      ++next_meeting;
      leader.meet(s);
    }
  };
  sim::Simulation simulation(scenario, open_ground(w, c), std::move(how));
  simulation.run_to_end({}, observe);

  const auto truth = simulation.true_poses();
  for (int i = 0; i < n; ++i) {
    // Errors in the robot's own frame: its filter's pose, and dead reckoning of what its encoders reported.
    const Eigen::Vector2d t =
        core::Pose2::from_transform(c.robots[std::size_t(i)].start.as_transform().inverse() * truth[std::size_t(i)].as_transform())
            .position();
    core::Pose2 odometry;
    for (const auto& u : simulation.track(i).odometry) odometry = localization::integrate_motion(odometry, u);
    out.final_position_error.push_back((filter_of(simulation, i).pose().position() - t).norm());
    out.odometry_position_error.push_back((odometry.position() - t).norm());
  }
  return out;
}

LandmarkExperimentResult run_landmark_experiment(const LandmarkExperimentOptions& o, int jobs,
                                                 const LandmarkProgress& progress) {
  LandmarkExperimentResult r;
  r.options = o;
  const auto case_named = [&](const std::string& name) -> const LandmarkCase& {
    for (const auto& c : o.cases) {
      if (c.name == name) return c;
    }
    throw InputError("parts: no case is named '" + name + "'");
  };
  // Every job: (target list, case, run, noise).
  struct Job {
    std::vector<LandmarkCaseRun>* into;
    const LandmarkCase* c;
    int run;
    std::optional<double> noise;
  };
  std::vector<Job> work;
  const auto add_runs = [&](std::vector<LandmarkCaseRun>& into, const std::string& name, int runs,
                            std::optional<double> noise = std::nullopt) {
    if (name.empty()) return;
    into.resize(std::size_t(runs));
    for (int k = 0; k < runs; ++k) work.push_back({&into, &case_named(name), k, noise});
  };
  add_runs(r.table1, o.table1, o.runs);
  add_runs(r.little, o.little_overlap, o.runs);
  add_runs(r.large, o.large_overlap, o.runs);
  add_runs(r.small_overlap, o.overlap_small, o.runs);
  add_runs(r.large_overlap, o.overlap_large, o.runs);
  if (!o.noise_case.empty()) {
    r.noise.resize(o.noise_levels.size());
    for (std::size_t i = 0; i < o.noise_levels.size(); ++i) {
      r.noise[i].range_noise = o.noise_levels[i];
      add_runs(r.noise[i].runs, o.noise_case, o.runs, o.noise_levels[i]);
    }
  }
  r.merges.resize(o.merges.size());
  for (std::size_t i = 0; i < o.merges.size(); ++i) {
    const LandmarkCase* c = &case_named(o.merges[i]);
    work.push_back({nullptr, c, int(i), std::nullopt});
  }
  int done = 0;
  const int total = int(work.size());
  if (progress) progress(0, total);
  core::parallel_for(
      total, jobs,
      [&](int index) {
        const Job& j = work[std::size_t(index)];
        if (j.into) {
          (*j.into)[std::size_t(j.run)] = run_landmark_case(o, *j.c, j.run, j.noise);
        } else {
          r.merges[std::size_t(j.run)] = run_landmark_case(o, *j.c, 0);
        }
      },
      [&](int) {
        if (progress) progress(++done, total);
      });
  return r;
}

}  // namespace fleetmap::experiments

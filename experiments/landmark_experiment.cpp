#include "experiments/landmark_experiment.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "core/angle.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/random.h"
#include "experiments/slam_experiment.h"
#include "localization/ekf_models.h"
#include "localization/fastslam2.h"
#include "merging/rendezvous.h"
#include "sim/world.h"

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

LandmarkCaseRun run_landmark_case(const LandmarkExperimentOptions& o, const LandmarkCase& c, int run,
                                  std::optional<double> range_noise) {
  const LandmarkWorld w = make_landmark_world(o, c.fields.empty() ? o.fields : c.fields);
  sim::LandmarkSensorOptions sensor = o.sensor;
  sim::RobotDetectorOptions camera = o.camera;
  sim::RobotOptions robot = o.robot;
  robot.max_speed_mps = o.speed_mps;
  if (range_noise) sensor.range_noise_m = camera.range_noise_m = *range_noise;
  const sim::World world(open_ground(w, c), w.landmarks);
  const core::Random base = core::Random(o.seed).fork(std::uint64_t(run) + 1);
  const int n = int(c.robots.size());

  localization::FastSlam2Options f;
  f.particles = o.particles;
  f.process_noise = Eigen::Vector3d(o.noise.position_m * o.noise.position_m, o.noise.position_m * o.noise.position_m,
                                    o.noise.heading_rad * o.noise.heading_rad)
                        .asDiagonal();
  f.measurement_noise = Eigen::Vector2d(std::max(sensor.range_noise_m, localization::kMinMeasurementStd) *
                                            std::max(sensor.range_noise_m, localization::kMinMeasurementStd),
                                        std::max(sensor.bearing_noise_rad, localization::kMinMeasurementStd) *
                                            std::max(sensor.bearing_noise_rad, localization::kMinMeasurementStd))
                            .asDiagonal();

  std::vector<core::Pose2> truth, odometry(static_cast<std::size_t>(n));
  std::vector<std::vector<localization::Odometry>> commands;
  std::vector<localization::FastSlam2> filters;
  std::vector<core::Random> motion_rng, sensor_rng, camera_rng;
  LandmarkCaseRun out;
  out.case_name = c.name;
  out.run = run;
  out.range_noise = sensor.range_noise_m;
  out.truth_paths.resize(static_cast<std::size_t>(n));
  const core::Transform2 leader_from_world = c.robots[0].start.as_transform().inverse();
  for (int i = 0; i < n; ++i) {
    const auto& r = c.robots[std::size_t(i)];
    truth.push_back(r.start);
    commands.push_back(path_commands(r.start, r.path, o.speed_mps, c.steps, o.period_s, robot.max_turn_rate_rps));
    // Each robot's map frame is its start: it knows its pose there exactly.
    filters.emplace_back(core::Pose2(), Eigen::Matrix3d::Zero(), f, base.fork(100 + std::uint64_t(i)).seed());
    motion_rng.push_back(base.fork(200 + std::uint64_t(i)));
    sensor_rng.push_back(base.fork(300 + std::uint64_t(i)));
    camera_rng.push_back(base.fork(400 + std::uint64_t(i)));
    out.truth_paths[std::size_t(i)].push_back(core::Pose2::from_transform(leader_from_world * r.start.as_transform()));
  }
  for (const auto& p : w.landmarks) out.truth_in_leader.push_back(leader_from_world.apply(p));

  // The true start of robot i in robot j's frame, and a pose in the world in robot i's frame.
  const auto frame_of = [&](int i) { return c.robots[std::size_t(i)].start.as_transform(); };
  const auto in_own_frame = [&](int i, const core::Pose2& p) {
    return core::Pose2::from_transform(frame_of(i).inverse() * p.as_transform());
  };

  // The simulator's order: readings at the start and after every step's moves, the filter updated
  // when a robot saw landmarks, the camera read every step.
  std::vector<std::vector<sim::Detection>> seen(static_cast<std::size_t>(n));
  const auto sense = [&] {
    for (int i = 0; i < n; ++i) {
      const auto readings = sim::read_landmarks(world, truth[std::size_t(i)], sensor, sensor_rng[std::size_t(i)]);
      if (!readings.empty()) filters[std::size_t(i)].update(readings);
      seen[std::size_t(i)] = sim::detect_robots(world, i, truth, camera, camera_rng[std::size_t(i)]);
    }
  };
  sense();
  std::size_t next_meeting = 0;
  for (int k = 1; k <= c.steps; ++k) {
    for (int i = 0; i < n; ++i) {
      const auto& u = commands[std::size_t(i)][std::size_t(k - 1)];
      const sim::MoveResult mv = sim::move_robot(world, i, truth, robot, {u.v, u.omega}, o.period_s, o.noise,
                                                 motion_rng[std::size_t(i)]);
      truth[std::size_t(i)] = mv.pose;
      odometry[std::size_t(i)] = localization::integrate_motion(odometry[std::size_t(i)], mv.odometry);
      filters[std::size_t(i)].predict(mv.odometry);
      out.truth_paths[std::size_t(i)].push_back(core::Pose2::from_transform(leader_from_world * mv.pose.as_transform()));
    }
    sense();
    if (next_meeting >= c.rendezvous.size() || c.rendezvous[next_meeting] != k) continue;
    ++next_meeting;

    // The rendezvous: every follower reports its maps, pose and observation to the leader.
    const auto maps_of = [&](int i, localization::ParticleMap which) {
      return landmark_map(filters[std::size_t(i)].map(which), w, o.signature_noise, base.fork(500 + std::uint64_t(i)));
    };
    const auto find = [&](int a, int b) -> const sim::Detection* {
      for (const auto& d : seen[std::size_t(a)]) {
        if (d.other == b) return &d;
      }
      return nullptr;
    };
    RobotLandmarkMap global = maps_of(0, localization::ParticleMap::Combined);
    std::vector<int> source(global.ids.size(), 0);
    for (int j = 1; j < n; ++j) {
      const sim::Detection* lj = find(0, j);
      const sim::Detection* jl = find(j, 0);
      if (!lj || !jl) {
        throw InputError(fmt::format("case '{}': robots {} and {} do not see each other at the rendezvous of step {} ({:.1f} m "
                                     "apart, camera range {:g} m): move their paths' ends closer",
                                     c.name, c.robots[0].name, c.robots[std::size_t(j)].name, k,
                                     (truth[0].position() - truth[std::size_t(j)].position()).norm(), camera.max_range_m));
      }
      FollowerReport rep;
      rep.step = k;
      rep.leader = c.robots[0].name;
      rep.follower = c.robots[std::size_t(j)].name;
      rep.truth = frame_of(0).inverse() * frame_of(j);
      core::Random ransac = base.fork(600 + std::uint64_t(j) + 10 * std::uint64_t(k));
      for (int kind = 0; kind < 2; ++kind) {
        const auto which = kind == 0 ? localization::ParticleMap::MaxWeight : localization::ParticleMap::Combined;
        const RobotLandmarkMap self = maps_of(0, which), other = maps_of(j, which);
        // Each map with the pose that goes with it (the maximum-weight particle's, or the mean).
        const merging::Rendezvous meeting{filters[0].pose(which), filters[std::size_t(j)].pose(which),
                                          {lj->range, lj->bearing, jl->range, jl->bearing}};
        const auto evaluate = [&](MethodOutcome& m, const std::optional<core::Transform2>& t) {
          m.transform = t;
          if (!t) return;
          m.error = transform_error(*t, rep.truth);
          const auto merged = merging::merge_landmark_maps(self.map, other.map, *t, o.alignment);
          landmark_rms(merged.merged, merged_ids(merged, self, other, *t), out.truth_in_leader, m.landmark_rms_x,
                       m.landmark_rms_y);
        };
        const auto da = merging::align_landmarks(self.map, other.map, o.alignment, ransac);
        evaluate(rep.data_association[kind], da.found ? std::optional(da.transform) : std::nullopt);
        evaluate(rep.observation[kind],
                 merging::rendezvous_transform(meeting.self_pose, meeting.other_pose, meeting.observation));
        if (kind == 1) {
          const std::set<int> mine(self.ids.begin(), self.ids.end());
          for (int id : other.ids) rep.shared += int(mine.count(id));
          rep.choice = merging::align_landmark_maps(self.map, other.map, meeting, o.alignment, ransac);
          rep.overlap = rep.choice.overlapping_landmarks;
          if (rep.choice.transform) {
            // The leader's global map grows by this follower's map (§VI, Fig. 9).
            const RobotLandmarkMap before = global;
            const auto merged = merging::merge_landmark_maps(global.map, other.map, *rep.choice.transform, o.alignment);
            const auto ids = merged_ids(merged, before, other, *rep.choice.transform);
            std::vector<int> src = source;
            // Fused entries (self's, changed by the fusion) are marked -1.
            for (std::size_t s = 0; s < before.map.landmarks.size(); ++s) {
              if (merged.merged.landmarks[s].position != before.map.landmarks[s].position) src[s] = -1;
            }
            for (std::size_t s = before.ids.size(); s < ids.size(); ++s) src.push_back(j);
            global.map = merged.merged;
            global.ids = ids;
            source = src;
          }
        }
      }
      rep.global_landmarks = int(global.map.landmarks.size());
      out.reports.push_back(std::move(rep));
    }
    out.global = global.map;
    out.global_source = source;
  }
  for (int i = 0; i < n; ++i) {
    const core::Pose2 t = in_own_frame(i, truth[std::size_t(i)]);
    out.final_position_error.push_back((filters[std::size_t(i)].pose().position() - t.position()).norm());
    out.odometry_position_error.push_back((odometry[std::size_t(i)].position() - t.position()).norm());
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

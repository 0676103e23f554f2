// Robots in their own map frames bring each other's maps in by rendezvous, by overlap search or by
// associating their landmark maps; a program registers an aligner of its own.
#include <gtest/gtest.h>

#include <algorithm>

#include "maps/builtin_maps.h"
#include "merging/map_aligner.h"
#include "sim/scenario.h"
#include "sim/run_output.h"
#include "sim/simulation.h"

namespace fleetmap::sim {
namespace {

Scenario own_frames(const std::string& mode) {
  Scenario s;
  s.map = "office";
  s.robot_count = 3;
  s.placement = Placement::Random;
  s.min_separation_m = 4.0;
  s.communication.range_m = 0.0;  // they talk only when they see each other
  s.merging = mode;
  s.exploration.strategy = "coordinated";
  s.steps = 400;
  return s;
}

TEST(MergingRuns, KnownFramesNeverMerge) {
  const RunResult r = Simulation(own_frames("known"), maps::load_map_source("office")).run();
  EXPECT_TRUE(r.merges.empty());
  for (const auto& f : r.robot_frames) EXPECT_TRUE(f.is_approx(core::Transform2::identity()));
}

TEST(MergingRuns, RendezvousBringsEveryoneIntoOneFrame) {
  const RunResult r = Simulation(own_frames("rendezvous"), maps::load_map_source("office")).run();
  ASSERT_FALSE(r.merges.empty());
  for (const auto& m : r.merges) {
    EXPECT_TRUE(m.merged);
    EXPECT_EQ(m.method, "rendezvous");
    // Ideal localization: the error comes only from the detection noise (0.02 m, 1 degree).
    EXPECT_LT(m.rotation_error_deg, 5.0);
    EXPECT_LT(m.position_error_m, 0.3);
  }
  // Robots that met share a frame: their map frames lie in the same place in the world.
  const auto& last = r.merges.back();
  EXPECT_TRUE(r.robot_frames[std::size_t(last.receiver)].is_approx(r.robot_frames[std::size_t(last.sender)], 1e-9));
  EXPECT_GE(r.coverage.back(), 0.99);
  // The world-frame trajectories stay on the truth: ideal localization is exact but for the step of
  // each merge, when the estimate carries the merge's error (centimetres) until the next reading.
  EXPECT_LT(metrics_json(r, "office")["position_rmse_m"].get<double>(), 0.05);
}

TEST(MergingRuns, OverlapSearchMergesOnlyWithConfidence) {
  Scenario s = own_frames("overlap");
  s.communication.range_m = std::numeric_limits<double>::infinity();  // they can talk from the start
  s.merge_attempt_every = 10;
  const RunResult r = Simulation(s, maps::load_map_source("office")).run();
  ASSERT_FALSE(r.merges.empty());
  int made = 0;
  for (const auto& m : r.merges) {
    if (!m.merged) {
      EXPECT_FALSE(m.reason.empty());
      EXPECT_LT(m.confidence, merging::map_aligner_options(s.merging, s.merging_settings).number("min_confidence"));
      continue;
    }
    ++made;
    EXPECT_GE(m.confidence, merging::map_aligner_options(s.merging, s.merging_settings).number("min_confidence"));
    // A wrong merge is worse than none: every merge made is right to within a degree and a few cells.
    EXPECT_LT(m.rotation_error_deg, 1.0);
    EXPECT_LT(m.position_error_m, 0.3);
  }
  EXPECT_GT(made, 0) << "three robots exploring one office should find an overlap";
}

// EKF-SLAM robots in the warehouse with landmarks along the walls (0.3 per metre), who can always
// talk: they associate their estimated landmark maps (RANSAC) and merge once enough landmarks agree.
TEST(MergingRuns, LandmarkMapsMergeOnlyWhenEnoughLandmarksAgree) {
  Scenario s;
  s.map = "warehouse";
  s.seed = 2;
  s.robot_count = 3;
  s.placement = Placement::Random;
  s.min_separation_m = 4.0;
  s.landmarks_along_walls = 0.3;
  s.landmark_sensor.range_noise_m = 0.05;
  s.localization = "ekf-slam";
  s.merging = "landmarks";
  s.exploration.strategy = "market";
  s.steps = 260;
  const RunResult r = Simulation(s, maps::load_map_source("warehouse")).run();
  int made = 0;
  for (const auto& m : r.merges) {
    EXPECT_EQ(m.method, "landmarks");
    if (!m.merged) {
      EXPECT_LT(m.confidence, merging::map_aligner_options(s.merging, s.merging_settings).number("min_confidence"));
      continue;
    }
    ++made;
    // EKF-SLAM landmark estimates are good to centimetres; supports count within 0.3 m.
    EXPECT_LT(m.rotation_error_deg, 2.0);
    EXPECT_LT(m.position_error_m, 0.3);
  }
  EXPECT_GT(made, 0) << "three robots mapping the warehouse's landmarks should find a common part";
}

// A program's own aligner, by name: here one that never trusts anything, so robots keep their frames
// and every attempt is recorded under its name.
class NeverAligner final : public merging::MapAligner {
 public:
  merging::FrameAlignment align(const merging::AlignmentRequest&) const override {
    ++calls;
    merging::FrameAlignment out;
    out.attempted = true;
    out.method = "never";
    out.reason = "this aligner trusts nothing";
    return out;
  }
  static inline int calls = 0;
};

TEST(MergingRuns, ARegisteredAlignerRunsByName) {
  merging::register_map_aligner("never", "refuses every merge (a test's own)",
                                 [](const core::Params&) { return std::make_unique<NeverAligner>(); });
  const auto names = merging_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "never"), names.end());
  const Scenario s = parse_scenario("map: office\nrobots: 2\nsteps: 30\nmerging: never\n", "never.yaml", "");
  const RunResult r = Simulation(s, maps::load_map_source("office")).run();
  EXPECT_GT(NeverAligner::calls, 0);
  ASSERT_FALSE(r.merges.empty());
  for (const auto& m : r.merges) {
    EXPECT_FALSE(m.merged);
    EXPECT_EQ(m.reason, "this aligner trusts nothing");
  }
}

}  // namespace
}  // namespace fleetmap::sim

// Robots in their own map frames bring each other's maps in by rendezvous or by overlap search.
#include <gtest/gtest.h>

#include "maps/builtin_maps.h"
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
      EXPECT_LT(m.confidence, s.merge_min_confidence);
      continue;
    }
    ++made;
    EXPECT_GE(m.confidence, s.merge_min_confidence);
    // A wrong merge is worse than none: every merge made is right to within a degree and a few cells.
    EXPECT_LT(m.rotation_error_deg, 1.0);
    EXPECT_LT(m.position_error_m, 0.3);
  }
  EXPECT_GT(made, 0) << "three robots exploring one office should find an overlap";
}

}  // namespace
}  // namespace fleetmap::sim

// The map-alignment paper's experiments (experiments/landmark_experiment.h) on small cases.
#include "experiments/landmark_experiment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "experiments/landmark_output.h"
#include "io/file_io.h"
#include "tests/test_support.h"

namespace fleetmap::experiments {
namespace {

using fleetmap::testing::expect_input_error;

// Two robots 40 m apart (the follower turned by 30 degrees) map a shared 40 m x 20 m strip of
// landmarks and meet in it; few particles keep the test short.
constexpr const char* kSmall = R"(
experiment: landmark_alignment
seed: 3
runs: 2
particles: 15
sensors:
  landmarks: {max_range: 10, range_noise: 0.05, bearing_noise_deg: 0.5}
  camera: {max_range: 40, range_noise: 0.05, bearing_noise_deg: 0.5}
landmarks:
  fields:
    - {area: [-25, -12, 25, 12], count: 80}
cases:
  - name: shared
    steps: 90
    robots:
      - {name: a, start: [-20, 0, 0], path: [[15, 0]]}
      - {name: b, start: [20, 3, 30], path: [[-15, 3]]}
parts:
  table1: shared
  merges: [shared]
)";

const LandmarkCase& only_case(const LandmarkExperimentOptions& o) { return o.cases.front(); }

// The true transform: b's start seen from a's frame, (40, 3) turned by 30 degrees.
TEST(LandmarkExperiment, BothMethodsRecoverTheTransformBetweenTheRobotsFrames) {
  const LandmarkExperimentOptions o = parse_landmark_options(kSmall, "small.yaml");
  const LandmarkCaseRun run = run_landmark_case(o, only_case(o), 0);
  ASSERT_EQ(run.reports.size(), 1u);
  const FollowerReport& r = run.reports[0];
  EXPECT_NEAR(r.truth.translation().x(), 40.0, 1e-9);
  EXPECT_NEAR(r.truth.translation().y(), 3.0, 1e-9);
  EXPECT_NEAR(r.truth.rotation(), 30.0 * std::numbers::pi / 180.0, 1e-9);
  // Both robots drove the same strip: most of the landmarks are in both maps, and the signatures
  // find them (a chance match within th_s = 1 of signatures spread over 100 is rare).
  EXPECT_GE(r.shared, 30);
  EXPECT_NEAR(r.overlap, r.shared, 0.1 * r.shared + 2);
  for (int kind = 0; kind < 2; ++kind) {
    const MethodOutcome& da = r.data_association[kind];
    ASSERT_TRUE(da.transform.has_value()) << "kind " << kind;
    // What is left is how far each robot's map turned and slid from its true frame while it
    // drove (0.3 degrees of heading noise per step: dead reckoning would drift ~0.05 rad over the
    // 90 steps); the transform from many landmarks adds little to that.
    EXPECT_LT(da.error.translation(), 0.5) << "kind " << kind;
    EXPECT_LT(da.error.theta, 0.05) << "kind " << kind;
    EXPECT_LT(da.landmark_rms_x, 0.5);
    EXPECT_LT(da.landmark_rms_y, 0.5);
    // The observation carries both robots' pose errors and the 0.5 degree bearing over ~5 m.
    const MethodOutcome& io = r.observation[kind];
    ASSERT_TRUE(io.transform.has_value());
    EXPECT_LT(io.error.translation(), 2.0);
    EXPECT_LT(io.error.theta, 0.1);
  }
  // Fig. 3: many overlapping landmarks, so data association.
  EXPECT_EQ(r.choice.method, merging::AlignmentMethod::DataAssociation);
  EXPECT_EQ(r.choice.message, "Map alignment using data association");
  // The global map holds each landmark once: fused duplicates plus each robot's own.
  EXPECT_LT(r.global_landmarks, int(run.global.landmarks.size()) + 1);
  EXPECT_EQ(run.global.landmarks.size(), run.global_source.size());
  // FastSLAM 2.0 beats dead reckoning on the same drive.
  ASSERT_EQ(run.final_position_error.size(), 2u);
  EXPECT_LT(run.final_position_error[0], 0.5);
}

// Fig. 3 with a threshold no overlap reaches: the leader uses the inter-robot observation.
TEST(LandmarkExperiment, BelowTheOverlapThresholdTheObservationIsChosen) {
  LandmarkExperimentOptions o = parse_landmark_options(kSmall, "small.yaml");
  o.alignment.overlap_threshold = 1000;
  const LandmarkCaseRun run = run_landmark_case(o, only_case(o), 1);
  ASSERT_EQ(run.reports.size(), 1u);
  EXPECT_EQ(run.reports[0].choice.method, merging::AlignmentMethod::InterRobotObservation);
  EXPECT_EQ(run.reports[0].choice.message, "Map alignment using inter robot observations");
}

// The whole experiment on the small file: the report names every part that ran.
TEST(LandmarkExperiment, TheReportHasTableOneTheMergesAndThePapersValues) {
  const LandmarkExperimentOptions o = parse_landmark_options(kSmall, "small.yaml");
  const LandmarkExperimentResult r = run_landmark_experiment(o, 1);
  ASSERT_EQ(r.table1.size(), 2u);
  const std::string md = landmark_report_markdown(r);
  EXPECT_NE(md.find("Table I"), std::string::npos);
  EXPECT_NE(md.find("4.7347"), std::string::npos);  // the paper's value beside the measured one
  EXPECT_NE(md.find("no_overlap = "), std::string::npos);
  EXPECT_EQ(md.find("Table II"), std::string::npos);  // not asked for
  const std::string csv = landmark_reports_csv(r);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 + 1);  // header, two table1 runs, one merge
}

TEST(LandmarkExperiment, TheShippedScenarioNamesEveryPart) {
  const auto o = parse_landmark_options(io::read_file(std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/landmark_alignment.yaml"),
                                        "landmark_alignment.yaml");
  EXPECT_EQ(o.runs, 10);
  EXPECT_EQ(o.alignment.overlap_threshold, 10);
  EXPECT_DOUBLE_EQ(o.alignment.geometric_threshold, 0.8);
  EXPECT_DOUBLE_EQ(o.noise_levels.front(), 0.01);
  EXPECT_DOUBLE_EQ(o.noise_levels.back(), 10.0);
  EXPECT_FALSE(o.table1.empty());
  EXPECT_FALSE(o.little_overlap.empty());
  EXPECT_FALSE(o.overlap_large.empty());
  ASSERT_EQ(o.merges.size(), 2u);
}

TEST(LandmarkExperiment, BadScenariosAreInputErrorsNamingTheKey) {
  std::string text = kSmall;
  expect_input_error([&] { parse_landmark_options(text + "bogus: 1\n", "s.yaml"); }, {"s.yaml", "bogus"});
  std::string wrong_part = text;
  wrong_part.replace(wrong_part.find("table1: shared"), 14, "table1: nothing");
  expect_input_error([&] { parse_landmark_options(wrong_part, "s.yaml"); }, {"s.yaml", "table1", "nothing"});
  std::string one_robot = text;
  one_robot.erase(one_robot.find("      - {name: b"), std::string("      - {name: b, start: [20, 3, 30], path: [[-15, 3]]}\n").size());
  expect_input_error([&] { parse_landmark_options(one_robot, "s.yaml"); }, {"s.yaml", "robots", "at least two"});
  // Robots whose paths end beyond the camera's range cannot meet: refused before running ...
  std::string far = text;
  far.replace(far.find("camera: {max_range: 40"), 22, "camera: {max_range: 10");
  expect_input_error([&] { parse_landmark_options(far, "s.yaml"); }, {"s.yaml", "case 'shared'", "apart at the rendezvous"});
  // ... and if the noise carries them apart, the run stops with the same message.
  LandmarkExperimentOptions o = parse_landmark_options(text, "s.yaml");
  o.camera.max_range_m = 1.0;
  expect_input_error([&] { run_landmark_case(o, only_case(o), 0); }, {"case 'shared'", "do not see each other"});
}

}  // namespace
}  // namespace fleetmap::experiments

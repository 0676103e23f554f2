// End-to-end: `fleetmap merge` as a user runs it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>

#include "core/angle.h"
#include "maps/builtin_maps.h"
#include "io/map_io.h"
#include "viz/render.h"
#include "merging/evaluation.h"
#include "merging/rendezvous.h"
#include "tests/cli_run.h"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace fleetmap::cli {
namespace {

using fleetmap::testing::run_fleetmap;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

struct PixelTruth {
  double tx, ty, theta_deg;
};

// Two crops of the built-in office, the second turned and shifted, saved as map_saver PNGs. The
// truth is in the command's pixel convention.
PixelTruth write_pair(const TempDir& dir, const std::string& a_name, const std::string& b_name, std::uint64_t seed) {
  const auto office = maps::load_map_source("office");
  core::Random random(seed);
  merging::CropPairOptions o;
  o.width = o.height = 140;
  o.overlap = 0.5;
  const merging::CropPair pair = merging::make_crop_pair(office, o, random);
  io::save_map_image(pair.a, dir / a_name);
  io::save_map_image(pair.b, dir / b_name);
  const core::Transform2 px = merging::flip_rows(pair.b_to_a, pair.a.height(), pair.b.height());
  return {px.translation().x(), px.translation().y(), core::rad2deg(px.rotation())};
}

TEST(MergeCommand, MergesTwoMapsInThePixelConvention) {
  TempDir dir;
  const PixelTruth truth = write_pair(dir, "a.png", "b.png", 5);
  const auto r = run_fleetmap("merge a.png b.png --out out/merged.png --json out/result.json", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("wrote out/merged.png"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(slurp(dir / "out" / "result.json"));
  ASSERT_EQ(j["transforms"].size(), 1u);
  const auto& t = j["transforms"][0];
  EXPECT_EQ(t["map"], "b.png");
  EXPECT_EQ(t["merged"], true);
  // Within a degree; within a cell at the crop (the translation is at the image origin, so allow
  // the rotation error over the crop's extent too).
  const double dtheta = std::abs(core::rad2deg(core::normalize_angle(core::deg2rad(t["theta_deg"].get<double>() - truth.theta_deg))));
  EXPECT_LT(dtheta, 1.0);
  EXPECT_LT(std::hypot(t["tx"].get<double>() - truth.tx, t["ty"].get<double>() - truth.ty), 1.0 + core::deg2rad(dtheta) * 200.0);
  EXPECT_GT(t["acceptance"].get<double>(), 0.95);
  EXPECT_GE(t["confidence"].get<double>(), 0.5);
  EXPECT_LE(t["confidence"].get<double>(), 1.0);
  EXPECT_EQ(t["method"], "overlap");
  EXPECT_EQ(t["via"], "a.png");
  EXPECT_NE(j["convention"].get<std::string>().find("R(theta) (u, v) + (tx, ty)"), std::string::npos);

  // The picture tints each input's free cells toward its palette colour (legend swatches included).
  const cv::Mat img = cv::imread((dir / "out" / "merged.png").string());
  ASSERT_FALSE(img.empty());
  const auto has_colour = [&](const viz::Color& c) {
    for (int y = 0; y < img.rows; ++y) {
      for (int x = 0; x < img.cols; ++x) {
        const auto& p = img.at<cv::Vec3b>(y, x);
        const auto tint = [](int v) { return cv::saturate_cast<uchar>(255 * 0.7 + v * 0.3); };
        if (p[0] == tint(c.b) && p[1] == tint(c.g) && p[2] == tint(c.r)) return true;
      }
    }
    return false;
  };
  EXPECT_TRUE(has_colour(viz::palette_color(0)));
  EXPECT_TRUE(has_colour(viz::palette_color(1)));
}

// Robots with different map resolutions: the second map is the pair's b seen through 0.1 m cells
// (a's are 0.05 m), given second and then first. Its pixel p is placed at scale R p + t, with
// scale its cell size over the first map's.
TEST(MergeCommand, MergesMapsOfDifferentResolutions) {
  TempDir dir;
  const auto office = maps::load_map_source("office");
  core::Random random(5);
  merging::CropPairOptions o;
  o.width = o.height = 140;
  o.overlap = 0.5;
  const merging::CropPair pair = merging::make_crop_pair(office, o, random);
  const mapping::OccupancyGrid coarse = mapping::coarsen(pair.b, 2);
  io::save_map_image(pair.a, dir / "a.png");
  io::save_map_image(coarse, dir / "b.png");
  dir.write("a.yaml", "image: a.png\nresolution: 0.05\n");
  dir.write("b.yaml", "image: b.png\nresolution: 0.1\n");
  // The coarse map's pixel (u, v) has its centre at the fine pixel (2u + 0.5, 2v + H + 0.5 - 2H'),
  // H and H' the fine and coarse heights; the truth takes fine pixels of b into a's pixels.
  const core::Transform2 b_to_a = merging::flip_rows(pair.b_to_a, pair.a.height(), pair.b.height());
  const auto coarse_to_a = [&](const Eigen::Vector2d& p) {
    return b_to_a.apply(Eigen::Vector2d(2 * p.x() + 0.5, 2 * p.y() + pair.b.height() + 0.5 - 2 * coarse.height()));
  };
  const auto placed = [](const nlohmann::json& t, const Eigen::Vector2d& p) {
    const core::Transform2 rigid(t["tx"].get<double>(), t["ty"].get<double>(), core::deg2rad(t["theta_deg"].get<double>()));
    return rigid.apply(t["scale"].get<double>() * p);
  };
  const std::vector<Eigen::Vector2d> corners = {
      {0, 0}, {coarse.width() - 1.0, 0}, {0, coarse.height() - 1.0}, {coarse.width() - 1.0, coarse.height() - 1.0}};

  // Coarse second: resampled to 0.05 m; the placement within a fine cell and a half at b's corners.
  auto r = run_fleetmap("merge a.yaml b.yaml --json r.json --out m.yaml", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("maps of different resolutions: each pair aligned through the coarser one's cells, fused in a.yaml's 0.05 m cells"), std::string::npos) << r.out;
  auto t = nlohmann::json::parse(slurp(dir / "r.json"))["transforms"][0];
  ASSERT_EQ(t["merged"], true) << t.dump();
  EXPECT_DOUBLE_EQ(t["scale"].get<double>(), 2.0);
  for (const auto& p : corners) EXPECT_LT((placed(t, p) - coarse_to_a(p)).norm(), 1.5) << t.dump();
  // The fused map is in the first map's cells.
  const auto fused = io::load_map(dir / "m.yaml");
  EXPECT_DOUBLE_EQ(fused.resolution(), 0.05);

  // Coarse first: a is resampled to 0.1 m, and b's fine pixels are placed at half scale; the
  // placement within one coarse cell (two fine ones) at a's corners.
  r = run_fleetmap("merge b.yaml a.yaml --json r2.json --out m2.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  t = nlohmann::json::parse(slurp(dir / "r2.json"))["transforms"][0];
  ASSERT_EQ(t["merged"], true) << t.dump();
  EXPECT_DOUBLE_EQ(t["scale"].get<double>(), 0.5);
  // a's fine pixel q lies at the coarse pixel c with coarse_to_a(c) = q.
  const core::Transform2 a_to_b = b_to_a.inverse();
  for (const Eigen::Vector2d& q : {Eigen::Vector2d(0, 0), Eigen::Vector2d(pair.a.width() - 1.0, pair.a.height() - 1.0),
                                  Eigen::Vector2d(0, pair.a.height() - 1.0)}) {
    const Eigen::Vector2d fine_b = a_to_b.apply(q);
    const Eigen::Vector2d want((fine_b.x() - 0.5) / 2, (fine_b.y() - pair.b.height() - 0.5 + 2 * coarse.height()) / 2);
    EXPECT_LT((placed(t, q) - want).norm(), 1.0) << t.dump();
  }
}

TEST(MergeCommand, ThePictureHoldsTheMapWithoutEmptyMarginsAndDarkWalls) {
  TempDir dir;
  write_pair(dir, "a.png", "b.png", 5);
  ASSERT_EQ(run_fleetmap("merge a.png b.png --out m.png", dir).exit_code, 0);
  const cv::Mat img = cv::imread((dir / "m.png").string());
  ASSERT_FALSE(img.empty());
  // Two 140-cell crops overlapping by half span at most 280 cells: drawn at 3 px or more per
  // cell toward 800 px, the picture stays near that size plus axes and legend, nowhere near the
  // fused grid's padded extent.
  EXPECT_LT(img.cols, 1400);
  EXPECT_LT(img.rows, 1100);
  // Walls are black, not tints.
  cv::Mat black;
  cv::inRange(img, cv::Scalar(0, 0, 0), cv::Scalar(0, 0, 0), black);
  EXPECT_GT(cv::countNonZero(black), 2000);
}

TEST(MergeCommand, AMapWithoutOverlapIsReportedNotMerged) {
  TempDir dir;
  write_pair(dir, "a.png", "b.png", 6);
  // A piece of the maze shares nothing with the office.
  const auto maze = maps::load_map_source("maze");
  io::save_map_image(merging::crop_grid(maze, 30, 30, 120, 120), dir / "maze.png");
  const auto r = run_fleetmap("merge a.png maze.png b.png --method overlap --json r.json --out m.png", dir);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("2 of 3 maps merged"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir / "r.json"));
  ASSERT_EQ(j["transforms"].size(), 2u);
  EXPECT_EQ(j["transforms"][0]["map"], "maze.png");
  EXPECT_EQ(j["transforms"][0]["merged"], false);
  EXPECT_NE(j["transforms"][0]["reason"].get<std::string>().find("no reliable overlap"), std::string::npos);
  EXPECT_FALSE(j["transforms"][0].contains("tx"));
  EXPECT_EQ(j["transforms"][1]["merged"], true);
  EXPECT_TRUE(std::filesystem::exists(dir / "m.png"));
}

TEST(MergeCommand, ReadsMapServerYaml) {
  TempDir dir;
  write_pair(dir, "a.png", "b.png", 7);
  dir.write("b.yaml", "image: b.png\nresolution: 0.05\norigin: [1.0, 2.0, 0.0]\n");
  const auto r = run_fleetmap("merge a.png b.yaml --json r.json --out m.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(dir / "r.json"))["transforms"][0]["map"], "b.yaml");
}

// Merge, then plan: a map file as --out is a map_server map in the first input's metres.
TEST(MergeCommand, WritesAMapFileInTheFirstMapsMetresThatPlanReads) {
  TempDir dir;
  write_pair(dir, "a.png", "b.png", 7);
  dir.write("a.yaml", "image: a.png\nresolution: 0.05\norigin: [1.0, 2.0, 0.0]\n");
  const auto r = run_fleetmap("merge a.yaml b.png --out out/merged.yaml --picture out/merged.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  for (const char* f : {"merged.yaml", "merged.pgm", "merged.png"}) {
    EXPECT_NE(r.out.find(std::string("wrote out/") + f), std::string::npos) << r.out;
  }
  const mapping::OccupancyGrid a = io::load_map(dir / "a.yaml");
  const mapping::OccupancyGrid merged = io::load_map(dir / "out" / "merged.yaml");
  EXPECT_DOUBLE_EQ(merged.resolution(), 0.05);
  EXPECT_GT(merged.known_count(), a.known_count());
  // Every cell of the reference keeps its place in metres (the fused map adds b's evidence, so a
  // few cells may change state, not many).
  std::int64_t same = 0, known = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      const auto state = a.state({x, y});
      if (state == mapping::CellState::Unknown) continue;
      const auto cell = merged.geometry().world_to_cell(a.geometry().cell_center({x, y}));
      ASSERT_TRUE(cell.has_value());
      ++known;
      same += merged.state(*cell) == state;
    }
  }
  EXPECT_GT(double(same) / double(known), 0.97);

  // Plan between two points of the reference's free space, in its metres, on the merged map.
  cv::Mat free(a.height(), a.width(), CV_8U);
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) free.at<uchar>(y, x) = a.state({x, y}) == mapping::CellState::Free ? 255 : 0;
  }
  cv::Mat clearance;
  cv::distanceTransform(free, clearance, cv::DIST_L2, 3);
  cv::Point widest;
  cv::minMaxLoc(clearance, nullptr, nullptr, nullptr, &widest);
  const Eigen::Vector2d from = a.geometry().cell_center({widest.x, widest.y});
  const Eigen::Vector2d to = from + Eigen::Vector2d(0.2, 0.1);
  const auto p = run_fleetmap(fmt::format("plan --map out/merged.yaml --from {},{} --to {},{} --planner astar --json "
                                          "path.json",
                                          from.x(), from.y(), to.x(), to.y()),
                              dir);
  ASSERT_EQ(p.exit_code, 0) << p.err << p.out;
  const auto path = nlohmann::json::parse(slurp(dir / "path.json"));
  EXPECT_TRUE(path["success"].get<bool>()) << path.dump();
  EXPECT_NEAR(path["start"][0].get<double>(), from.x(), 1e-6);
}

TEST(MergeCommand, PictureAndMapFileNamesAreChecked) {
  TempDir dir;
  write_pair(dir, "a.png", "b.png", 7);
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge a.png b.png --out m.png --picture p.png", dir), "--picture p.png");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge a.png b.png --out m.txt", dir), "--out m.txt: give a .png picture");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge a.png b.png --out m.yaml --picture p.jpg", dir), "--picture p.jpg");
  // The map's image beside the YAML may not be an input either.
  io::save_map_image(io::load_map(dir / "a.png"), dir / "c.pgm");
  const std::string before = slurp(dir / "c.pgm");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge c.pgm b.png --out c.yaml", dir), "c.pgm");
  EXPECT_FALSE(std::filesystem::exists(dir / "c.yaml"));
  EXPECT_EQ(slurp(dir / "c.pgm"), before);
  EXPECT_FALSE(std::filesystem::exists(dir / "m.png"));
}

TEST(MergeCommand, HelpStatesTheConventionAndEveryFlagWithItsDefault) {
  TempDir dir;
  const auto r = run_fleetmap("merge --help", dir);
  ASSERT_EQ(r.exit_code, 0);
  for (const char* part : {"R(theta) (u, v) + (tx, ty)", "u = column", "row from the top", "--method",
                           "=auto", "--out", "=merged.png", "--json", "default: none", "--min-confidence", "=0.5",
                           "--seed", "--resolution", "else 0.05", "overlap:", "features:", "auto:", "merged: false"}) {
    EXPECT_NE(r.out.find(part), std::string::npos) << part;
  }
}

TEST(MergeCommand, BadInputGetsOneLineNamingItAndExitCode2) {
  TempDir dir;
  write_pair(dir, "a.png", "b.png", 8);
  auto r = run_fleetmap("merge a.png missing.png", dir);
  EXPECT_ONE_LINE_ERROR(r, "missing.png");
  EXPECT_EQ(r.exit_code, 2);
  dir.write("junk.png", "not an image at all");
  r = run_fleetmap("merge a.png junk.png", dir);
  EXPECT_ONE_LINE_ERROR(r, "junk.png");
  EXPECT_EQ(r.exit_code, 2);
  cv::imwrite((dir / "unknown.png").string(), cv::Mat(50, 50, CV_8UC1, cv::Scalar(205)));
  r = run_fleetmap("merge a.png unknown.png", dir);
  EXPECT_ONE_LINE_ERROR(r, "unknown.png: every cell is unknown");
  EXPECT_EQ(r.exit_code, 2);
  r = run_fleetmap("merge a.png", dir);
  EXPECT_ONE_LINE_ERROR(r, "at least two maps, got one: a.png");
  EXPECT_EQ(r.exit_code, 2);
  r = run_fleetmap("merge a.png b.png --method magic", dir);
  EXPECT_ONE_LINE_ERROR(r, "magic");
  EXPECT_EQ(r.exit_code, 2);
  r = run_fleetmap("merge a.png b.png --out a.png", dir);
  EXPECT_ONE_LINE_ERROR(r, "--out a.png: is the input a.png; fleetmap never overwrites an input");
  EXPECT_EQ(r.exit_code, 2);
  r = run_fleetmap("merge", dir);
  EXPECT_ONE_LINE_ERROR(r, "maps");
  EXPECT_EQ(r.exit_code, 2);
}

}  // namespace
}  // namespace fleetmap::cli

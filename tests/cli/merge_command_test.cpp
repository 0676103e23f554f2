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

// Two 140-cell crops of the built-in office overlapping by half, the second turned and shifted.
merging::CropPair office_pair(std::uint64_t seed) {
  core::Random random(seed);
  merging::CropPairOptions o;
  o.width = o.height = 140;
  o.overlap = 0.5;
  return merging::make_crop_pair(maps::load_map_source("office"), o, random);
}

// office_pair saved as map_saver PNGs. The truth is in the command's pixel convention.
PixelTruth write_pair(const TempDir& dir, const std::string& a_name, const std::string& b_name, std::uint64_t seed) {
  const merging::CropPair pair = office_pair(seed);
  io::save_map_image(pair.a, dir / a_name);
  io::save_map_image(pair.b, dir / b_name);
  const core::Transform2 px = merging::flip_rows(pair.b_to_a, pair.a.height(), pair.b.height());
  return {px.translation().x(), px.translation().y(), core::rad2deg(px.rotation())};
}

// The centre of the free cell farthest from any other cell (metres): a place to plan from.
Eigen::Vector2d widest_free_point(const mapping::OccupancyGrid& g) {
  cv::Mat free(g.height(), g.width(), CV_8U);
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) free.at<uchar>(y, x) = g.state({x, y}) == mapping::CellState::Free ? 255 : 0;
  }
  cv::Mat clearance;
  cv::distanceTransform(free, clearance, cv::DIST_L2, 3);
  cv::Point widest;
  cv::minMaxLoc(clearance, nullptr, nullptr, nullptr, &widest);
  return g.geometry().cell_center({widest.x, widest.y});
}

// The share of `a`'s known cells that `merged` holds at the same place in metres (a cell centre on
// a cell centre) and in the same state.
double share_in_place(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& merged) {
  std::int64_t same = 0, known = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      const auto state = a.state({x, y});
      if (state == mapping::CellState::Unknown) continue;
      ++known;
      const Eigen::Vector2d p = a.geometry().cell_center({x, y});
      const auto cell = merged.geometry().world_to_cell(p);
      same += cell && (merged.geometry().cell_center(*cell) - p).norm() < 1e-6 && merged.state(*cell) == state;
    }
  }
  return known > 0 ? double(same) / double(known) : 0.0;
}

TEST(MergeCommand, MergesTwoMapsAndGivesThePixelPlacement) {
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
  const double dtheta = std::abs(core::rad2deg(core::normalize_angle(core::deg2rad(t["theta_px_deg"].get<double>() - truth.theta_deg))));
  EXPECT_LT(dtheta, 1.0);
  EXPECT_LT(std::hypot(t["tx_px"].get<double>() - truth.tx, t["ty_px"].get<double>() - truth.ty), 1.0 + core::deg2rad(dtheta) * 200.0);
  EXPECT_GT(t["acceptance"].get<double>(), 0.95);
  EXPECT_GE(t["confidence"].get<double>(), 0.5);
  EXPECT_LE(t["confidence"].get<double>(), 1.0);
  EXPECT_EQ(t["method"], "grid");
  EXPECT_EQ(t["via"], "a.png");
  // The covariance of (tx_m, ty_m, theta): symmetric, its standard deviations as given, a fraction
  // of a cell (a bare image's cells are 0.05 m) and of a degree; and the summary line says them.
  ASSERT_EQ(t["covariance"].size(), 3u);
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(t["covariance"][i][k].get<double>(), t["covariance"][k][i].get<double>());
  EXPECT_DOUBLE_EQ(t["std_tx_m"].get<double>(), std::sqrt(t["covariance"][0][0].get<double>()));
  EXPECT_NEAR(t["std_theta_deg"].get<double>(), core::rad2deg(std::sqrt(t["covariance"][2][2].get<double>())), 1e-12);
  EXPECT_LT(t["std_tx_m"].get<double>(), 0.025);
  EXPECT_LT(t["std_theta_deg"].get<double>(), 0.5);
  EXPECT_GE(t["std_major_m"].get<double>(), t["std_minor_m"].get<double>());
  EXPECT_NE(r.out.find("uncertainty (1 sigma"), std::string::npos) << r.out;
  EXPECT_NE(j["convention"].get<std::string>().find("R(theta) p + (tx_m, ty_m)"), std::string::npos);
  EXPECT_NE(j["pixel_convention"].get<std::string>().find("R(theta_px) (u, v) + (tx_px, ty_px)"), std::string::npos);

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

// A known turn and shift between two map_server files, origins and all, comes back in metres and
// degrees: a point p of b's map frame lies at R(theta) p + (tx_m, ty_m) in a's.
TEST(MergeCommand, ReportsTheTransformBetweenTheMapFilesFramesInMetresAndDegrees) {
  TempDir dir;
  const merging::CropPair pair = office_pair(5);
  io::save_map_image(pair.a, dir / "a.png");
  io::save_map_image(pair.b, dir / "b.png");
  dir.write("a.yaml", "image: a.png\nresolution: 0.05\norigin: [1.0, 2.0, 0.0]\n");
  dir.write("b.yaml", "image: b.png\nresolution: 0.05\norigin: [-3.0, 0.5, 0.4]\n");
  const auto a = io::load_map(dir / "a.yaml"), b = io::load_map(dir / "b.yaml");
  const core::Transform2 truth = merging::world_from_cells(a.geometry(), b.geometry(), pair.b_to_a);
  const auto r = run_fleetmap("merge a.yaml b.yaml --json r.json --out m.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const auto t = nlohmann::json::parse(slurp(dir / "r.json"))["transforms"][0];
  ASSERT_EQ(t["merged"], true) << t.dump();
  const core::Transform2 got(t["tx_m"].get<double>(), t["ty_m"].get<double>(), core::deg2rad(t["theta_deg"].get<double>()));
  EXPECT_LT(std::abs(core::rad2deg(core::normalize_angle(got.rotation() - truth.rotation()))), 1.0) << got << " vs " << truth;
  // b's centre lands within a cell and a half of where it belongs.
  const Eigen::Vector2d centre = b.geometry().cell_center({b.width() / 2, b.height() / 2});
  EXPECT_LT((got.apply(centre) - truth.apply(centre)).norm(), 0.075) << got << " vs " << truth;
  // The printed line says the same numbers.
  EXPECT_NE(r.out.find(fmt::format("b.yaml: tx {:.3f} ty {:.3f} m, theta {:.3f} deg (pixels: tx {:.2f} ty {:.2f}",
                                   got.translation().x(), got.translation().y(), t["theta_deg"].get<double>(),
                                   t["tx_px"].get<double>(), t["ty_px"].get<double>())),
            std::string::npos)
      << r.out;
}

// Robots with different map resolutions: the second map is the pair's b seen through 0.1 m cells
// (a's are 0.05 m), given second and then first. Its pixel p is placed at scale R p + t, with
// scale its cell size over the first map's; in metres the frames are the same whatever the cells.
TEST(MergeCommand, MergesMapsOfDifferentResolutions) {
  TempDir dir;
  const merging::CropPair pair = office_pair(5);
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
    const core::Transform2 rigid(t["tx_px"].get<double>(), t["ty_px"].get<double>(),
                                 core::deg2rad(t["theta_px_deg"].get<double>()));
    return rigid.apply(t["scale"].get<double>() * p);
  };
  const std::vector<Eigen::Vector2d> corners = {
      {0, 0}, {coarse.width() - 1.0, 0}, {0, coarse.height() - 1.0}, {coarse.width() - 1.0, coarse.height() - 1.0}};
  // Both files have their origin at (0, 0): b's frame in metres is pair.b's at 0.05 m.
  const core::Transform2 metres = merging::world_from_cells(io::load_map(dir / "a.yaml").geometry(),
                                                            core::GridGeometry(0.05, pair.b.width(), pair.b.height()),
                                                            pair.b_to_a);
  const auto expect_metres = [&](const nlohmann::json& t, const core::Transform2& truth, const mapping::OccupancyGrid& b) {
    const core::Transform2 got(t["tx_m"].get<double>(), t["ty_m"].get<double>(), core::deg2rad(t["theta_deg"].get<double>()));
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(b.geometry().width_m(), b.geometry().height_m())}) {
      EXPECT_LT((got.apply(corner) - truth.apply(corner)).norm(), 0.1) << got << " vs " << truth;
    }
  };

  // Coarse second: resampled to 0.05 m; the placement within a fine cell and a half at b's corners.
  auto r = run_fleetmap("merge a.yaml b.yaml --json r.json --out m.yaml", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("maps of different resolutions: each pair aligned through the coarser one's cells, fused in a.yaml's 0.05 m cells"), std::string::npos) << r.out;
  auto t = nlohmann::json::parse(slurp(dir / "r.json"))["transforms"][0];
  ASSERT_EQ(t["merged"], true) << t.dump();
  EXPECT_DOUBLE_EQ(t["scale"].get<double>(), 2.0);
  for (const auto& p : corners) EXPECT_LT((placed(t, p) - coarse_to_a(p)).norm(), 1.5) << t.dump();
  expect_metres(t, metres, coarse);
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
  expect_metres(t, metres.inverse(), io::load_map(dir / "a.yaml"));
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

// The part of a merge picture inside the margin of unknown cells around the known ones (the largest
// patch of unknown grey), its central three fifths.
cv::Mat central_known_area(const cv::Mat& img) {
  cv::Mat grey, labels, stats, centroids;
  cv::inRange(img, cv::Scalar(205, 205, 205), cv::Scalar(205, 205, 205), grey);
  const int n = cv::connectedComponentsWithStats(grey, labels, stats, centroids);
  int largest = 1;
  for (int k = 2; k < n; ++k) {
    if (stats.at<int>(k, cv::CC_STAT_AREA) > stats.at<int>(largest, cv::CC_STAT_AREA)) largest = k;
  }
  const cv::Rect ring(stats.at<int>(largest, cv::CC_STAT_LEFT), stats.at<int>(largest, cv::CC_STAT_TOP),
                      stats.at<int>(largest, cv::CC_STAT_WIDTH), stats.at<int>(largest, cv::CC_STAT_HEIGHT));
  return img(cv::Rect(ring.x + ring.width / 5, ring.y + ring.height / 5, ring.width * 3 / 5, ring.height * 3 / 5));
}

double share_of(const cv::Mat& img, const cv::Vec3b& bgr) {
  cv::Mat hit;
  cv::inRange(img, cv::Scalar(bgr[0], bgr[1], bgr[2]), cv::Scalar(bgr[0], bgr[1], bgr[2]), hit);
  return double(cv::countNonZero(hit)) / double(img.total());
}

// Cells free in both maps stand apart from unknown grey and from each map's own tint.
TEST(MergeCommand, CellsFreeInSeveralMapsAreWhiteNeitherUnknownGreyNorATint) {
  TempDir dir;
  const merging::CropPair pair = office_pair(5);
  // In a larger unknown area, so that the picture has its margin of unknown around the known cells.
  const mapping::OccupancyGrid a = merging::crop_grid(pair.a, -20, -20, pair.a.width() + 40, pair.a.height() + 40);
  io::save_map_image(a, dir / "a.png");
  io::save_map_image(a, dir / "same.png");
  ASSERT_EQ(run_fleetmap("merge a.png same.png --out m.png", dir).exit_code, 0);
  const cv::Mat img = cv::imread((dir / "m.png").string());
  ASSERT_FALSE(img.empty());
  const cv::Mat known = central_known_area(img);
  // Every known cell is free in both maps or a wall.
  EXPECT_GT(share_of(known, {255, 255, 255}), 0.5);
  EXPECT_GT(share_of(known, {255, 255, 255}) + share_of(known, {0, 0, 0}), 0.999);
  EXPECT_EQ(share_of(known, {205, 205, 205}), 0.0);
  // The inputs' tints appear in the legend's swatches only (14 x 14 pixels).
  const auto tint = [](const viz::Color& c) {
    const auto t = [](int v) { return cv::saturate_cast<uchar>(255 * 0.7 + v * 0.3); };
    return cv::Vec3b(t(c.b), t(c.g), t(c.r));
  };
  for (int k : {0, 1}) EXPECT_LT(share_of(img, tint(viz::palette_color(k))) * double(img.total()), 14 * 14);
}

TEST(MergeCommand, AMapWithoutOverlapIsReportedNotMerged) {
  TempDir dir;
  write_pair(dir, "a.png", "b.png", 6);
  // A piece of the maze shares nothing with the office.
  const auto maze = maps::load_map_source("maze");
  io::save_map_image(merging::crop_grid(maze, 30, 30, 120, 120), dir / "maze.png");
  const auto r = run_fleetmap("merge a.png maze.png b.png --method grid --json r.json --out m.png", dir);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("2 of 3 maps merged"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir / "r.json"));
  ASSERT_EQ(j["transforms"].size(), 2u);
  EXPECT_EQ(j["transforms"][0]["map"], "maze.png");
  EXPECT_EQ(j["transforms"][0]["merged"], false);
  EXPECT_NE(j["transforms"][0]["reason"].get<std::string>().find("no reliable overlap"), std::string::npos);
  EXPECT_FALSE(j["transforms"][0].contains("tx_m"));
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
  EXPECT_GT(share_in_place(a, merged), 0.97);

  // Plan between two points of the reference's free space, in its metres, on the merged map.
  const Eigen::Vector2d from = widest_free_point(a);
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

// Maps inside a large unknown area (as robots allocate them): the merged map file holds the known
// cells and half a metre around them, each at its place in the first map's metres, and plan's
// picture of it is the map, not a field of unknown.
TEST(MergeCommand, CutsTheMergedMapFileToTheKnownCellsKeepingTheirPlaceInMetres) {
  TempDir dir;
  const merging::CropPair pair = office_pair(7);
  io::save_map_image(merging::crop_grid(pair.a, -150, -150, pair.a.width() + 300, pair.a.height() + 300), dir / "a.png");
  io::save_map_image(merging::crop_grid(pair.b, -100, -120, pair.b.width() + 220, pair.b.height() + 240), dir / "b.png");
  const mapping::OccupancyGrid a = io::load_map(dir / "a.png");
  const auto r = run_fleetmap("merge a.png b.png --out merged.yaml", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const mapping::OccupancyGrid merged = io::load_map(dir / "merged.yaml");
  // The known cells' box, 10 cells (0.5 m) from every edge.
  int x0 = merged.width(), y0 = merged.height(), x1 = -1, y1 = -1;
  for (int y = 0; y < merged.height(); ++y) {
    for (int x = 0; x < merged.width(); ++x) {
      if (merged.state({x, y}) == mapping::CellState::Unknown) continue;
      x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
    }
  }
  EXPECT_EQ(x0, 10);
  EXPECT_EQ(y0, 10);
  EXPECT_EQ(merged.width() - 1 - x1, 10);
  EXPECT_EQ(merged.height() - 1 - y1, 10);
  // Two 140-cell crops overlapping by half span at most 280 cells.
  EXPECT_LE(std::max(merged.width(), merged.height()), 300);
  // Every known cell of the reference is where it was, in metres.
  EXPECT_GT(share_in_place(a, merged), 0.97);
  // plan reads it, and its picture is mostly map.
  const Eigen::Vector2d from = widest_free_point(a);
  const auto p = run_fleetmap(fmt::format("plan --map merged.yaml --from {},{} --to {},{} --planner astar --out plan.png",
                                          from.x(), from.y(), from.x() + 0.1, from.y()),
                              dir);
  ASSERT_EQ(p.exit_code, 0) << p.err << p.out;
  const cv::Mat picture = cv::imread((dir / "plan.png").string());
  ASSERT_FALSE(picture.empty());
  EXPECT_LT(share_of(picture, {205, 205, 205}), 0.25);
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
  for (const char* part : {"R(theta) p + (tx_m, ty_m)", "metres", "degrees", "origin", "tx_px",
                           "R(theta_px) (u, v) + (tx_px, ty_px)", "u = column", "row from the top", "--method",
                           "=auto", "--out", "=merged.png", "--json", "default: none", "--min-confidence", "=0.5",
                           "--seed", "--resolution", "else 0.05", "grid:", "features:", "auto:", "merged: false",
                           "white when several did", "to the known cells and half a metre around them (its origin says where)"}) {
    EXPECT_NE(r.out.find(part), std::string::npos) << part;
  }
}

// A merge method's declared parameters, set with --set METHOD.KEY=VALUE and recorded in the JSON.
TEST(MergeCommand, SetsAMergeMethodsParameters) {
  TempDir dir;
  write_pair(dir, "a.png", "b.png", 5);
  // These small crops give ORB too few matches for a model of 8 inliers; a looser ratio test and
  // fewer inliers give it candidates.
  const auto strict = run_fleetmap("merge a.png b.png --method features --out s.png --json s.json", dir);
  ASSERT_NE(strict.exit_code, 2) << strict.err;
  EXPECT_NE(slurp(dir / "s.json").find("no candidate transform"), std::string::npos);
  const auto loose = run_fleetmap(
      "merge a.png b.png --method features --set features.ratio=1 --set features.min_inliers=3 --out l.png --json l.json", dir);
  ASSERT_NE(loose.exit_code, 2) << loose.err;
  const auto j = nlohmann::json::parse(slurp(dir / "l.json"));
  EXPECT_EQ(j["method_parameters"]["features"]["min_inliers"], "3");
  EXPECT_EQ(j["method_parameters"]["features"]["ratio"], "1");
  EXPECT_EQ(slurp(dir / "l.json").find("no candidate transform"), std::string::npos) << slurp(dir / "l.json");
  // Under auto, each method run gets its own.
  const auto with_auto = run_fleetmap("merge a.png b.png --set features.min_inliers=10000 --set grid.sweep_step_deg=2 --out x.png", dir);
  EXPECT_EQ(with_auto.exit_code, 0) << with_auto.err;
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge a.png b.png --method grid --set features.ratio=0.5 --out bad.png", dir),
                        "merge method 'grid' does not run 'features'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge a.png b.png --set features.ratoi=0.5 --out bad.png", dir), "did you mean 'ratio'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge a.png b.png --set grid.sweep_step_deg=0 --out bad.png", dir), ">= 0.25");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge a.png b.png --set grd.search_cells=64 --out bad.png", dir), "did you mean 'grid'");
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.png"));
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
